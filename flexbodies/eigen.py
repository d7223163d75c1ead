"""Sparse symmetric solves for stiffness/mass pairs.

One factorisation per shift, with a fill-reducing ordering, reused for every
solve and handed to ARPACK as its shift-invert operator (scipy's default
COLAMD ordering gives several times more fill on elasticity matrices).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["factorize", "natural_frequencies", "free_dofs"]


class _Factor:
    """A sparse LU factorisation that solves one or many right-hand sides."""

    def __init__(self, matrix: sp.spmatrix):
        self.shape = matrix.shape
        self._lu = spla.splu(
            sp.csc_matrix(matrix),
            permc_spec="MMD_AT_PLUS_A",
            options={"SymmetricMode": True},
        )

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solve for a vector or for each column of a matrix."""
        rhs = np.asarray(rhs, dtype=float)
        if rhs.ndim == 1:
            return self._lu.solve(rhs)
        # SuperLU on a 2-D right-hand side is slower than a loop over columns.
        return np.column_stack([self._lu.solve(np.ascontiguousarray(c)) for c in rhs.T])

    def as_operator(self) -> spla.LinearOperator:
        return spla.LinearOperator(self.shape, matvec=self._lu.solve, dtype=float)


def factorize(matrix: sp.spmatrix) -> _Factor:
    """Factorise a sparse square matrix with a symmetric fill-reducing ordering.

    Parameters
    ----------
    matrix : scipy.sparse matrix, shape (n, n)
        Typically a stiffness matrix with its fixed DOF removed, or K - sigma M.

    Returns
    -------
    factor
        Object with ``solve(rhs)`` for a vector or a matrix of columns and
        ``as_operator()`` for ARPACK's ``OPinv``.
    """
    return _Factor(matrix)


def free_dofs(ndof: int, fixed) -> np.ndarray:
    """Indices in ``range(ndof)`` not listed in ``fixed``."""
    mask = np.ones(ndof, dtype=bool)
    mask[np.asarray(fixed, dtype=int)] = False
    return np.flatnonzero(mask)


def natural_frequencies(stiffness, mass, count: int, *, fixed=(), shift_hz: float | None = None):
    """Lowest natural frequencies and mode shapes of ``K x = w^2 M x``.

    Parameters
    ----------
    stiffness, mass : scipy.sparse matrix, shape (n, n)
        Stiffness in N/m and consistent mass in kg (or any consistent units).
    count : int
        Number of modes wanted (including rigid-body modes of a free body).
    fixed : sequence of int, optional
        DOF held at zero; their rows and columns are removed.
    shift_hz : float, optional
        Shift of the shift-invert transformation in Hz. The default is a small
        negative shift, which works for free (singular) and supported bodies.

    Returns
    -------
    frequencies_hz : ndarray, shape (count,)
        Natural frequencies in Hz, ascending (rigid-body modes come out as ~0).
    modes : ndarray, shape (n, count)
        Mass-normalised mode shapes, zero at the fixed DOF.
    """
    K = sp.csr_matrix(stiffness)
    M = sp.csr_matrix(mass)
    n = K.shape[0]
    keep = free_dofs(n, fixed)
    Kf = K[keep][:, keep]
    Mf = M[keep][:, keep]
    if shift_hz is None:
        # A shift of -1 % of a typical frequency keeps K - sigma M regular for
        # free bodies without distorting the lower spectrum.
        scale = Kf.diagonal().mean() / Mf.diagonal().mean()
        sigma = -1e-4 * scale
    else:
        sigma = (2 * np.pi * shift_hz) ** 2
    factor = factorize((Kf - sigma * Mf).tocsc())
    count = min(count, Kf.shape[0] - 2)
    lam, vec = spla.eigsh(Kf, k=count, M=Mf, sigma=sigma, which="LM", OPinv=factor.as_operator())
    order = np.argsort(lam)
    lam = np.clip(lam[order], 0.0, None)
    modes = np.zeros((n, count))
    modes[keep] = vec[:, order]
    return np.sqrt(lam) / (2 * np.pi), modes
