"""The pylon as a user's solid mesh, reduced to its compliance at the pins.

Closed forms: a clamped square bar's static compliance at a pin bore near
its tip (axial L / EA; bending L^3 / 3EI plus shear L / (k G A)). The whole
mount: a very stiff mesh is the rigid pylon, a soft one changes the answer.
Bad meshes are refused naming the field. A second run loads the reduction
from the cache of the reduced bodies, bit for bit.
"""
import dataclasses
import json
import pickle
import subprocess
import sys

import gmsh
import numpy as np
import pytest
from test_sdof import sdof_case

from flexbodies.materials import Material
from flexbodies.pylon_reduction import MINIMUM_MODES, reduce_pylon
from workbook.cli.main import main
from workbook.errors import EXIT_BAD_INPUT, CaseError
from workbook.model.case import AnalysisSettings, HarmonicForce
from workbook.model.codec import from_json, to_json
from workbook.model.pylon_beam import BoxBeamPylon
from workbook.model.pylon_mesh import MeshPylon, mesh_pylon_model
from workbook.solve.pipeline import run_case

STEEL_BAR = Material("steel", youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
#: The bar: 1 m from its clamped root to the pin bore, a 50 mm square, 40 mm beyond the bore.
LENGTH, SIDE, BEYOND, BORE_RADIUS = 1.0, 0.05, 0.04, 0.01
#: Shear coefficient of a rectangular section (Timoshenko).
SHEAR_COEFFICIENT = 5 / 6


def _mesh(path, boxes, bores, size):
    """A gmsh quadratic-tetrahedron mesh of boxes ((x0, y0, z0), (dx, dy, dz)) with vertical bores
    ((x, y), radius) through them, written to *path*."""
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("pylon")
        solids = [(3, gmsh.model.occ.addBox(*corner, *extent)) for corner, extent in boxes]
        if len(solids) > 1:
            solids, _ = gmsh.model.occ.fuse(solids[:1], solids[1:])
        low = min(c[2] for c, _ in boxes) - 1.0
        holes = [(3, gmsh.model.occ.addCylinder(x, y, low, 0.0, 0.0, 3.0, radius)) for (x, y), radius in bores]
        gmsh.model.occ.cut(solids, holes)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.option.setNumber("Mesh.MeshSizeMin", size / 2)
        gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)  # straight-sided: no element tangled by curving
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.setOrder(2)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


def _bar(tmp_path, size=0.0125):
    path = _mesh(tmp_path / "bar.msh", [((0.0, -SIDE / 2, -SIDE / 2), (LENGTH + BEYOND, SIDE, SIDE))],
                 [((LENGTH, 0.0), BORE_RADIUS)], size)
    return MeshPylon(str(path), root_point=(0.0, 0.0, 0.0), root_normal=(1.0, 0.0, 0.0), bore_axis=(0.0, 0.0, 1.0),
                     bore_radius=BORE_RADIUS, material=STEEL_BAR, loss_factor=0.0, name="bar")


@pytest.mark.slow
def test_a_clamped_bar_has_the_cantilevers_static_compliance_at_its_pin(tmp_path):
    pylon = _bar(tmp_path)
    structure, facts = mesh_pylon_model(pylon, [(LENGTH, 0.0, 0.0)], highest_hz=50.0)
    compliance = structure.compliance([0.0])[0].real
    e, area, inertia = STEEL_BAR.youngs_modulus, SIDE ** 2, SIDE ** 4 / 12
    shear = STEEL_BAR.youngs_modulus / (2 * (1 + STEEL_BAR.poisson_ratio))
    axial = LENGTH / (e * area)
    bending = LENGTH ** 3 / (3 * e * inertia) + LENGTH / (SHEAR_COEFFICIENT * shear * area)
    # 4 quadratic elements across the section: bending within 2 %; the bore (rigid, RBE2) shortens the
    # bar's flexible length by up to its radius, 1 % of the length: axial compliance within 3 %
    assert compliance[0, 0] == pytest.approx(axial, rel=0.03)
    assert compliance[1, 1] == pytest.approx(bending, rel=0.02)
    assert compliance[2, 2] == pytest.approx(bending, rel=0.02)
    assert abs(compliance[0, 1]) < 1e-3 * bending
    assert facts["reduced_dof"] == 6 + facts["modes"]


@pytest.mark.slow
def test_the_reduced_compliance_is_the_full_fe_compliance_below_the_cutoff(tmp_path):
    """Craig-Bampton with modes up to 4 x the highest frequency against a reduction keeping far more."""
    pylon = _bar(tmp_path, size=0.02)
    kept, kept_facts = mesh_pylon_model(pylon, [(LENGTH, 0.0, 0.0)], highest_hz=30.0)
    many, many_facts = mesh_pylon_model(pylon, [(LENGTH, 0.0, 0.0)], highest_hz=2000.0)
    assert many_facts["modes"] > kept_facts["modes"] == MINIMUM_MODES
    # up to the highest frequency asked for, 30 Hz, near the bar's first bending mode on its pin (about 40 Hz)
    for a, b in zip(kept.compliance([5.0, 20.0, 30.0]), many.compliance([5.0, 20.0, 30.0]), strict=True):
        assert np.abs(a - b).max() <= 1e-4 * np.abs(b).max()


#: A second process: the pickled pylon model reduced from the cache, its arrays saved, and whether it was
#: loaded and whether scikit-fem (meshing and assembly) was imported.
SECOND_RUN = """
import json, pickle, sys
import numpy as np
from flexbodies.pylon_reduction import reduce_pylon
model, highest, cache, out = pickle.load(open(sys.argv[1], "rb"))
reduced = reduce_pylon(model, highest, cache_dir=cache)
np.savez(out, **reduced.arrays())
print(json.dumps({"cache_hit": reduced.cache_hit, "skfem": "skfem" in sys.modules}))
"""


def test_a_second_run_loads_the_reduced_pylon_from_the_cache(tmp_path, monkeypatch):
    pylon = _bar(tmp_path, size=0.02)
    model, cache = pylon.model([(LENGTH, 0.0, 0.0)]), tmp_path / "cache"
    monkeypatch.setenv("MOUNTWB_CACHE", str(cache))
    first = reduce_pylon(model, 30.0)
    assert not first.cache_hit and len(list(cache.glob("clamped-*.npz"))) == 1
    (tmp_path / "job.pickle").write_bytes(pickle.dumps((model, 30.0, cache, tmp_path / "second.npz")))
    done = subprocess.run([sys.executable, "-c", SECOND_RUN, str(tmp_path / "job.pickle")], capture_output=True,
                          text=True, check=True)
    assert json.loads(done.stdout) == {"cache_hit": True, "skfem": False}, "the second run reduced the pylon again"
    with np.load(tmp_path / "second.npz") as second:
        for name, value in first.arrays().items():
            np.testing.assert_array_equal(second[name], value, err_msg=name)
    # the pylon as a case prepares it: from the cache; another frequency range is another mode rule, another entry
    structure, facts = mesh_pylon_model(pylon, [(LENGTH, 0.0, 0.0)], 30.0)
    assert facts["cache_hit"] and np.array_equal(structure.stiffness, first.stiffness)
    assert not mesh_pylon_model(pylon, [(LENGTH, 0.0, 0.0)], 300.0)[1]["cache_hit"]


def _plate_case(tmp_path, modulus=70e9):
    """The single-DOF engine whose four pins hang in bores of a plate, clamped on the top of a column on it."""
    base = sdof_case(())
    pins = [position for position, _ in base.pylon_pins()]
    xs, ys = [p[0] for p in pins], [p[1] for p in pins]
    z = pins[0][2]
    plate = ((min(xs) - 0.1, min(ys) - 0.1, z - 0.02), (max(xs) - min(xs) + 0.2, max(ys) - min(ys) + 0.2, 0.04))
    middle = (np.mean(xs), np.mean(ys))
    column = ((middle[0] - 0.1, middle[1] - 0.1, z + 0.02), (0.2, 0.2, 0.2))   # clamped on its top face
    path = _mesh(tmp_path / f"plate-{modulus:g}.msh", [plate, column], [((p[0], p[1]), 0.012) for p in pins], 0.05)
    material = Material("aluminium", youngs_modulus=modulus, poisson_ratio=0.33, density=2800.0)
    pylon = MeshPylon(str(path), root_point=(0.0, 0.0, z + 0.22), root_normal=(0.0, 0.0, 1.0),
                      bore_axis=(0.0, 0.0, 1.0), bore_radius=0.012, material=material, loss_factor=0.02, name="plate")
    cg = base.engine.center_of_mass
    excitations = tuple(HarmonicForce(f"{f:g} Hz", point=cg, direction=(0.3, 0.2, 1.0), amplitude=1000.0,
                                      frequency_hz=f) for f in (3.0, 10.5, 25.0))
    return dataclasses.replace(base, excitations=excitations, analysis=AnalysisSettings(method="auto"),
                               pylon=pylon)


@pytest.mark.slow
def test_a_stiff_mesh_is_the_rigid_pylon_and_a_soft_one_is_not(tmp_path):
    stiff = _plate_case(tmp_path, modulus=7e16)
    rigid = run_case(dataclasses.replace(stiff, pylon=None))
    on_stiff = run_case(stiff)
    soft = run_case(_plate_case(tmp_path, modulus=2e8))
    for run in rigid.runs:
        np.testing.assert_allclose(on_stiff.run(run.name).transmissibility, run.transmissibility, rtol=1e-5)
        assert max(abs(soft.run(run.name).transmissibility / run.transmissibility - 1)) > 0.01
    card = on_stiff.model_cards[rigid.runs[0].name]
    assert any(e.name == "flexible pylon (mesh)" for e in card.effects)


def test_a_mesh_pylon_round_trips_through_json_and_bad_ones_are_refused(tmp_path, capsys):
    case = _plate_case(tmp_path)
    assert from_json(to_json(case)) == case
    with pytest.raises(CaseError, match="bore_radius"):
        dataclasses.replace(case.pylon, bore_radius=-1.0)
    with pytest.raises(CaseError, match="root_normal"):
        dataclasses.replace(case.pylon, root_normal=(0.0, 0.0, 0.0))
    pins = [position for position, _ in case.pylon_pins()]
    with pytest.raises(CaseError, match="root_point"):
        mesh_pylon_model(dataclasses.replace(case.pylon, root_point=(0.0, 0.0, 5.0)), pins, 30.0)
    with pytest.raises(CaseError, match="every pylon pin"):
        mesh_pylon_model(dataclasses.replace(case.pylon, bore_radius=0.02), pins, 30.0)
    beam = BoxBeamPylon(root=(0.0, 0.0, 3.0), tip=case.engine.center_of_mass, width=0.05, height=0.05, wall=0.002,
                        material=STEEL_BAR, up=(1.0, 0.0, 0.0))
    with pytest.raises(CaseError, match="one pylon model"), pytest.warns(DeprecationWarning, match="Case.pylon"):
        dataclasses.replace(case, pylon_beam=beam)
    # from the command line: a mesh file that does not exist, exit 2 and the file named
    data = json.loads(to_json(dataclasses.replace(case, pylon=dataclasses.replace(
        case.pylon, path=str(tmp_path / "no-such.msh")))))
    (tmp_path / "case.json").write_text(json.dumps(data))
    assert main(["run", str(tmp_path / "case.json")]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "pylon mesh 'plate', field 'path'" in err and "no-such.msh" in err


def test_the_time_domain_refuses_a_mesh_pylon(tmp_path):
    case = _plate_case(tmp_path)
    with pytest.raises(CaseError, match="no pylon mesh in the time domain"):
        run_case(dataclasses.replace(case, analysis=AnalysisSettings(method="time")))
