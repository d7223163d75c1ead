"""Simulate only the effects a scene calls for: what is off is not built.

Each test inspects the Exudyn system a case builds (real items, read back
from Exudyn) for an effect switched on, off, or not asked for, and the
model card's record of it.
"""
import dataclasses

import numpy as np
import pytest

from workbook.model.reference import LP_ROTOR, reference_case
from workbook.scene.build import build_scene
from workbook.solve.pipeline import run_excitation
from workbook.solve.preload import solve_preload

#: Every effect the model card accounts for (docs/physics.md, section 4).
EFFECTS = {"link flexibility", "static preload", "hinge damping", "hinge loss factor",
           "hinge properties per direction", "link damping", "link modal damping", "link material loss factor", "hinge clearance",
           "flexible engine", "link spin restraints", "gyroscopic rotor", "test-rig force-sensor compliance",
           "link stress stiffening", "limit load cases", "link fatigue",
           "time domain", "frequency domain", "imbalance planes", "simultaneous excitations"}


@pytest.fixture(scope="module")
def rigid(coarse_reference):
    return coarse_reference.with_rigid_links()


def _effects(case, **switches):
    return dataclasses.replace(case, effects=dataclasses.replace(case.effects, **switches))


def _gaps(case, gap):
    return dataclasses.replace(case, hinges=tuple(dataclasses.replace(h, radial_clearance=gap)
                                                  for h in case.hinges))


def _spring_laws(scene):
    return [scene.mbs.GetObjectParameter(items.connector, "springForceUserFunction")
            for items in scene.hinges.values()]


@pytest.mark.slow
def test_no_contact_law_without_clearance(rigid):
    plain = build_scene(rigid, LP_ROTOR)
    assert all(law == 0 for law in _spring_laws(plain))
    gapped = build_scene(_gaps(rigid, 30e-6), LP_ROTOR)
    assert all(law != 0 for law in _spring_laws(gapped))
    ignored = build_scene(_effects(_gaps(rigid, 30e-6), clearance=False), LP_ROTOR)
    assert all(law == 0 for law in _spring_laws(ignored))


def test_no_static_loads_without_preload(rigid):
    loaded = build_scene(rigid, LP_ROTOR)
    unloaded = build_scene(_effects(rigid, preload=False), LP_ROTOR)
    # thrust, and gravity on the engine and each of the 8 links; the excitation is one more load
    assert loaded.mbs.systemData.NumberOfLoads() == 1 + 1 + 9
    assert unloaded.mbs.systemData.NumberOfLoads() == 1 and not unloaded.static_loads
    assert not solve_preload(unloaded).solved


def test_no_hinge_damping_when_switched_off(rigid):
    damped = build_scene(rigid, LP_ROTOR)
    undamped = build_scene(_effects(rigid, hinge_damping=False), LP_ROTOR)
    damping = lambda scene: [scene.mbs.GetObjectParameter(i.connector, "damping") for i in scene.hinges.values()]  # noqa: E731
    assert all(np.all(np.asarray(d) > 0) for d in damping(damped))
    assert all(np.all(np.asarray(d) == 0) for d in damping(undamped))


@pytest.mark.slow
def test_the_low_frequency_rule_builds_no_fixed_interface_modes(cache_dir):
    """At 59 Hz the front and rear links (mounted f1 above 600 Hz) meet the
    rule and carry static modes only; the thrust rods (f1 about 100 Hz) do not."""
    scene = build_scene(reference_case(), LP_ROTOR)
    for name, reduced in scene.reduced.items():
        modal = len(scene.mbs.GetNodeOutput(scene.links[name].nodes[1], _coordinates()))
        static_modes = modal - reduced.n_fixed_interface
        if name.startswith("thrust"):
            assert reduced.decision.ratio >= 0.25 and reduced.n_fixed_interface > 0
        else:
            assert reduced.decision.ratio < 0.25 and reduced.n_fixed_interface == 0
            assert modal == static_modes


def _coordinates():
    import exudyn as exu

    return exu.OutputVariableType.Coordinates


@pytest.mark.slow
def test_no_link_damping_when_switched_off(coarse_reference):
    case = coarse_reference
    damped_links = dataclasses.replace(case, links=tuple(dataclasses.replace(link, stiffness_damping=1e-5)
                                                         for link in case.links))
    on = build_scene(damped_links, LP_ROTOR)
    off = build_scene(_effects(damped_links, link_damping=False), LP_ROTOR)
    def largest_damping(scene):
        matrix = scene.mbs.GetObjectParameter(scene.links["thrust-left"].body, "dampingMatrixReduced")
        return np.abs(np.asarray(matrix.Convert2DenseMatrix())).max(initial=0.0)

    assert largest_damping(on) > 0 and largest_damping(off) == 0


def test_rigid_links_build_no_modal_coordinates(rigid):
    scene = build_scene(rigid, LP_ROTOR)
    assert all(link.dof == 6 and not link.flexible for link in scene.links.values())
    # engine 6, each rigid link 7 (Euler parameters)
    assert scene.mbs.systemData.ODE2Size() == 6 + 7 * len(rigid.links)


def test_the_model_card_lists_every_effect_with_its_reason(rigid):
    card = run_excitation(_effects(_gaps(rigid, 30e-6), hinge_damping=False), LP_ROTOR).model_card
    entries = {e.name: e for e in card.effects}
    assert set(entries) == EFFECTS
    assert entries["hinge clearance"].on and "hinge damping" in entries and not entries["hinge damping"].on
    assert entries["hinge damping"].detail == "switched off"
    assert not entries["link flexibility"].on and "rigid" in entries["link flexibility"].detail
    assert not entries["link stress stiffening"].on and entries["link stress stiffening"].detail == "no flexible link"
    assert not entries["flexible engine"].on and "rigid body" in entries["flexible engine"].detail
    assert (entries["limit load cases"].detail, entries["link fatigue"].detail) == ("none given", "no flexible link")
    assert all(e.detail for e in card.effects)
