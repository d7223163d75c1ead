"""The flexible engine: the casing's FE frequencies against beam theory, the engine's mass
properties kept, a stiff casing recovering the rigid engine, both domains, and bad input."""
import dataclasses
import json
import subprocess
import sys

import numpy as np
import pytest
from excel_helpers import copy_reference, set_cells
from openpyxl import load_workbook

from flexbodies.casing import CasingGeometry, CasingInterface, mesh_casing
from flexbodies.casing_reduction import CasingModel, reduce_casing
from flexbodies.materials import STEEL, TITANIUM
from workbook.errors import CaseError, WorkbookError
from workbook.excel.reader import read_workbook
from workbook.excel.template import case_workbook, write_workbook
from workbook.model.casing import CASING, parallel_axis, split_engine
from workbook.model.codec import to_json
from workbook.model.reference import HP_ROTOR, LP_ROTOR, reference_case, reference_casing
from workbook.scene.build import build_scene
from workbook.solve.four_pole import mount_case
from workbook.solve.pipeline import prepare, run_case

#: beta L of the first free-free bending mode of a uniform beam.
BETA_L = 4.730040745

#: The reference casing, coarse (0.12 m elements, one through the wall).
COARSE_CASING = reference_casing(element_size=0.12)


def _with_casing(case, casing):
    return dataclasses.replace(case, engine=dataclasses.replace(case.engine, casing=casing))


def _tube_first_hz(length, radius, thickness, element_size):
    """First free-free elastic frequency of a steel tube reduced with two bearing planes (Hz), and its
    Euler-Bernoulli value."""
    interfaces = tuple(CasingInterface(f"plane {k}", (x * length, 0.0, 0.0), "bearing", element_size)
                       for k, x in enumerate((0.2, 0.8)))
    model = CasingModel(interfaces, geometry=CasingGeometry(radius, thickness, 0.0, length), material=STEEL,
                        element_size=element_size)
    (reduced,) = reduce_casing(model, "static", [1.0], use_cache=False)
    inner = radius - thickness
    second_moment, area = np.pi / 4 * (radius ** 4 - inner ** 4), np.pi * (radius ** 2 - inner ** 2)
    beam = BETA_L ** 2 / (2 * np.pi * length ** 2) * np.sqrt(STEEL.youngs_modulus * second_moment
                                                             / (STEEL.density * area))
    return reduced.frequencies["free_free_hz"], beam, reduced


@pytest.mark.slow
def test_a_coarse_tube_bends_free_free_as_a_beam():
    """Tolerance 2 %: the coarse mesh (about 16 mm quadratic tetrahedra on a 12 mm wall) is
    stiff by a few tenths of a percent, and the tube's shear and rotary inertia, which
    Euler-Bernoulli leaves out, lower its first mode by up to about
    (beta r_g / L)^2 (1 + E / (kappa G)) / 2 = 1.4 % (L / r_g = 69, kappa = 0.5)."""
    hz, beam, reduced = _tube_first_hz(1.2, 0.03, 0.012, 0.02)
    # the bending pair (two planes) first, at the same frequency
    assert hz[1] == pytest.approx(hz[0], rel=2e-3)
    assert hz[0] == pytest.approx(beam, rel=0.02)
    inner = 0.03 - 0.012
    assert reduced.mass == pytest.approx(STEEL.density * np.pi * (0.03 ** 2 - inner ** 2) * 1.2, rel=2e-3)


@pytest.mark.slow
def test_a_long_tube_converges_on_the_beam_as_the_mesh_is_refined():
    """A 1.5 m steel tube of 30 mm radius and 10 mm wall (L / r_g = 83): each refinement
    moves the first frequency less than the one before, downwards (the FE model is too stiff),
    and the finest is within 1 % of Euler-Bernoulli, whose neglect of shear and rotary inertia
    is worth up to about (beta r_g / L)^2 (1 + E / (kappa G)) / 2 = 1 % here."""
    runs = [_tube_first_hz(1.5, 0.03, 0.01, size) for size in (0.016, 0.012, 0.009)]
    first, beam = [hz[0] for hz, _, _ in runs], runs[0][1]
    steps = np.diff(first)
    assert np.all(steps < 0)
    assert abs(steps[1]) < abs(steps[0])
    assert first[-1] == pytest.approx(beam, rel=0.01)


def test_the_core_is_the_engine_less_the_casing():
    """The split of known bodies: two point masses on a rod make the engine; the casing is one
    of them, the core must be the other."""
    a, b, ma, mb = np.array([0.4, 0.1, 0.0]), np.array([-0.6, 0.0, 0.2]), 300.0, 700.0
    own_a, own_b = np.diag([5.0, 7.0, 9.0]), np.diag([11.0, 13.0, 17.0])
    mass = ma + mb
    cg = (ma * a + mb * b) / mass
    inertia = own_a + parallel_axis(ma, a - cg) + own_b + parallel_axis(mb, b - cg)
    core = split_engine(mass, cg, inertia, ma, a, own_a)
    assert core.mass == pytest.approx(mb, rel=1e-12)
    np.testing.assert_allclose(core.centre_of_mass, b, atol=1e-12)
    np.testing.assert_allclose(core.inertia, own_b, atol=1e-9)
    with pytest.raises(CaseError, match="lighter than the engine"):
        split_engine(mass, cg, inertia, 1.01 * mass, a, own_a)
    with pytest.raises(CaseError, match="positive definite"):
        split_engine(mass, cg, inertia, ma, a, 100 * own_b)


@pytest.mark.slow
def test_casing_and_core_in_the_scene_make_the_engine(coarse_reference):
    """Mass, CG and inertia of the engine from the bodies Exudyn holds, to 1e-9."""
    import exudyn as exu

    case = _with_casing(dataclasses.replace(coarse_reference, excitations=(LP_ROTOR,)), COARSE_CASING)
    with build_scene(case, LP_ROTOR) as scene:
        mbs, engine = scene.mbs, case.engine
        core = mbs.GetObject(scene.engine.body)
        node = np.array(mbs.GetNodeOutput(scene.engine.node, exu.OutputVariableType.Position))
        core_centre = node + np.array(core["centerOfMass"])
        jxx, jyy, jzz, jyz, jxz, jxy = core["inertia"]
        core_at_node = np.array([[jxx, jxy, jxz], [jxy, jyy, jyz], [jxz, jyz, jzz]])
        reduced, casing_mass = scene.casing.reduced, scene.casing.casing.mass
        frame = np.array(mbs.GetNodeOutput(scene.casing.casing.nodes[0], exu.OutputVariableType.Position))
        casing_centre = frame + reduced.centre_of_mass
        mass = core["mass"] + casing_mass
        cg = (core["mass"] * core_centre + casing_mass * casing_centre) / mass
        about_cg = (core_at_node - parallel_axis(core["mass"], core_centre - node)
                    + parallel_axis(core["mass"], core_centre - cg)
                    + reduced.inertia_at_origin - parallel_axis(casing_mass, reduced.centre_of_mass)
                    + parallel_axis(casing_mass, casing_centre - cg))
        assert scene.body_dof()[CASING] == reduced.dof
    assert mass == pytest.approx(engine.mass, rel=1e-9)
    np.testing.assert_allclose(cg, engine.center_of_mass, atol=1e-9)
    np.testing.assert_allclose(about_cg, engine.inertia_matrix, rtol=0, atol=1e-9 * engine.inertia_matrix.max())


def _transmissibility(case, excitation):
    prepared = prepare(case, excitation)
    with prepared.scene:
        return prepared.model.result(excitation, case.analysis.steady_tolerance).transmissibility


@pytest.mark.slow
def test_a_stiff_casing_is_the_rigid_engine_and_a_soft_one_is_not(coarse_reference):
    """E x 1e4 and bearings of 1e12 N/m and a 20 kHz spin restraint put every mode inside the
    engine at 4.5 kHz or more; at 248.5 Hz they change T by O((248.5 / 4500)^2) = 0.3 %, at 59 Hz
    by 0.02 %: rtol 0.5 %. The real titanium casing changes the HP answer by more than 5 %."""
    stiff = dataclasses.replace(COARSE_CASING, material=dataclasses.replace(
        TITANIUM, youngs_modulus=1e4 * TITANIUM.youngs_modulus), bearing_stiffness=(1e12, 1e12), core_spin_hz=2e4)
    for excitation in (LP_ROTOR, HP_ROTOR):
        rigid = _transmissibility(coarse_reference, excitation)
        np.testing.assert_allclose(_transmissibility(_with_casing(coarse_reference, stiff), excitation), rigid,
                                   rtol=5e-3, err_msg=excitation.name)
    soft = _transmissibility(_with_casing(coarse_reference, COARSE_CASING), HP_ROTOR)
    assert np.max(np.abs(soft / _transmissibility(coarse_reference, HP_ROTOR) - 1)) > 0.05


@pytest.mark.slow
def test_time_and_frequency_domain_agree_with_a_flexible_engine(coarse_reference):
    case = _with_casing(dataclasses.replace(coarse_reference, excitations=(LP_ROTOR,)), COARSE_CASING)
    runs = {method: run_case(dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method=method)))
            for method in ("time", "frequency")}
    td, fd = runs["time"].run("LP rotor"), runs["frequency"].run("LP rotor")
    assert td.steady
    np.testing.assert_allclose(fd.transmissibility, td.transmissibility, rtol=0.01)
    card = runs["frequency"].model_cards["LP rotor"].to_dict()
    effects = {e["name"]: e for e in card["effects"]}
    assert effects["flexible engine"]["on"] and "first free-free casing mode" in effects["flexible engine"]["detail"]
    assert [b["name"] for b in card["bodies"]][:2] == ["engine", CASING]


def test_the_rigid_engine_stays_the_default(coarse_reference):
    assert coarse_reference.engine.casing is None
    with build_scene(coarse_reference, LP_ROTOR) as scene:
        assert scene.casing is None and CASING not in scene.body_dof()


# --- bad input ------------------------------------------------------------------------------------------------


def _run_cli(case_file):
    return subprocess.run([sys.executable, "-m", "workbook.cli.main", "run", "--no-progress", str(case_file)],
                          capture_output=True, text=True, timeout=300)


def _bad_json(coarse_reference, tmp_path, **changes):
    """The coarse reference mount with the coarse casing changed, as a JSON case file (not validated:
    the JSON is edited after encoding, as a user would)."""
    data = json.loads(to_json(_with_casing(coarse_reference, COARSE_CASING)))
    casing = data["engine"]["casing"]
    for path, value in changes.items():
        *parents, last = path.split(".")
        target = casing
        for key in parents:
            target = target[key]
        target[last] = value
    path = tmp_path / "case.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("changes, named", [
    ({"geometry.thickness": 0.3}, ["engine casing", "geometry", "lighter than the engine"]),
    ({"geometry.radius": 0.3, "geometry.thickness": 0.02}, ["hinge 'thrust-forward-left'", "position",
                                                             "mount eye on the engine casing"]),
    ({"geometry": None, "mesh": "no-such-casing.msh"}, ["engine casing", "mesh", "no-such-casing.msh",
                                                          "an existing mesh file"]),
    ({"bearing_planes": [0.35, 2.0]}, ["engine casing", "bearing_planes[1]", "within the casing"]),
])
def test_bad_casing_input_names_the_field_and_exits_2(coarse_reference, tmp_path, changes, named):
    done = _run_cli(_bad_json(coarse_reference, tmp_path, **changes))
    assert done.returncode == 2, done.stderr
    for words in named:
        assert words in done.stderr
    assert "Traceback" not in done.stderr


def test_a_mesh_without_surface_at_an_eye_is_refused(tmp_path):
    """A user's mesh that does not reach a mount eye: the error names the eye and the file."""
    tube = mesh_casing(CasingGeometry(0.1, 0.02, 0.0, 0.4), 0.04)
    path = tmp_path / "tube.vtu"
    tube.to_meshio().write(path)
    interfaces = (CasingInterface("eye far away", (0.2, 0.0, 0.5), "eye", 0.05),
                  CasingInterface("bearing", (0.2, 0.0, 0.0), "bearing", 0.04))
    with pytest.raises(ValueError, match=r"tube.vtu: interface 'eye far away': no casing surface within 0.05 m"):
        reduce_casing(CasingModel(interfaces, mesh_file=str(path)), "static", [1.0], use_cache=False)


def test_the_four_pole_set_refuses_a_flexible_engine(coarse_reference):
    """The four-pole set (and a flexible pylon, which closes it) takes the rigid engine's points."""
    with pytest.raises(CaseError, match="field 'casing'.*four-pole"):
        mount_case(_with_casing(coarse_reference, COARSE_CASING))


# --- the Excel case workbook ----------------------------------------------------------------------------------


def test_a_casing_row_is_read_and_written_back(tmp_path):
    """The Engine casing sheet: a case with the reference casing writes to it and reads back the same."""
    case = _with_casing(reference_case(), reference_casing(element_size=0.12, modes="static"))
    path = tmp_path / "casing.xlsx"
    write_workbook(case_workbook(case, []), path)
    wb = load_workbook(path)
    wb["Runs"].append(["LP", "LP rotor"])
    wb.save(path)
    assert read_workbook(path).case.engine == case.engine


@pytest.mark.parametrize("edits, named", [
    ({("Engine casing", "bearing 2 x", 3): 3.0}, ["sheet 'Engine casing'", "cell L3", "column 'bearing 2 x'",
                                                    "within the casing"]),
    ({("Engine casing", "wall thickness", 3): -5}, ["sheet 'Engine casing'", "column 'wall thickness'", "> 0"]),
])
def test_a_bad_casing_cell_is_named(tmp_path, edits, named):
    path = copy_reference(tmp_path)
    row = {("Engine casing", header, 3): value for header, value in (
        ("radius", 500), ("wall thickness", 25), ("x start", -1.8), ("x end", 0.7), ("front ring x", 0.0),
        ("front ring width", 80), ("front ring radius", 620), ("rear ring x", -1.72), ("rear ring width", 80),
        ("rear ring radius", 580), ("bearing 1 x", 0.35), ("bearing 2 x", -1.2), ("element size", 120),
        ("bearing band", 40))}
    set_cells(path, row)
    assert read_workbook(path).case.engine.casing == reference_casing(element_size=0.12)
    set_cells(path, edits)
    with pytest.raises(WorkbookError) as error:
        read_workbook(path)
    for words in named:
        assert words in str(error.value)


@pytest.mark.slow
def test_the_reduced_casing_stiffness_is_linear_in_its_modulus():
    """Two Craig-Bampton reductions of a tube with two bearing planes and four fixed-interface modes,
    at E and 1.3 E: the reduced stiffness scales by 1.3, the reduced mass and the mode shapes do not
    change (so the casing's modulus acts on the reduced casing as a factor on its stiffness)."""
    interfaces = tuple(CasingInterface(f"plane {k}", (x, 0.0, 0.0), "bearing", 0.02) for k, x in enumerate((0.1, 0.4)))
    reduced = [reduce_casing(CasingModel(interfaces, geometry=CasingGeometry(0.03, 0.012, 0.0, 0.5),
                                         material=dataclasses.replace(STEEL, youngs_modulus=factor * 210e9),
                                         element_size=0.02), 4, [1.0], use_cache=False)[0]
               for factor in (1.0, 1.3)]
    stiffness, mass = ([np.asarray(r.ffrf[key], dtype=float) for r in reduced]
                       for key in ("stiffnessMatrixReduced", "massMatrixReduced"))
    assert stiffness[0].shape[0] >= 4
    np.testing.assert_allclose(stiffness[1], 1.3 * stiffness[0], rtol=0, atol=1e-10 * np.abs(stiffness[0]).max())
    np.testing.assert_allclose(mass[1], mass[0], rtol=0, atol=1e-12 * np.abs(mass[0]).max())
    shapes = [np.asarray(r.mode_basis) for r in reduced]
    signs = np.sign(np.sum(shapes[0] * shapes[1], axis=0))
    np.testing.assert_allclose(shapes[1], shapes[0] * signs, rtol=0, atol=1e-8 * np.abs(shapes[0]).max())
