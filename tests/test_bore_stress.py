"""Bore stress under a pin's bearing load (flexbodies.bore_stress): a pin-loaded lug against Peterson's chart,
the bearing load's resultant, and the bore peak's convergence on meshes refined at the bores."""
import numpy as np
import pytest

from flexbodies import STEEL, LinkGeometry, LinkModel
from flexbodies.assembly import assemble
from flexbodies.bore_stress import BORE_DIVISIONS, bearing_load, bore_peaks, convergence_sizes
from flexbodies.eigen import factorize, free_dofs
from flexbodies.meshing import BodyMesh, BoreSpec, generate_tet10, gmsh_model, mesh_link, refine_near, skfem_mesh
from flexbodies.stress import max_principal, nodal_stress_operator

#: A square-ended lug: width H, hole d = H/2, hole centre L = H from the loaded end, held 3 H behind the
#: hole; thin (h = H/20) as the photoelastic plates of the chart.
H, D, THICKNESS = 0.040, 0.020, 0.002
END, HELD = H, 3 * H


def _frocht_hill(d_over_h: float) -> float:
    """K_tn of a closely fitting pin in a square-ended lug, L/H >= 1, 0.15 <= d/H <= 0.75: the curve fit of
    Frocht and Hill's photoelastic data in Peterson's Stress Concentration Factors (Pilkey & Pilkey, 3rd ed.,
    pin joints), on the net-section nominal stress P / ((H - d) h)."""
    x = d_over_h
    return 12.882 - 52.714 * x + 89.762 * x**2 - 51.667 * x**3


def _lug(bore_size: float | None, curvature_points: int) -> BodyMesh:
    size = H / 4
    with gmsh_model("lug") as gmsh:
        occ = gmsh.model.occ
        plate = occ.addBox(-HELD, -H / 2, -THICKNESS / 2, HELD + END, H, THICKNESS)
        hole = occ.addCylinder(0, 0, -THICKNESS, 0, 0, 2 * THICKNESS, D / 2)
        occ.cut([(3, plate)], [(3, hole)])
        occ.synchronize()
        if bore_size is not None:
            pad = 1e-6
            bore = [tag for _, tag in gmsh.model.getEntitiesInBoundingBox(
                -D / 2 - pad, -D / 2 - pad, -THICKNESS, D / 2 + pad, D / 2 + pad, THICKNESS, dim=2)]
            refine_near(bore, bore_size, size, D / 2)
        points, cells = generate_tet10(size, curvature_points)
    mesh, _ = skfem_mesh("tetra10", points, cells)
    return BodyMesh.from_skfem(mesh, [BoreSpec("pin", centre=(0, 0, 0), axis=(0, 0, 1), radius=D / 2)])


def _lug_factor(link_mesh: BodyMesh) -> float:
    """Peak largest principal stress over the net-section nominal stress, the pin pushing towards the end."""
    fe = assemble(link_mesh, STEEL)
    held = np.flatnonzero(fe.nodes[:, 0] < -HELD + 1e-9)
    free = free_dofs(fe.ndof, (3 * held[:, None] + np.arange(3)).ravel())
    force = 1000.0
    load = bearing_load(link_mesh, link_mesh.bores[0], (1.0, 0.0, 0.0), force)
    u = np.zeros(fe.ndof)
    u[free] = factorize(fe.stiffness[free][:, free].tocsc()).solve(load[free])
    stress = nodal_stress_operator(link_mesh, STEEL).of(u)[:, :, 0]
    near = np.linalg.norm(fe.nodes[:, :2], axis=1) < D
    return float(max_principal(stress)[near].max() / (force / ((H - D) * THICKNESS)))


@pytest.mark.slow
def test_pin_loaded_lug_matches_peterson_and_a_coarse_mesh_does_not():
    chart = _frocht_hill(D / H)                                     # 2.51 at d/H = 0.5
    coarse = _lug_factor(_lug(None, curvature_points=6))
    refined = [_lug_factor(_lug(2 * np.pi * (D / 2) / n, 16)) for n in BORE_DIVISIONS]
    assert abs(refined[1] / refined[0] - 1) < 0.02                  # converged between the two refined meshes
    # Within 10 %: the chart's photoelastic data and its fit (a few %), and the cosine pressure of a
    # perfectly fitting pin against the real pins' contact (a clearance narrows the arc and raises the
    # peak: the cosine load lies below the chart).
    assert abs(refined[1] / chart - 1) < 0.10
    assert abs(coarse / chart - 1) > 0.15                          # 6 elements around the hole: visibly off


def test_bearing_load_pushes_one_half_of_the_bore_with_the_given_resultant():
    geometry = LinkGeometry(length=0.30, eye_outer_radius=0.025, bore_radius=0.012, thickness=0.020,
                            shank_width=0.030, shank_thickness=0.020)
    link_mesh = mesh_link(geometry, 0.012)
    bore = link_mesh.bores[1]
    load = bearing_load(link_mesh, bore, (0.0, 1.0, 0.0), 250.0).reshape(-1, 3)
    np.testing.assert_allclose(load.sum(axis=0), [0.0, 250.0, 0.0], atol=0.5)
    loaded = np.flatnonzero(np.abs(load).sum(axis=1) > 1e-9 * np.abs(load).max())   # not the round-off
    assert np.isin(loaded, bore.nodes).all()
    assert (link_mesh.nodes[loaded, 1] > -0.004).all()   # the half the pin bears on (and its edge faces' nodes)
    assert (link_mesh.nodes[bore.nodes, 1] < -0.006).any()
    # more pressure where the surface faces the push: the cosine
    top = loaded[np.argmax(load[loaded, 1])]
    assert link_mesh.nodes[top, 1] > 0.9 * geometry.bore_radius


@pytest.mark.slow
def test_bore_peaks_per_newton_are_kept_in_the_cache(tmp_path):
    geometry = LinkGeometry(length=0.20, eye_outer_radius=0.020, bore_radius=0.010, thickness=0.012,
                            shank_width=0.025, shank_thickness=0.012)
    model = LinkModel(geometry=geometry, material=STEEL, element_size=0.008)    # coarse: the test's time
    sizes = convergence_sizes(model)
    np.testing.assert_allclose(sizes, [min(2 * np.pi * 0.010 / n, 0.008) for n in BORE_DIVISIONS])
    size = 0.008
    peaks = bore_peaks(model, size, cache_dir=tmp_path)
    net_section = 2 * (geometry.eye_outer_radius - geometry.bore_radius) * geometry.thickness
    # a pin-loaded eye of d/H = 0.5: a concentration of a few times the net-section stress, the
    # bearing (compression) side lower than the net section in tension
    assert 2.0 < peaks.tension[1] * net_section < 6.0
    assert peaks.compression[1] < peaks.tension[1]
    assert peaks.peak(-2e4) == pytest.approx(2e4 * max(peaks.compression))
    again = bore_peaks(model, size, cache_dir=tmp_path)
    assert again == peaks and len(list(tmp_path.glob("bores-*.json"))) == 1


@pytest.mark.slow
def test_load_case_bore_peaks_follow_the_axial_force_on_both_meshes(cache_dir, monkeypatch):
    from types import SimpleNamespace

    import flexbodies.bore_stress as bore_stress
    from workbook.model.case import Link
    from workbook.model.load_cases import LoadCase
    from workbook.solve.bore_convergence import CONVERGENCE_TOLERANCE, bore_convergence
    from workbook.solve.load_cases import LinkStress, LoadCaseResult

    monkeypatch.setattr(bore_stress, "BORE_DIVISIONS", (8, 10))   # a coarse pair: the test's time
    geometry = LinkGeometry(length=0.20, eye_outer_radius=0.020, bore_radius=0.010, thickness=0.012,
                            shank_width=0.025, shank_thickness=0.012)
    model = LinkModel(geometry=geometry, material=STEEL, element_size=0.008)
    case = SimpleNamespace(links=(Link("bar", (0.0, 0.0, 0.0), (0.20, 0.0, 0.0), model),
                                  Link("twin", (0.0, 1.0, 0.0), (0.20, 1.0, 0.0), model)))
    results = [LoadCaseResult(LoadCase(name), {}, np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3),
                              {"bar": LinkStress("bar", force, None, None, von_mises=1e6),
                               "twin": LinkStress("twin", -force, None, None, von_mises=1e6)}, 0.0)
               for name, force in (("pull", 2e4), ("light", 5e2))]
    study = bore_convergence(case, results)
    assert [(row.load_case, row.link) for row in study.rows] == [("pull", "bar"), ("pull", "twin"),
                                                                  ("light", "bar"), ("light", "twin")]
    assert list(study.meshes) == ["bar, twin"]                     # one model, meshed once per size
    pair = [bore_peaks(model, size, cache_dir=cache_dir) for size in convergence_sizes(model)]
    for row in study.rows:
        np.testing.assert_allclose(row.peaks, [p.peak(row.axial_force) for p in pair])
        assert row.change == pytest.approx(row.peaks[1] / row.peaks[0] - 1)
        assert row.converged == (abs(row.change) <= CONVERGENCE_TOLERANCE)
        assert row.yield_margin == pytest.approx(STEEL.yield_strength / row.peaks[1] - 1)
        assert row.ultimate_margin == pytest.approx(STEEL.ultimate_strength / (1.5 * row.peaks[1]) - 1)
    # the same relative change at any force of one sign: the peak is linear in it
    assert study.rows[0].change == pytest.approx(study.rows[2].change)
    assert study.rows[1].peaks[0] < study.rows[0].peaks[0]        # compression bears on the other half
