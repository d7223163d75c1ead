"""Checks against independent computations.

:func:`exudyn_invariants` gives the floating-frame invariants as Exudyn's own
``ObjectFFRFreducedOrderInterface`` computes them, the peer of
:func:`flexbodies.invariants.ffrf_invariants`; :func:`scikit_fem_matrices`
gives K and M by scikit-fem's own assembly of the weak forms, the peer of
:func:`flexbodies.assembly.assemble`.

How good is a static-modes-only link? Harmonic response against the full FE model.

The check the seed study's low-frequency approximation rests on: a link
clamped at eye A and forced harmonically at eye B's master node. Three
models answer the displacement at the force:

- the full coupled FE model (the reference),
- static modes only, their mass kept (the low-frequency approximation),
- static stiffness only, no inertia (a quasi-static spring), for contrast.

Frequencies are given as fractions of ``f1``, the first resonance of the
clamped link that the force excites (the mode with the largest static
contribution to the response in that direction).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .assembly import INTEGRATION_ORDERS
from .craig_bampton import craig_bampton
from .eigen import factorize, free_dofs, natural_frequencies
from .reduced import FFRF_KEYS

__all__ = ["HarmonicCheck", "harmonic_response_check", "exudyn_invariants", "scikit_fem_matrices"]

#: Force directions at eye B, in the link frame.
DIRECTIONS = {"axial": 0, "in-plane": 1, "out-of-plane": 2}


@dataclass(frozen=True)
class HarmonicCheck:
    """Errors of the reduced models against the full FE response.

    Attributes
    ----------
    direction : str
    f1_hz : float
        First resonance excited by the force, Hz.
    ratios : ndarray
        f / f1.
    static_modes_error : ndarray
        Relative error of static modes only (mass kept), at each ratio.
    quasi_static_error : ndarray
        Relative error of the massless static model, at each ratio.
    """

    direction: str
    f1_hz: float
    ratios: np.ndarray
    static_modes_error: np.ndarray
    quasi_static_error: np.ndarray

    def rows(self):
        """One dict per frequency, errors in %."""
        return [
            {
                "direction": self.direction,
                "f1 [Hz]": self.f1_hz,
                "f/f1": r,
                "static modes, mass kept [%]": 100 * e_s,
                "stiffness only, no mass [%]": 100 * e_q,
            }
            for r, e_s, e_q in zip(self.ratios, self.static_modes_error, self.quasi_static_error, strict=True)
        ]


def _dominant_resonance(K, M, keep, dof, count=12) -> float:
    """Frequency of the mode with the largest static contribution at ``dof``, Hz."""
    freqs, modes = natural_frequencies(K[keep][:, keep], M[keep][:, keep], count)
    position = int(np.searchsorted(keep, dof))
    contribution = modes[position] ** 2 / np.maximum((2 * np.pi * freqs) ** 2, 1e-30)
    return float(freqs[np.argmax(contribution)])


def harmonic_response_check(coupled, direction: str = "axial", ratios=(0.05, 0.1, 0.25, 0.5)) -> HarmonicCheck:
    """Harmonic response at eye B of a link clamped at eye A.

    Parameters
    ----------
    coupled : flexbodies.reduction.CoupledModel
        The link in its link frame (eye B on +x).
    direction : {"axial", "in-plane", "out-of-plane"}
        Force direction at eye B.
    ratios : sequence of float
        Excitation frequencies as fractions of the first excited resonance.

    Returns
    -------
    HarmonicCheck
    """
    if direction not in DIRECTIONS:
        raise ValueError(f"unknown direction {direction!r}; expected one of {', '.join(DIRECTIONS)}")
    K, M = coupled.stiffness, coupled.mass
    masters = coupled.coupling.master_dofs
    keep = free_dofs(K.shape[0], masters[0])
    dof = masters[1][DIRECTIONS[direction]]
    f1 = _dominant_resonance(K, M, keep, dof)

    cb = craig_bampton(K, M, coupled.coupling.boundary, count=0)
    K_r, M_r = cb.project(K), cb.project(M)
    keep_r = np.arange(6, 12)  # eye B's static modes; eye A's are clamped
    K_r, M_r = K_r[np.ix_(keep_r, keep_r)], M_r[np.ix_(keep_r, keep_r)]
    load_r = np.zeros(6)
    load_r[DIRECTIONS[direction]] = 1.0
    quasi_static = np.linalg.solve(K_r, load_r)[DIRECTIONS[direction]]

    Kf, Mf = K[keep][:, keep], M[keep][:, keep]
    load = np.zeros(len(keep))
    position = int(np.searchsorted(keep, dof))
    load[position] = 1.0
    ratios = np.asarray(ratios, dtype=float)
    err_static, err_quasi = [], []
    for ratio in ratios:
        omega2 = (2 * np.pi * ratio * f1) ** 2
        full = factorize(sp.csc_matrix(Kf - omega2 * Mf)).solve(load)[position]
        reduced = np.linalg.solve(K_r - omega2 * M_r, load_r)[DIRECTIONS[direction]]
        err_static.append(abs(reduced - full) / abs(full))
        err_quasi.append(abs(quasi_static - full) / abs(full))
    return HarmonicCheck(direction, f1, ratios, np.array(err_static), np.array(err_quasi))


def exudyn_invariants(nodes, mass, stiffness, mode_basis, triangles) -> dict:
    """Floating-frame invariants computed by Exudyn's ``ObjectFFRFreducedOrderInterface``.

    Parameters
    ----------
    nodes : ndarray, shape (n, 3)
        Node positions, m.
    mass, stiffness : scipy.sparse matrix, shape (3n, 3n)
        Node-major mass (kg) and stiffness (N/m).
    mode_basis : ndarray, shape (3n, m)
        Elastic modes.
    triangles : ndarray of int, shape (k, 3)
        Surface triangles (Exudyn wants a surface).

    Returns
    -------
    dict
        The arrays of :data:`~flexbodies.reduced.FFRF_KEYS`.
    """
    from exudyn.FEM import FEMinterface, ObjectFFRFreducedOrderInterface

    fem = FEMinterface()
    fem.nodes = {"Position": np.asarray(nodes, dtype=float)}
    # Exudyn needs scipy's csr_matrix, not csr_array.
    fem.massMatrix = sp.csr_matrix(mass)
    fem.stiffnessMatrix = sp.csr_matrix(stiffness)
    fem.surface = [{"Name": "surface", "Trigs": np.asarray(triangles, dtype=int)}]
    fem.modeBasis = {"matrix": np.asarray(mode_basis, dtype=float), "type": "HCBmodes"}
    data = ObjectFFRFreducedOrderInterface(fem).GetDictionary()
    return {key: np.asarray(data[key], dtype=float) for key in FFRF_KEYS}


def scikit_fem_matrices(mesh, material) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Stiffness (N/m) and consistent mass (kg) by scikit-fem's assembly of the weak forms, node-major.

    The elasticity form ``2 mu eps(u):eps(v) + lambda div u div v`` on the
    vector element, the mass ``rho u v`` on the scalar element for each
    component (``M = M_scalar (x) I3``), at the integration orders of
    :data:`~flexbodies.assembly.INTEGRATION_ORDERS`; scikit-fem numbers the
    vector element's DOF node-major.

    Parameters
    ----------
    mesh : skfem.Mesh
        A mesh of a type in :data:`~flexbodies.assembly.INTEGRATION_ORDERS`, m.
    material : Material
    """
    import skfem

    lam, mu, rho = material.lame_lambda, material.shear_modulus, material.density
    k_order, m_order = INTEGRATION_ORDERS[type(mesh)]

    @skfem.BilinearForm
    def elasticity(u, v, _):
        gu, gv = u.grad, v.grad
        eps_u, eps_v = 0.5 * (gu + np.swapaxes(gu, 0, 1)), 0.5 * (gv + np.swapaxes(gv, 0, 1))
        return 2 * mu * np.einsum("ij...,ij...->...", eps_u, eps_v) + lam * np.trace(gu) * np.trace(gv)

    @skfem.BilinearForm
    def inertia(u, v, _):
        return rho * u * v

    stiffness = skfem.asm(elasticity, skfem.Basis(mesh, skfem.ElementVector(mesh.elem()), intorder=k_order))
    scalar_mass = skfem.asm(inertia, skfem.Basis(mesh, mesh.elem(), intorder=m_order))
    return sp.csr_matrix(stiffness), sp.kron(scalar_mass, sp.identity(3), format="csr")
