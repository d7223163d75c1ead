"""Link stresses from the reduced coordinates (flexbodies.stress) against closed forms and the full FE model."""
import numpy as np
import pytest
import scipy.sparse.linalg as spla

from flexbodies import STEEL, LinkGeometry, LinkModel
from flexbodies.errors import LinkModelError
from flexbodies.link import _meshed_fe_model, reduce_link
from flexbodies.materials import Material
from flexbodies.reduced import load_reduced_body, save_reduced_body
from flexbodies.reduction import couple
from flexbodies.stress import link_regions, max_principal, nodal_stress_operator, state_stress, von_mises

#: A slender, coarse link: a long shank so that mid-span is far from the eyes (Saint-Venant).
BAR = LinkGeometry(length=0.30, eye_outer_radius=0.025, bore_radius=0.012, thickness=0.020, shank_width=0.030,
                   shank_thickness=0.020)
MODEL = LinkModel(geometry=BAR, element_size=0.012)
AREA = BAR.shank_width * BAR.shank_thickness


@pytest.fixture(scope="module")
def reduced(cache_dir):
    return reduce_link(MODEL, modes=4, cache_dir=cache_dir)


@pytest.fixture(scope="module")
def full():
    fe, link_mesh, rotation, _ = _meshed_fe_model(MODEL)
    return couple(fe), nodal_stress_operator(link_mesh, MODEL.material, rotation)


def _clamped_solve(coupled, force_b):
    """Full FE static solve: eye A's master held, a force (N, link frame) on eye B's master."""
    c = coupled.coupling
    free = np.setdiff1d(np.arange(c.n_q), c.master_dofs[0])
    f = np.zeros(c.n_q)
    f[c.master_dofs[1, :3]] = force_b
    u = np.zeros(c.n_q)
    u[free] = spla.spsolve(coupled.stiffness[free][:, free].tocsc(), f[free])
    return c.transform @ u


def _axial_state(link, force):
    """Modal coordinates of a tension *force* (N) between the eyes: K_r q = Phi^T f (self-equilibrated)."""
    f = np.zeros(3 * len(link.nodes))
    a, b = link.master_nodes[:2]
    f[3 * b], f[3 * a] = force, -force
    return np.linalg.solve(np.asarray(link.ffrf["stiffnessMatrixReduced"]), link.mode_basis.T @ f)


def _mid_shank(nodes, half=0.03):
    return np.abs(nodes[:, 0] - BAR.length / 2) < half


def test_bar_in_tension_gives_f_over_a(reduced):
    force = 1000.0
    stress = state_stress(reduced, _axial_state(reduced, force))
    nodes = reduced.nodes[: reduced.master_nodes[0]]
    mid = _mid_shank(nodes)
    assert mid.sum() > 20
    np.testing.assert_allclose(stress[mid, 0], force / AREA, rtol=1e-5)
    assert np.abs(stress[mid, 1:]).max() < 1e-5 * force / AREA
    np.testing.assert_allclose(von_mises(stress[mid]), force / AREA, rtol=1e-5)
    np.testing.assert_allclose(max_principal(stress[mid]), force / AREA, rtol=1e-5)
    # the peak is at a bore, above the nominal stress
    regions = link_regions(reduced)
    assert regions[np.argmax(von_mises(stress))] in (0, 2) and von_mises(stress).max() > 1.2 * force / AREA


def test_reduced_static_stress_equals_the_full_fe_solve(reduced, full):
    coupled, operator = full
    force = 2500.0
    full_stress = operator.of(_clamped_solve(coupled, [force, 0.0, 0.0]))[:, :, 0]
    reduced_stress = state_stress(reduced, _axial_state(reduced, force))
    scale = np.abs(full_stress).max()
    assert np.abs(reduced_stress - full_stress).max() < 1e-7 * scale


def test_cantilever_in_bending_gives_mc_over_i(reduced, full):
    coupled, operator = full
    force = 200.0
    u = _clamped_solve(coupled, [0.0, force, 0.0])
    # the cantilever's field lies in the Craig-Bampton span: its modal coordinates are its mass projection
    n = int(reduced.master_nodes[0])
    phi = reduced.mode_basis[: 3 * n]
    q = phi.T @ (coupled.fe_model.mass @ u)
    stress = state_stress(reduced, q)
    nodes = reduced.nodes[:n]
    w, t, length = BAR.shank_width, BAR.shank_thickness, BAR.length
    inertia = t * w**3 / 12
    fibre = _mid_shank(nodes) & (np.abs(np.abs(nodes[:, 1]) - w / 2) < 1e-9)
    assert fibre.sum() > 10
    expected = -force * (length - nodes[fibre, 0]) * nodes[fibre, 1] / inertia     # M = F (L - x), sigma = -M y / I
    np.testing.assert_allclose(stress[fibre, 0], expected, rtol=0.03)
    np.testing.assert_allclose(stress, operator.of(u)[:, :, 0], atol=1e-7 * np.abs(stress).max())


def test_stress_shapes_survive_the_file(reduced, tmp_path):
    loaded = load_reduced_body(save_reduced_body(reduced, tmp_path / "link.npz"))
    assert loaded.stress_modes.shape == (reduced.master_nodes[0], 6, reduced.n_modes)
    np.testing.assert_array_equal(loaded.stress_modes, reduced.stress_modes)


def test_strengths_do_not_change_the_reduction_key():
    weaker = Material("steel", 210e9, 0.3, 7850.0, yield_strength=200e6, ultimate_strength=300e6)
    assert LinkModel(geometry=BAR, material=weaker).key() == LinkModel(geometry=BAR, material=STEEL).key()
    with pytest.raises(LinkModelError, match="ultimate strength"):
        Material("x", 210e9, 0.3, 7850.0, yield_strength=500e6, ultimate_strength=400e6)
    with pytest.raises(LinkModelError, match="yield strength"):
        Material("x", 210e9, 0.3, 7850.0, yield_strength=-1.0)


def test_largest_principal_in_closed_form_equals_the_eigen_solve():
    rng = np.random.default_rng(3)
    stress = rng.standard_normal((2000, 6)) * 1e8
    stress[:3] = [[1e8, 1e8, 1e8, 0, 0, 0], [0, 0, 0, 0, 0, 0], [2e8, -1e8, -1e8, 0, 0, 1e-3]]   # degenerate states
    tensor = np.empty((len(stress), 3, 3))
    for row, (a, b) in enumerate(((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))):
        tensor[:, a, b] = tensor[:, b, a] = stress[:, row]
    np.testing.assert_allclose(max_principal(stress), np.linalg.eigvalsh(tensor)[:, -1], rtol=0, atol=1e-12 * 1e9)


def test_regions_are_made_once_per_link_mesh(reduced):
    first, second = link_regions(reduced), link_regions(reduced)
    assert first is second and not first.flags.writeable
    assert set(np.unique(first)) == {0, 1, 2}
