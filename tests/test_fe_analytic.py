"""Finite element assembly against analytic solutions (real scikit-fem, no mocks).

Bars are meshed with scikit-fem's structured quadratic tetrahedra; the
reference link with gmsh. Frequencies use flexbodies.eigen. A shift of a few
hundred Hz (between the rigid-body modes and the first elastic one) is
passed explicitly: it is valid for free bodies and converges faster than
eigen's default shift.
"""
import math

import numpy as np
import pytest
import skfem

from flexbodies.assembly import FEModel, assemble
from flexbodies.eigen import natural_frequencies
from flexbodies.geometry import LinkGeometry
from flexbodies.materials import STEEL, TITANIUM, Material, material
from flexbodies.meshing import BodyMesh, mesh_link

# Prismatic bar: 0.5 m long, 20 mm x 20 mm (slenderness L/h = 25, L/r = 87).
# Timoshenko (shear + rotary inertia) lowers the first cantilever frequency
# by ~0.1 %, and the lateral inertia (Love) lowers the axial one by 0.012 %.
BAR_LENGTH = 0.5
BAR_SIDE = 0.02
# The prototype test link: a 300 mm steel link whose prototype model weighed
# 2.87 kg and had its first free-free mode at 1031 Hz (converged).
REFERENCE = LinkGeometry(length=0.30, eye_outer_radius=0.030, bore_radius=0.015,
                         thickness=0.025, shank_width=0.040, shank_thickness=0.025)


def _bar_mesh(mesh_cls, nx: int, nyz: int):
    """Structured bar along x from 0 to BAR_LENGTH, centred on the x axis."""
    x = np.linspace(0.0, BAR_LENGTH, nx + 1)
    yz = np.linspace(-BAR_SIDE / 2, BAR_SIDE / 2, nyz + 1)
    if mesh_cls is skfem.MeshTet2:
        return skfem.MeshTet2.from_mesh(skfem.MeshTet1.init_tensor(x, yz, yz))
    if mesh_cls is skfem.MeshHex2:
        return skfem.MeshHex2.from_mesh(skfem.MeshHex1.init_tensor(x, yz, yz))
    return mesh_cls.init_tensor(x, yz, yz)


@pytest.fixture(scope="module")
def bar() -> FEModel:
    """Quadratic-tetrahedron bar, 50 x 2 x 2 cells (7575 DOF)."""
    return assemble(BodyMesh(_bar_mesh(skfem.MeshTet2, 50, 2)), STEEL)


@pytest.fixture(scope="module")
def reference_link() -> FEModel:
    return assemble(mesh_link(REFERENCE), STEEL)


def _cantilever_euler_bernoulli_hz(material: Material) -> float:
    inertia, area = BAR_SIDE**4 / 12, BAR_SIDE**2
    return 1.8751**2 / (2 * math.pi * BAR_LENGTH**2) * math.sqrt(
        material.youngs_modulus * inertia / (material.density * area))


def _clamped_x0(model: FEModel) -> np.ndarray:
    """All DOF of the nodes on the face x = 0."""
    return np.flatnonzero(np.repeat(model.nodes[:, 0] < 1e-12, 3))


def _field(model: FEModel, fn) -> np.ndarray:
    """Node-major DOF vector of a displacement field fn(x, y, z) -> (ux, uy, uz)."""
    x, y, z = model.nodes.T
    return np.column_stack(fn(x, y, z)).ravel()


# --- materials ------------------------------------------------------------------


def test_material_presets_and_lookup():
    assert material("Steel") is STEEL and material(" TITANIUM ") is TITANIUM
    assert (TITANIUM.youngs_modulus, TITANIUM.poisson_ratio, TITANIUM.density) == (114e9, 0.34, 4430.0)
    assert STEEL.shear_modulus == pytest.approx(210e9 / 2.6)
    with pytest.raises(ValueError, match="unknown material 'brass'.*steel, titanium"):
        material("brass")


@pytest.mark.parametrize("kwargs, words", [
    (dict(youngs_modulus=0.0), "Young's modulus must be a positive"),
    (dict(density=-1.0), "density must be a positive"),
    (dict(poisson_ratio=0.5), "Poisson's ratio must lie strictly between -1 and 0.5"),
    (dict(poisson_ratio=-1.0), "Poisson's ratio"),
])
def test_material_validation(kwargs, words):
    values = dict(name="x", youngs_modulus=1e9, poisson_ratio=0.3, density=1000.0) | kwargs
    with pytest.raises(ValueError, match=words):
        Material(**values)


# --- matrices against exact fields -------------------------------------------------


def test_bar_mass_matrix_is_exact(bar):
    assert bar.total_mass == pytest.approx(STEEL.density * BAR_LENGTH * BAR_SIDE**2, rel=1e-12)
    assert bar.ndof == 3 * bar.nodes.shape[0] == bar.mass.shape[0]


def test_strain_energy_of_linear_fields_is_exact(bar):
    """Node-major component order and the elasticity law, from fields P2 represents exactly."""
    volume = BAR_LENGTH * BAR_SIDE**2
    lam, mu = STEEL.lame_lambda, STEEL.shear_modulus
    zero = np.zeros(bar.nodes.shape[0])
    cases = [
        (lambda x, y, z: (1e-3 * x, zero, zero), 0.5 * (lam + 2 * mu) * 1e-6 * volume),  # stretch x
        (lambda x, y, z: (zero, 1e-3 * x, zero), 0.5 * mu * 1e-6 * volume),  # shear x-y
        (lambda x, y, z: (zero, zero, 1e-3 * z), 0.5 * (lam + 2 * mu) * 1e-6 * volume),  # stretch z
        (lambda x, y, z: (-1e-3 * y, 1e-3 * x, zero), 0.0),  # rigid rotation about z
    ]
    scale = 0.5 * (lam + 2 * mu) * 1e-6 * volume
    for field, energy in cases:
        u = _field(bar, field)
        assert 0.5 * u @ (bar.stiffness @ u) == pytest.approx(energy, abs=1e-9 * scale)
    assert abs(bar.stiffness - bar.stiffness.T).max() == 0.0


def test_bar_free_free_axial_frequency(bar):
    """First axial mode c/(2L); the 6 rigid-body modes come out at ~0 Hz."""
    freqs, modes = natural_frequencies(bar.stiffness, bar.mass, 18, shift_hz=100.0)
    assert np.all(freqs[:6] < 0.05) and freqs[6] > 400.0
    axial_share = [_axial_kinetic_share(bar, modes[:, k]) for k in range(6, 18)]
    axial = freqs[6 + int(np.argmax(np.array(axial_share) > 0.9))]
    expected = math.sqrt(STEEL.youngs_modulus / STEEL.density) / (2 * BAR_LENGTH)
    assert axial == pytest.approx(expected, rel=1e-3)  # measured -0.012 % (Love's lateral inertia)


def _axial_kinetic_share(model: FEModel, mode: np.ndarray) -> float:
    axial = np.zeros_like(mode)
    axial[0::3] = mode[0::3]
    return float(axial @ (model.mass @ axial) / (mode @ (model.mass @ mode)))


def test_bar_cantilever_first_bending_frequency(bar):
    freqs, _ = natural_frequencies(bar.stiffness, bar.mass, 2, fixed=_clamped_x0(bar), shift_hz=10.0)
    expected = _cantilever_euler_bernoulli_hz(STEEL)
    # Square section: two equal bending modes. Measured +0.16 % (mesh) and
    # ~ -0.1 % Timoshenko; the brief allows 2 %.
    assert freqs == pytest.approx([expected, expected], rel=5e-3)


def test_quadratic_hexahedra_cantilever():
    """Quadratic hexahedra (27 points per element by default) converge as well."""
    model = assemble(BodyMesh(_bar_mesh(skfem.MeshHex2, 20, 1)), TITANIUM)
    freqs, _ = natural_frequencies(model.stiffness, model.mass, 1, fixed=_clamped_x0(model), shift_hz=10.0)
    assert freqs[0] == pytest.approx(_cantilever_euler_bernoulli_hz(TITANIUM), rel=5e-3)
    assert model.description.startswith("quadratic hexahedra")


def test_linear_tetrahedra_lock_in_bending():
    """Why quadratic elements are required: linear tetrahedra are far too stiff."""
    model = assemble(BodyMesh(_bar_mesh(skfem.MeshTet1, 50, 2)), STEEL)
    freqs, _ = natural_frequencies(model.stiffness, model.mass, 1, fixed=_clamped_x0(model), shift_hz=10.0)
    assert freqs[0] > 1.2 * _cantilever_euler_bernoulli_hz(STEEL)  # measured +30 %


def test_mirrored_elements_are_accepted_and_tangled_ones_rejected():
    mesh = skfem.MeshHex1.init_tensor(*[np.linspace(0.0, 0.01, 3)] * 3)
    reference = assemble(BodyMesh(mesh), STEEL).stiffness
    # Mirror every element (swap the two 4-node faces): valid, same matrix.
    t = mesh.t.copy()
    bottom, top = _opposite_hex_faces(mesh)
    t[bottom + top] = mesh.t[top + bottom]
    mirrored = assemble(BodyMesh(skfem.MeshHex1(mesh.doflocs, t)), STEEL).stiffness
    assert abs(mirrored - reference).max() <= 1e-9 * abs(reference).max()
    # Swap two diagonally opposite corners of one element: tangled.
    t = mesh.t.copy()
    t[[bottom[0], top[2]], 0] = t[[top[2], bottom[0]], 0]
    with pytest.raises(ValueError, match="1 of 8 elements are tangled"):
        assemble(BodyMesh(skfem.MeshHex1(mesh.doflocs, t), source="twisted.vtu"), STEEL)


def _opposite_hex_faces(mesh):
    """Local corner indices of the faces x = min and x = max of element 0, in matching order."""
    corners = mesh.doflocs[:, mesh.t[:, 0]]
    low = [int(i) for i in np.flatnonzero(corners[0] == corners[0].min())]
    high = [int(np.flatnonzero((corners[0] == corners[0].max()) & (corners[1] == corners[1, i])
                               & (corners[2] == corners[2, i]))[0]) for i in low]
    return low, high


# --- the reference link --------------------------------------------------------------


def test_reference_link_mass_matches_geometry(reference_link):
    # Analytic volume of the modelled solid (eye rings + shank outside the
    # eyes) is 3.5083e-4 m^3, 2.754 kg of steel. The prototype model
    # weighed 2.87 kg (built differently).
    assert reference_link.total_mass == pytest.approx(STEEL.density * REFERENCE.volume, rel=1e-4)
    assert reference_link.total_mass == pytest.approx(2.754, abs=2e-3)


def test_reference_link_free_free_frequency(reference_link):
    freqs, _ = natural_frequencies(reference_link.stiffness, reference_link.mass, 8, shift_hz=200.0)
    assert np.all(freqs[:6] < 0.1)
    # The prototype model: 1031 Hz converged. This geometry converges to
    # 1040.9 Hz (+1 %, mass 4 % lower than the prototype's).
    assert freqs[6] == pytest.approx(1031.0, rel=0.03)
    assert freqs[6] == pytest.approx(1040.9, rel=2e-3)
    assert reference_link.description == (
        f"quadratic tetrahedra, {reference_link.nodes.shape[0]} nodes, {reference_link.ndof} DOF")
    assert 15_000 <= reference_link.ndof <= 25_000


@pytest.mark.slow
def test_reference_link_mesh_convergence(reference_link):
    """Default size against a 7 mm mesh (~33k DOF): first two modes within 1 %."""
    fine = assemble(mesh_link(REFERENCE, element_size=0.007), STEEL)
    assert fine.ndof > 1.5 * reference_link.ndof
    default, _ = natural_frequencies(reference_link.stiffness, reference_link.mass, 8, shift_hz=200.0)
    finer, _ = natural_frequencies(fine.stiffness, fine.mass, 8, shift_hz=200.0)
    assert default[6:] == pytest.approx(finer[6:], rel=1e-2)  # measured 0.01-0.03 %


@pytest.mark.parametrize("mesh_cls", [skfem.MeshTet2, skfem.MeshHex2, skfem.MeshTet1])
def test_assembly_equals_scikit_fems_forms(mesh_cls):
    """The batched element matrices equal scikit-fem's own assembly of the elasticity and mass forms."""
    from flexbodies.validation import scikit_fem_matrices

    mesh = _bar_mesh(mesh_cls, 4, 2)
    model = assemble(BodyMesh(mesh), TITANIUM)
    stiffness, mass = scikit_fem_matrices(mesh, TITANIUM)
    for ours, theirs in ((model.stiffness, stiffness), (model.mass, mass)):
        assert abs(ours - theirs).max() <= 1e-12 * abs(theirs).max()
