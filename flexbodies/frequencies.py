"""Natural frequencies of a coupled link under named boundary conditions.

All work on the coupled coordinates of :mod:`flexbodies.interfaces`
(full FE model, bores tied to their master nodes), so they are the
reference the reduced body is checked against.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .eigen import natural_frequencies

__all__ = ["free_free_frequencies", "mounted_frequencies", "clamped_frequencies", "mounted_constraint_basis"]


def free_free_frequencies(stiffness, mass, count: int = 6) -> np.ndarray:
    """First elastic frequencies of the free link, Hz (the six rigid-body modes skipped)."""
    freqs, _ = natural_frequencies(stiffness, mass, count + 6)
    return freqs[6:]


def clamped_frequencies(stiffness, mass, coupling, interfaces=(0,), count: int = 6) -> np.ndarray:
    """Frequencies with all six DOF of the given interfaces' masters held, Hz.

    ``interfaces=(0,)`` is a cantilever from the first eye; ``(0, 1)`` both
    eyes clamped (the fixed-interface spectrum).
    """
    fixed = coupling.master_dofs[list(interfaces)].ravel()
    freqs, _ = natural_frequencies(stiffness, mass, count, fixed=fixed)
    return freqs


def mounted_constraint_basis(coupling) -> np.ndarray:
    """Master motions left when both masters are pinned and spin is held, shape (n_master_dof, n_master_dof - 7).

    Master translations of every interface are held; the rotation of the first
    master about the line through the first two master nodes is held. Rows
    follow ``coupling.boundary``; the columns are orthonormal.
    """
    masters = coupling.master_dofs
    axis = coupling.centres[1] - coupling.centres[0]
    axis = axis / np.linalg.norm(axis)
    constraints = np.zeros((3 * len(masters) + 1, masters.size))
    for i in range(len(masters)):
        constraints[3 * i: 3 * i + 3, 6 * i: 6 * i + 3] = np.eye(3)
    constraints[-1, 3:6] = axis
    return sla.null_space(constraints)


def _mounted_transform(coupling) -> sp.csr_matrix:
    """Basis of the coordinates left when both masters are pinned and spin is held (:func:`mounted_constraint_basis`)."""
    n_q = coupling.n_q
    masters = coupling.master_dofs
    n_m = masters.size
    null = mounted_constraint_basis(coupling)  # (n_m, n_m - 7)
    others = np.setdiff1d(np.arange(n_q), masters.ravel())
    n_free = len(others) + null.shape[1]
    identity = sp.csr_matrix((np.ones(len(others)), (others, np.arange(len(others)))), shape=(n_q, n_free))
    rows = np.repeat(masters.ravel(), null.shape[1])
    cols = np.tile(len(others) + np.arange(null.shape[1]), n_m)
    master_part = sp.csr_matrix((null.ravel(), (rows, cols)), shape=(n_q, n_free))
    return (identity + master_part).tocsr()


def mounted_frequencies(stiffness, mass, coupling, count: int = 3) -> np.ndarray:
    """Frequencies as mounted by ball hinges, Hz.

    Both bore centres pinned (translations held, rotations free) and the
    spin about the link axis restrained, which a ball-jointed link needs to
    have a fundamental frequency at all. This is the frequency the
    low-frequency rule compares the excitation with.
    """
    P = _mounted_transform(coupling)
    K = (P.T @ stiffness @ P).tocsr()
    M = (P.T @ mass @ P).tocsr()
    freqs, _ = natural_frequencies(K, M, count)
    return freqs
