"""Stress stiffening of flexible links: the geometric stiffness of an axial
preload against the pinned-pinned beam, and in the mount."""
import numpy as np
import pytest
import skfem

from flexbodies.geometric_stiffness import mesh_stiffening
from flexbodies.materials import STEEL
from flexbodies.meshing import Bore, LinkMesh

#: A slender steel bar, 0.6 m long, 20 x 20 mm: Euler load 76.8 kN.
BAR_LENGTH, BAR_SIDE = 0.6, 0.02
EULER_LOAD = np.pi ** 2 * STEEL.youngs_modulus * BAR_SIDE ** 4 / 12 / BAR_LENGTH ** 2


def _bar() -> LinkMesh:
    """Quadratic tetrahedra, 40 x 2 x 2 boxes; each end face is a "bore" tied to a master at its centre."""
    mesh = skfem.MeshTet2.from_mesh(skfem.MeshTet.init_tensor(
        np.linspace(0.0, BAR_LENGTH, 41), *[np.linspace(-BAR_SIDE / 2, BAR_SIDE / 2, 3)] * 2))
    points = mesh.doflocs.T

    def end(name, x):
        nodes = np.flatnonzero(np.isclose(points[:, 0], x))
        return Bore(name, np.array([x, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), BAR_SIDE / 2, nodes,
                    np.full(len(nodes), BAR_SIDE ** 2 / len(nodes)))

    return LinkMesh(mesh, (end("A", 0.0), end("B", BAR_LENGTH)), "bar")


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
