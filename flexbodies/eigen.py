"""Sparse symmetric solves for stiffness/mass pairs.

One factorisation per shift, with a fill-reducing ordering, reused for every
solve and handed to ARPACK as its shift-invert operator (scipy's default
COLAMD ordering gives several times more fill on elasticity matrices).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["factorize", "natural_frequencies", "free_dofs", "lowest_modes", "start_vector"]


#: Relative residual below which a solve is not refined.
_ROUND_OFF = 1e-13


class _Factor:
    """A sparse LU factorisation that solves one or many right-hand sides."""

    def __init__(self, matrix: sp.spmatrix):
        self.shape = matrix.shape
        self._matrix = sp.csc_matrix(matrix)
        self._lu = spla.splu(
            self._matrix,
            permc_spec="MMD_AT_PLUS_A",
            options={"SymmetricMode": True},
        )

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solve for a vector or for each column of a matrix, with one refinement step.

        One step of iterative refinement recovers the digits that the
        ill-conditioning of coupled (RBE3) matrices costs; it is skipped for
        the columns whose residual is already at round-off. The columns of a
        matrix are solved together (SuperLU's block solve costs about a third
        of a loop over them).
        """
        rhs = np.asarray(rhs, dtype=float)
        x = self._lu.solve(rhs)
        residual = rhs - self._matrix @ x
        if rhs.ndim == 1:
            return x if np.linalg.norm(residual) <= _ROUND_OFF * np.linalg.norm(rhs) else x + self._lu.solve(residual)
        refine = np.linalg.norm(residual, axis=0) > _ROUND_OFF * np.linalg.norm(rhs, axis=0)
        if refine.any():
            x[:, refine] += self._lu.solve(np.ascontiguousarray(residual[:, refine]))
        return x

    def solve_plain(self, rhs: np.ndarray) -> np.ndarray:
        """Solve for one vector, without refinement (what an eigen-solver's operator needs)."""
        return self._lu.solve(np.ascontiguousarray(rhs, dtype=float))

    def as_operator(self) -> spla.LinearOperator:
        return spla.LinearOperator(self.shape, matvec=self.solve_plain, dtype=float)


def factorize(matrix: sp.spmatrix) -> _Factor:
    """Factorise a sparse square matrix with a symmetric fill-reducing ordering.

    Parameters
    ----------
    matrix : scipy.sparse matrix, shape (n, n)
        Typically a stiffness matrix with its fixed DOF removed, or K - sigma M.

    Returns
    -------
    factor
        Object with ``solve(rhs)`` for a vector or a matrix of columns (with
        one step of iterative refinement) and ``as_operator()`` for ARPACK's
        ``OPinv`` (plain solves).
    """
    return _Factor(matrix)


def free_dofs(ndof: int, fixed) -> np.ndarray:
    """Indices in ``range(ndof)`` not listed in ``fixed``."""
    mask = np.ones(ndof, dtype=bool)
    mask[np.asarray(fixed, dtype=int)] = False
    return np.flatnonzero(mask)


def start_vector(n: int) -> np.ndarray:
    """Lanczos start vector: fixed, so that the modes, and every file made from them, are reproducible."""
    return np.random.default_rng(0).standard_normal(n)


def lowest_modes(stiffness, mass, count: int, sigma: float, factor=None, *, tol: float = 0.0, ncv: int | None = None):
    """Eigenpairs of ``K x = lambda M x`` nearest to ``sigma``, by shift-invert Lanczos.

    Parameters
    ----------
    stiffness, mass : scipy.sparse matrix, shape (n, n)
    count : int
        Number of eigenpairs (at most n - 2).
    sigma : float
        Shift, (rad/s)^2.
    factor : optional
        A factorisation of ``K - sigma M`` from :func:`factorize`, to reuse.
    tol : float
        Lanczos's relative accuracy of the eigenvalues (0: machine precision).
    ncv : int, optional
        Lanczos vectors between restarts (ARPACK's default: ``max(2 count + 1, 20)``).

    Returns
    -------
    frequencies_hz : ndarray, shape (count,)
        ``sqrt(lambda) / 2 pi``, ascending; round-off negatives count as 0.
    modes : ndarray, shape (n, count)
        Mass-normalised.
    """
    n = stiffness.shape[0]
    if factor is None:
        factor = factorize((stiffness - sigma * mass).tocsc())
    lam, vec = spla.eigsh(
        stiffness, k=min(count, n - 2), M=mass, sigma=sigma, which="LM",
        OPinv=factor.as_operator(), v0=start_vector(n), tol=tol,
        ncv=None if ncv is None else min(max(ncv, count + 1), n - 1),
    )
    order = np.argsort(lam)
    return np.sqrt(np.clip(lam[order], 0.0, None)) / (2 * np.pi), vec[:, order]


#: Default shift for free or supported bodies, Hz: negative and small, so that
#: ``K - sigma M`` is regular even with rigid-body modes and the lowest modes converge first.
DEFAULT_SHIFT_HZ = -10.0


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
        Shift of the shift-invert transformation in Hz; a negative value means
        a negative shift ``-(2 pi |shift_hz|)^2``. Default
        :data:`DEFAULT_SHIFT_HZ`, which works for free (singular) and
        supported bodies.

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
    shift_hz = DEFAULT_SHIFT_HZ if shift_hz is None else shift_hz
    sigma = np.sign(shift_hz) * (2 * np.pi * shift_hz) ** 2
    freqs, vec = lowest_modes(Kf, Mf, count, sigma)
    modes = np.zeros((n, vec.shape[1]))
    modes[keep] = vec
    return freqs, modes
