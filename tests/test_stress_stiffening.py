"""Stress stiffening of flexible links: the geometric stiffness of an axial
preload against the pinned-pinned beam, and in the mount."""
import dataclasses

import numpy as np
import pytest
import skfem
from conftest import COARSE_ELEMENT_SIZE
from excel_helpers import copy_reference, set_cells

import flexbodies.geometric_stiffness as geometric_stiffness
from flexbodies import LinkGeometry, LinkModel, reduce_link, reduce_link_set
from flexbodies.geometric_stiffness import link_stiffening, mesh_stiffening, stiffened
from flexbodies.materials import STEEL
from flexbodies.meshing import BodyMesh, Bore
from workbook.cli.main import main
from workbook.errors import EXIT_TROUBLE, BucklingError, CaseError, WorkbookError, exit_code
from workbook.excel.reader import read_workbook
from workbook.model.case import AnalysisSettings, Effects
from workbook.model.codec import to_json
from workbook.model.reference import LP_ROTOR
from workbook.solve.modes import mounted_modes
from workbook.solve.pipeline import prepare, run_case
from workbook.solve.stress_stiffening import AUTO_SHIFT, TENSION_TOLERANCE

#: A slender steel bar, 0.6 m long, 20 x 20 mm: Euler load 76.8 kN.
BAR_LENGTH, BAR_SIDE = 0.6, 0.02
EULER_LOAD = np.pi ** 2 * STEEL.youngs_modulus * BAR_SIDE ** 4 / 12 / BAR_LENGTH ** 2


def _bar() -> BodyMesh:
    """Quadratic tetrahedra, 40 x 2 x 2 boxes; each end face is a "bore" tied to a master at its centre."""
    mesh = skfem.MeshTet2.from_mesh(skfem.MeshTet.init_tensor(
        np.linspace(0.0, BAR_LENGTH, 41), *[np.linspace(-BAR_SIDE / 2, BAR_SIDE / 2, 3)] * 2))
    points = mesh.doflocs.T

    def end(name, x):
        nodes = np.flatnonzero(np.isclose(points[:, 0], x))
        return Bore(name, np.array([x, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), BAR_SIDE / 2, nodes,
                    np.full(len(nodes), BAR_SIDE ** 2 / len(nodes)))

    return BodyMesh(mesh, (end("A", 0.0), end("B", BAR_LENGTH)), "bar")


@pytest.fixture(scope="module")
def bar():
    # RBE3: the end faces contract freely, so the stress is the bar's uniform P / A
    return mesh_stiffening(_bar(), STEEL, "RBE3")


def _beam(f0, tension, n):
    """Pinned-pinned Euler-Bernoulli beam under tension: f_n = f_n0 sqrt(1 + P L^2 / (n^2 pi^2 E I))."""
    return f0 * np.sqrt(1.0 + tension / (n ** 2 * EULER_LOAD))


@pytest.mark.parametrize("tension", [0.5 * EULER_LOAD, EULER_LOAD, 2.0 * EULER_LOAD])
def test_tension_raises_the_bending_modes_as_the_beam_formula_says(bar, tension):
    unloaded, loaded = bar.pinned_hz(0.0, 4), bar.pinned_hz(tension, 4)
    # the square bar bends alike in both planes: modes 1-2 are n = 1, modes 3-4 n = 2
    for n, index in ((1, 0), (2, 2)):
        assert loaded[index] == pytest.approx(_beam(unloaded[index], tension, n), rel=5e-3)
    assert loaded[0] > 1.2 * unloaded[0]


def test_compression_lowers_the_bending_modes_and_the_first_vanishes_at_the_euler_load(bar):
    unloaded, pushed = bar.pinned_hz(0.0, 3), bar.pinned_hz(-0.5 * EULER_LOAD, 3)
    assert pushed[0] < 0.75 * unloaded[0]
    assert pushed[0] == pytest.approx(_beam(unloaded[0], -0.5 * EULER_LOAD, 1), rel=5e-3)
    assert pushed[2] == pytest.approx(_beam(unloaded[2], -0.5 * EULER_LOAD, 2), rel=5e-3)
    assert bar.buckling_load == pytest.approx(EULER_LOAD, rel=5e-3)
    assert abs(bar.pinned_hz(-bar.buckling_load, 1)[0]) < 1e-3 * unloaded[0]
    assert bar.pinned_hz(-1.05 * bar.buckling_load, 1)[0] < 0
    assert bar.first_mode_shift(-bar.buckling_load) == pytest.approx(-1.0, abs=1e-3)


# --- in the mount ----------------------------------------------------------------------------------------

def _with(case, setting, **analysis):
    effects = dataclasses.replace(case.effects, stress_stiffening=setting)
    return dataclasses.replace(case, effects=effects, analysis=dataclasses.replace(case.analysis, **analysis))


def _shank_euler_factor(case, name, tension):
    """sqrt(1 + P L^2 / (pi^2 E I)) of the link's shank (its weaker bending plane) over the eye distance."""
    model = case.link_map[name].model
    g = model.geometry
    inertia = min(g.shank_width * g.shank_thickness ** 3, g.shank_thickness * g.shank_width ** 3) / 12
    return np.sqrt(1.0 + tension * g.length ** 2 / (np.pi ** 2 * model.material.youngs_modulus * inertia))


def _thrust_rod_modes(prepared):
    return [m.frequency_hz for m in prepared.modes
            if m.body_shares.get("thrust-left", 0) + m.body_shares.get("thrust-right", 0) > 0.95]


@pytest.fixture(scope="module")
def stiffened_and_not(coarse_reference):
    """The coarse reference mount prepared for LP with the effect on auto and off."""
    out = {}
    for setting in ("auto", "off"):
        prepared = prepare(_with(coarse_reference, setting), LP_ROTOR)
        with prepared.scene:
            out[setting] = (prepared.preload, _thrust_rod_modes(prepared),
                            prepared.model.result(LP_ROTOR, 0.01).transmissibility)
    return out


@pytest.mark.slow
def test_the_thrust_rods_tension_stiffens_them_as_the_beam_formula_says(coarse_reference, stiffened_and_not):
    preload, stiffened_modes, stiffened_t = stiffened_and_not["auto"]
    _, plain_modes, plain_t = stiffened_and_not["off"]
    record = preload.stiffening
    links = {link.name: link for link in record.links}
    assert set(links) == {link.name for link in coarse_reference.links}
    assert record.passes == 1 and record.tension_change < TENSION_TOLERANCE
    for name in ("thrust-left", "thrust-right"):
        rod = links[name]
        assert 11e3 < rod.tension < 12.5e3, rod          # pulled by the 23 kN thrust
        assert rod.stiffened and rod.shift > AUTO_SHIFT
        # pinned-pinned first mode against the beam formula with the shank's E I
        factor = _shank_euler_factor(coarse_reference, name, rod.tension)
        assert rod.loaded_hz / rod.unloaded_hz == pytest.approx(factor, rel=5e-4)
        assert rod.buckling_load > 20 * rod.tension
    # the short links carry less and are stiffer: auto leaves them alone
    assert all(not link.stiffened and abs(link.shift) < AUTO_SHIFT
               for name, link in links.items() if not name.startswith("thrust"))
    # in the mount the rods' first bending pair (weaker plane) rises too, by less than pinned-pinned: their
    # eyes sit on hinge springs, whose stiffness the tension does not change
    factor = _shank_euler_factor(coarse_reference, "thrust-left", links["thrust-left"].tension)
    assert len(plain_modes) == len(stiffened_modes) >= 2
    for plain, stiff in zip(plain_modes[:2], stiffened_modes[:2], strict=True):
        assert 1.0 + 0.5 * (factor - 1.0) < stiff / plain < factor
    # and LP T_y, which the rods carry, moves by about a per cent
    assert abs(stiffened_t[1] / plain_t[1] - 1.0) > 0.005
    assert stiffened_t[0] == pytest.approx(plain_t[0], rel=1e-3)


def _slender_and_pushed(case):
    """Titanium thrust rods with a 12 x 12 mm shank (Euler load 1.6 kN), and the thrust reversed so they push."""
    links = tuple(
        dataclasses.replace(link, model=dataclasses.replace(link.model, geometry=dataclasses.replace(
            link.model.geometry, shank_width=0.012, shank_thickness=0.012)))
        if link.name.startswith("thrust") else link for link in case.links)
    loads = tuple(dataclasses.replace(load, force=tuple(-f for f in load.force)) if load.name == "thrust" else load
                  for load in case.static_loads)
    return dataclasses.replace(case, links=links, static_loads=loads)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["frequency", "time"])
def test_a_link_pushed_beyond_its_buckling_load_stops_the_run_in_words(coarse_reference, method):
    case = _with(_slender_and_pushed(coarse_reference), "auto", method=method)
    with pytest.raises(BucklingError) as caught:
        run_case(dataclasses.replace(case, excitations=(LP_ROTOR,)))
    error = caught.value
    assert error.link.startswith("thrust-")
    euler = _shank_euler_factor(case, error.link, 1.0) ** 2 - 1.0   # 1 / P_E of the shank, 1/N
    assert error.buckling_load == pytest.approx(1.0 / euler, rel=0.15)
    assert error.compression > 5 * error.buckling_load
    message = str(error)
    for part in (repr(error.link), f"{error.compression / 1e3:.4g} kN", f"{error.buckling_load / 1e3:.4g} kN",
                 f"{error.compression / error.buckling_load:.3g} times"):
        assert part in message
    assert exit_code(error) == EXIT_TROUBLE
    # switched off, the same case answers (the links keep their unloaded stiffness)
    result = run_case(dataclasses.replace(_with(_slender_and_pushed(coarse_reference), "off"), excitations=(LP_ROTOR,)))
    (entry,) = [e for e in result.model_cards[LP_ROTOR.name].effects if e.name == "link stress stiffening"]
    assert not entry.on and entry.detail.startswith("switched off")


def test_the_setting_is_checked():
    with pytest.raises(CaseError, match="stress_stiffening"):
        Effects(stress_stiffening="yes")


def test_a_workbook_switches_it(tmp_path):
    path = copy_reference(tmp_path)
    assert read_workbook(path).case.effects.stress_stiffening == "auto"
    set_cells(path, {("Case", "stress stiffening", 3): "off"})
    assert read_workbook(path).case.effects.stress_stiffening == "off"
    set_cells(path, {("Case", "stress stiffening", 3): "sometimes"})
    with pytest.raises(WorkbookError, match="stress stiffening"):
        read_workbook(path)


@pytest.mark.slow
def test_the_geometric_stiffness_is_cached_and_a_damaged_entry_recomputed(tmp_path):
    model = LinkModel(geometry=LinkGeometry(length=0.20, eye_outer_radius=0.025, bore_radius=0.012, thickness=0.020,
                                            shank_width=0.030, shank_thickness=0.020), element_size=0.012)
    link = reduce_link(model, 4, cache_dir=tmp_path)
    first = link_stiffening(model, cache_dir=tmp_path)
    (entry,) = tmp_path.glob("stiffening-*.npz")
    assert link_stiffening(model, cache_dir=tmp_path).buckling_load == first.buckling_load
    entry.write_bytes(b"not an archive")
    again = link_stiffening(model, cache_dir=tmp_path)
    assert again.buckling_load == pytest.approx(first.buckling_load, rel=1e-9)
    # the stiffened body: K_r + P K_G,r, linear in P and symmetric
    base = np.asarray(link.ffrf["stiffnessMatrixReduced"])
    pulled = stiffened(link, again, 1e4).ffrf["stiffnessMatrixReduced"]
    pushed = stiffened(link, again, -1e4).ffrf["stiffnessMatrixReduced"]
    np.testing.assert_allclose(pulled + pushed, 2 * base, rtol=1e-12, atol=1e-9 * np.abs(base).max())
    np.testing.assert_allclose(pulled, pulled.T, rtol=0, atol=1e-12 * np.abs(base).max())
    assert np.abs(pulled - base).max() > 1e-6 * np.abs(base).max()


@pytest.mark.slow
def test_the_projected_geometric_stiffness_is_kept_beside_it_and_a_damaged_one_recomputed(tmp_path):
    """K_G,r of a reduction is kept beside the stiffening's cache file: a later process reads it
    (no sparse product), equal to the projection; a damaged file is recomputed and replaced."""
    model = LinkModel(geometry=LinkGeometry(length=0.20, eye_outer_radius=0.025, bore_radius=0.012, thickness=0.020,
                                            shank_width=0.030, shank_thickness=0.020), element_size=0.02)
    link = reduce_link(model, 4, cache_dir=tmp_path)
    stiffening = link_stiffening(model, cache_dir=tmp_path)
    assert not list(tmp_path.glob("stiffening-*.npy"))
    base = np.asarray(link.ffrf["stiffnessMatrixReduced"])
    pulled = stiffened(link, stiffening, 1e4).ffrf["stiffnessMatrixReduced"]
    (kept,) = tmp_path.glob("stiffening-*.npy")
    projected = link_stiffening(model, use_cache=False).project(link.mode_basis)
    np.testing.assert_allclose(np.load(kept), projected, rtol=1e-7, atol=1e-9 * np.abs(projected).max())
    np.testing.assert_array_equal(pulled, base + 1e4 * np.load(kept))

    def in_a_new_process():
        """The stiffened matrix as a new process makes it (the files alone, nothing in memory), and
        whether it made the sparse G (that is, projected it)."""
        geometric_stiffness._memory.clear()
        geometric_stiffness._projections.clear()
        loaded = link_stiffening(model, cache_dir=tmp_path)
        return stiffened(link, loaded, 1e4).ffrf["stiffnessMatrixReduced"], "scalar" in vars(loaded)

    again, projected_again = in_a_new_process()
    np.testing.assert_array_equal(again, pulled)
    assert not projected_again
    kept.write_bytes(b"not an array")
    again, projected_again = in_a_new_process()
    np.testing.assert_array_equal(again, pulled)
    assert projected_again and np.load(kept).shape == (link.n_modes, link.n_modes)
    other = reduce_link(model, 2, cache_dir=tmp_path)      # another mode basis: a file of its own
    stiffened(other, link_stiffening(model, cache_dir=tmp_path), 1e4)
    assert len(list(tmp_path.glob("stiffening-*.npy"))) == 2


def test_the_reduction_keeps_the_geometric_stiffness_of_its_own_factorisation(tmp_path):
    """Reduced with ``stiffening=True`` the link's geometric stiffness is cached from the reduction's
    FE model and factorisation, equal to the one computed on its own; nothing is computed twice."""
    model = LinkModel(geometry=LinkGeometry(length=0.20, eye_outer_radius=0.025, bore_radius=0.012, thickness=0.020,
                                            shank_width=0.030, shank_thickness=0.020), element_size=0.02)
    assert not list(tmp_path.glob("stiffening-*.npz"))
    reduce_link_set(model, "static", (50.0,), cache_dir=tmp_path, stiffening=True)
    (entry,) = tmp_path.glob("stiffening-*.npz")
    kept = link_stiffening(model, cache_dir=tmp_path)
    alone = link_stiffening(model, use_cache=False)
    assert kept.buckling_load == pytest.approx(alone.buckling_load, rel=1e-9)
    np.testing.assert_allclose(kept.pinned_geometric, alone.pinned_geometric, rtol=1e-7,
                               atol=1e-9 * np.abs(alone.pinned_geometric).max())
    difference = abs(kept.scalar - alone.scalar).max()
    assert difference <= 1e-9 * abs(alone.scalar).max()


@pytest.mark.slow
def test_the_command_line_exits_1_with_the_buckling_in_words(coarse_reference, tmp_path, capsys):
    path = tmp_path / "slender.json"
    path.write_text(to_json(dataclasses.replace(_slender_and_pushed(coarse_reference), excitations=(LP_ROTOR,))))
    assert main(["run", str(path), "--json", "--no-progress"]) == 1
    out, err = capsys.readouterr()
    assert out == "" and "buckles" in err and "times its buckling load" in err and "Traceback" not in err


@pytest.mark.slow
def test_the_rebuilt_scene_keeps_the_loss_factors_exact_in_the_frequency_domain(cache_dir):
    """The stiffened scene of a frequency-domain run leaves the hinges' loss factor to the
    structural matrix H: every mounted mode (hinge-dominated) has zeta close to eta / 2, not the
    viscous equivalent's eta f / (2 f_exc), and the card says the loss factor is exact."""
    from workbook.model.reference import HINGE_LOSS_FACTOR, reference_case

    case = dataclasses.replace(reference_case(element_size=COARSE_ELEMENT_SIZE), excitations=(LP_ROTOR,))
    prepared = prepare(case, LP_ROTOR)
    with prepared.scene:
        assert any(link.stiffened for link in prepared.preload.stiffening.links)
        assert prepared.scene.loss_factor_hz is None and prepared.model.linearization.structural is not None
        zeta = [m.damping_ratio for m in mounted_modes(prepared.modes)]
    np.testing.assert_allclose(zeta, HINGE_LOSS_FACTOR / 2, rtol=0.05)
    card = run_case(dataclasses.replace(case, analysis=AnalysisSettings(method="frequency"))).model_cards["LP rotor"]
    detail = next(e for e in card.effects if e.name == "hinge loss factor")
    assert "exact at every frequency" in detail.detail
