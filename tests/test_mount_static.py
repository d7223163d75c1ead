"""Static preload of the reference mount: equilibrium, load paths, symmetry, mechanisms."""
import dataclasses

import numpy as np
import pytest

from workbook.errors import EquilibriumError, MechanismError
from workbook.model.case import Gravity, PointForce
from workbook.model.reference import ENGINE_CG
from workbook.scene.build import build_scene
from workbook.solve.harmonic import harmonic_model
from workbook.solve.modes import modes_of, mounted_modes
from workbook.solve.preload import check_equilibrium, solve_preload

# The coarse reference mount of conftest: statics need the links' stiffness,
# which Craig-Bampton reproduces exactly for any mesh; 30 mm elements keep the
# reductions short.
MIRROR = np.array([1.0, -1.0, 1.0])


@pytest.fixture(scope="module")
def reference(coarse_reference):
    return coarse_reference


@pytest.fixture(scope="module")
def preloaded(reference):
    scene = build_scene(reference)
    return scene, solve_preload(scene)


def test_pylon_force_balances_thrust_and_weight(preloaded):
    scene, preload = preloaded
    link_mass = sum(link.mass for link in scene.links.values())
    weight = (3568.0 + link_mass) * 9.81
    assert 50 < link_mass < 100
    expected = np.array([23_000.0, 0.0, -weight])
    assert np.linalg.norm(preload.pylon_force - expected) <= 1e-6 * np.linalg.norm(expected)
    assert preload.relative_mismatch <= 1e-6


def test_thrust_reaches_the_pylon_through_the_rear_pins(preloaded):
    _, preload = preloaded
    forces = preload.hinge_forces
    # front and rear links stand in y-z planes: the thrust goes through the
    # thrust rods onto the rear left/right pins, less what the links' tilt carries
    rear_pins = forces["rear-up-left"][0] + forces["rear-up-right"][0]
    assert rear_pins == pytest.approx(23_000.0, rel=0.02)
    assert forces["thrust-aft-left"][0] == pytest.approx(forces["thrust-aft-right"][0], rel=1e-3)
    # the front mount carries more of the weight than the rear (centre of gravity forward)
    front = -(forces["front-up-left"][2] + forces["front-up-right"][2])
    assert front > 0.35 * -preload.pylon_force[2]


def _force_on_link(scene, link, hinge):
    """Force of *hinge* on *link*: +connector force on marker 0, minus on marker 1."""
    first = hinge.body_a if hinge.body_b != "pylon" else hinge.body_b
    sign = 1.0 if first == link else -1.0
    return sign * scene.hinge_forces()[hinge.name]


def test_weightless_links_are_two_force_members(reference):
    """Ball-jointed links carry force only along the line through their eye
    centres (in the deformed position): checks markers, hinge signs and eyes."""
    weight = PointForce("engine weight", (0.0, 0.0, -3568.0 * 9.81), ENGINE_CG)
    loads = tuple(load for load in reference.static_loads if not isinstance(load, Gravity)) + (weight,)
    scene = build_scene(dataclasses.replace(reference, static_loads=loads))
    solve_preload(scene)
    import exudyn as exu

    scale = max(np.linalg.norm(f) for f in scene.hinge_forces().values())
    for link in reference.links:
        items = scene.links[link.name]
        eyes = {"a": np.zeros(3), "b": np.zeros(3)}
        for hinge in reference.hinges:
            if link.name in hinge.bodies:
                eyes[link.eye_at(hinge.position)] += _force_on_link(scene, link.name, hinge)
        position = {e: np.array(scene.mbs.GetMarkerOutput(m, exu.OutputVariableType.Position))
                    for e, m in (("a", items.marker_a), ("b", items.marker_b))}
        axis = (position["b"] - position["a"]) / np.linalg.norm(position["b"] - position["a"])
        np.testing.assert_allclose(eyes["a"] + eyes["b"], 0.0, atol=1e-6 * scale, err_msg=link.name)
        assert np.linalg.norm(np.cross(eyes["a"], axis)) < 1e-6 * scale, link.name
        # under these symmetric loads only the lateral link idles
        if link.name == "rear-lateral":
            assert np.linalg.norm(eyes["a"]) < 1e-3 * scale
        else:
            assert np.linalg.norm(eyes["a"]) > 0.1 * scale, link.name


def test_symmetric_mount_gives_mirror_image_hinge_forces(reference):
    """Without its lateral link the mount is left-right symmetric; thrust on
    the axis and gravity are symmetric loads."""
    case = reference.without_link("rear-lateral")
    scene = build_scene(case)
    forces = solve_preload(scene).hinge_forces
    scale = max(np.linalg.norm(f) for f in forces.values())
    pairs = [name for name in forces if "left" in name]
    assert len(pairs) == 6
    for left in pairs:
        right = forces[left.replace("left", "right")]
        np.testing.assert_allclose(forces[left], MIRROR * right, atol=1e-6 * scale, err_msg=left)
    for middle in ("rear-up-middle", "rear-down-middle"):
        assert abs(forces[middle][1]) < 1e-6 * scale
        assert abs(forces[middle][2]) > 1000.0


def test_reference_has_six_mounted_modes_well_below_the_lp_rotor(preloaded):
    scene, _ = preloaded
    # the harmonic model's linearisation: it holds the hinges' loss factors (a static scene has no
    # excitation frequency at which to build their viscous equivalent)
    modes = modes_of(harmonic_model(scene).linearization)
    mounted = mounted_modes(modes)
    assert len(mounted) == 6
    frequencies = [m.frequency_hz for m in mounted]
    assert 3.0 < min(frequencies) and max(frequencies) < 59.0 / 2
    assert all(0.005 < m.damping_ratio < 0.15 for m in mounted)


def test_one_link_removed_is_a_mechanism(reference):
    # the left thrust rod's aft eye hangs on the rear-left link's pylon-side eye
    case = reference.without_link("rear-left").with_rigid_links()
    with pytest.raises(MechanismError, match="thrust-left") as error:
        solve_preload(build_scene(case))
    assert len(error.value.motions) == 2          # the dangling rod swings in two planes
    assert "too soft" not in str(error.value)


def test_a_hinge_too_soft_to_hold_its_link_is_named_in_the_mechanism(reference):
    # 50 N/m holds the rear-left link (a few kg) above the free-motion limit (0.05 Hz), though not the engine it joins
    soft, firm = "front-up-left", "rear-down-left"
    stiffness = {soft: 1e-3, firm: 50.0}
    hinges = tuple(dataclasses.replace(h, stiffness=stiffness.get(h.name, h.stiffness)) for h in reference.hinges)
    case = dataclasses.replace(reference, hinges=hinges).with_rigid_links()
    with pytest.raises(MechanismError) as error:
        solve_preload(build_scene(case))
    assert ("Hinges too soft to hold the lighter body they join (it alone would move on them below the "
            f"free-motion limit): '{soft}' (0.001 N/m); check") in str(error.value)
    assert firm not in str(error.value)


def test_engine_without_thrust_rods_is_free_to_move_forward(reference):
    case = reference.without_link("thrust-left").without_link("thrust-right").with_rigid_links()
    with pytest.raises(MechanismError, match=r"engine heading translation \(x\)") as error:
        solve_preload(build_scene(case))
    assert len(error.value.motions) == 1


def test_equilibrium_check_stops_the_run():
    applied = np.array([23_000.0, 0.0, -35_000.0])
    assert check_equilibrium("c", applied * (1 + 1e-9), applied, 1e-6, 1.0) < 1e-6
    with pytest.raises(EquilibriumError, match=r"hinge forces sum to .*relative mismatch 1.00e-02"):
        check_equilibrium("c", applied * 1.01, applied, 1e-6, 1.0)
