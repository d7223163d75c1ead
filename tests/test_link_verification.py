"""Reduced links against the full FE model (flexbodies.verification), the full FE model against closed forms.

A prismatic steel bar with its end faces tied to master nodes stands in
for a link: clamped at x = 0 and forced at x = L its tip answers the bar
(axial) and the cantilever (bending) closed forms.
"""
import math

import numpy as np
import pytest
import skfem

from flexbodies.assembly import assemble
from flexbodies.frequencies import clamped_frequencies
from flexbodies.materials import STEEL
from flexbodies.meshing import BodyMesh, Bore
from flexbodies.reduction import couple
from flexbodies.verification import verify_coupled

LENGTH, SIDE, FORCE = 0.5, 0.02, 1e5
E, RHO = STEEL.youngs_modulus, STEEL.density
AREA, INERTIA = SIDE**2, SIDE**4 / 12
WAVE_SPEED = math.sqrt(E / RHO)


def _face(mesh, name, x):
    nodes = np.flatnonzero(np.abs(mesh.doflocs[0] - x) < 1e-12)
    return Bore(name, np.array([x, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), SIDE / 2, nodes,
                np.full(len(nodes), AREA / len(nodes)))


@pytest.fixture(scope="module")
def bar():
    """Quadratic tetrahedra, 24 x 2 x 2 cells, end faces tied rigidly (RBE2) to masters A (x = 0) and B (x = L)."""
    yz = np.linspace(-SIDE / 2, SIDE / 2, 3)
    mesh = skfem.MeshTet2.from_mesh(skfem.MeshTet1.init_tensor(np.linspace(0, LENGTH, 25), yz, yz))
    fe = assemble(BodyMesh(mesh, (_face(mesh, "A", 0.0), _face(mesh, "B", LENGTH))), STEEL)
    return couple(fe, "RBE2")


@pytest.fixture(scope="module")
def axial_cb(bar):
    return verify_coupled(bar, "bar", modes=(0, 4, 12), frequencies_hz=(200.0, 2000.0), basis="cb")


def test_full_fe_axial_column_is_the_bar(axial_cb):
    # static: F L / (E A); the rigid end faces hold the Poisson contraction there: a little stiffer
    assert axial_cb.full.static == pytest.approx(FORCE * LENGTH / (E * AREA), rel=6e-3)
    # harmonic: u = F tan(k L) / (E A k), k = w / c; at 2000 Hz (0.77 of the first axial frequency c / 4 L: 0.9 % off)
    # the tangent makes it sensitive to that frequency: 1 % here is 0.2 % on it
    for f, u in zip(axial_cb.frequencies_hz, axial_cb.full.harmonic, strict=True):
        k = 2 * math.pi * f / WAVE_SPEED
        assert u == pytest.approx(FORCE * math.tan(k * LENGTH) / (E * AREA * k), rel=1.5e-2)


def test_full_fe_frequencies_are_the_packages_own_clamped_solve(bar, axial_cb):
    reference = clamped_frequencies(bar.stiffness, bar.mass, bar.coupling, interfaces=(0,), count=6)
    np.testing.assert_allclose(axial_cb.full.frequencies_hz, reference, rtol=1e-8)


def test_full_fe_bending_column_is_the_cantilever(bar):
    lateral = verify_coupled(bar, "bar", modes=(0,), frequencies_hz=(20.0,), direction=(0, 1, 0))
    f1 = 1.8751**2 / (2 * math.pi * LENGTH**2) * math.sqrt(E * INERTIA / (RHO * AREA))
    assert lateral.full.frequencies_hz[0] == pytest.approx(f1, rel=1e-2)
    assert lateral.full.static == pytest.approx(FORCE * LENGTH**3 / (3 * E * INERTIA), rel=1e-2)
    # Euler-Bernoulli tip receptance of a cantilever at 20 Hz (0.3 f1)
    beta = (RHO * AREA * (2 * math.pi * 20.0) ** 2 / (E * INERTIA)) ** 0.25
    bl = beta * LENGTH
    receptance = (math.sin(bl) * math.cosh(bl) - math.cos(bl) * math.sinh(bl)) / (
        E * INERTIA * beta**3 * (1 + math.cos(bl) * math.cosh(bl)))
    assert lateral.full.harmonic[0] == pytest.approx(FORCE * receptance, rel=1e-2)


def test_craig_bampton_static_response_is_exact_and_frequencies_converge_from_above(axial_cb):
    np.testing.assert_allclose(axial_cb.static_error(), 0.0, atol=1e-9)
    full = axial_cb.full.frequencies_hz
    previous = None
    for row in axial_cb.reduced:
        assert np.all(row.frequencies_hz[:len(full)] >= full[:len(row.frequencies_hz)] * (1 - 1e-9))  # Rayleigh-Ritz
        if previous is not None:
            assert np.all(row.frequencies_hz[:6] <= previous[:6] * (1 + 1e-9))
        previous = row.frequencies_hz
    errors = np.abs(axial_cb.harmonic_error())
    assert errors[-1, 1] < errors[0, 1]        # more modes, closer at 2000 Hz
    table = axial_cb.to_pandas()
    assert list(table.index.get_level_values("model")) == ["full FE", "CB 0", "CB 4", "CB 12"]
    assert (table["wall time [s]"] > 0).all()


def test_truncated_orthonormal_basis_loses_the_static_response(bar):
    ortho = verify_coupled(bar, "bar", modes=(0, 4, 12), frequencies_hz=(200.0,), basis="orthonormal")
    errors = np.abs(ortho.static_error())
    assert errors[0] > 0.01 and errors[1] > 0.01   # few modes: the static modes' content is cut off
    assert errors[-1] < 1e-9                       # all kept: the span of Craig-Bampton with 12 modes
    assert "exact only" in ortho.explanation()


def test_bad_arguments_are_named(bar):
    from flexbodies.errors import LinkModelError

    with pytest.raises(LinkModelError, match="basis 'mnf'"):
        verify_coupled(bar, basis="mnf")
    with pytest.raises(LinkModelError, match="mode counts"):
        verify_coupled(bar, modes=(-1, 2))
    with pytest.raises(LinkModelError, match="frequencies"):
        verify_coupled(bar, frequencies_hz=(0.0,))
