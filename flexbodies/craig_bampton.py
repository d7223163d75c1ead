"""Craig-Bampton reduction of a coupled link model.

Works on the coupled coordinates ``q = [interior DOF, master DOF]`` of
:mod:`flexbodies.interfaces`. The basis holds one static (constraint) mode
per master DOF and a chosen set of fixed-interface normal modes (all master
DOF held). For a floating-frame body the basis is then orthonormalised: the
reduced eigenproblem gives six rigid-body modes, which the floating frame
replaces, and the remaining *elastic* modes, which form the body's mode basis.
Static modes make the reduced statics exact for loads at the masters.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .errors import LinkModelError

if TYPE_CHECKING:  # SciPy is imported where a basis is made: a run with its bodies cached needs only the errors
    import scipy.sparse as sp

__all__ = ["CraigBamptonBasis", "craig_bampton", "elastic_modes", "elastic_coefficients", "fixed_interface_set", "kept_count",
           "ModeBudgetExceeded", "MODE_BUDGET", "estimated_mode_count"]

#: Frequencies below this fraction of the first elastic one count as rigid-body modes.
_RIGID_FRACTION = 1e-3


@dataclass(frozen=True)
class CraigBamptonBasis:
    """A Craig-Bampton basis in coupled coordinates.

    Attributes
    ----------
    vectors : ndarray, shape (n_q, n_boundary + n_fixed)
        Static modes first (unit value at one master DOF, zero at the
        others), then mass-normalised fixed-interface modes.
    boundary : ndarray of int
        Master DOF positions in ``q``.
    fixed_interface_hz : ndarray
        Frequencies of the kept fixed-interface modes, Hz.
    """

    vectors: np.ndarray
    boundary: np.ndarray
    fixed_interface_hz: np.ndarray

    @property
    def n_static(self) -> int:
        return len(self.boundary)

    def project(self, matrix: sp.spmatrix) -> np.ndarray:
        """Reduced matrix ``V^T A V`` (dense, symmetrised)."""
        V = self.vectors
        reduced = V.T @ (matrix @ V)
        return 0.5 * (reduced + reduced.T)


#: Margin on the mode count a cut-off is estimated to need (:func:`fixed_interface_set`).
_BATCH_MARGIN = 1.25
#: Most fixed-interface modes a cut-off may ask of one body. The reference
#: mount's links hold 5 to 31 modes below 10 kHz, its casing 41 below 1 kHz;
#: a cut-off far beyond (an rpm typed as Hz) would ask for thousands, whose
#: Lanczos vectors alone fill gigabytes.
MODE_BUDGET = 200
#: Bounds of the exponent p of the mode count N(f) ~ f^p fitted to a batch:
#: 1 for a slender body's bending and axial modes, 3 for a solid's (Weyl).
_EXPONENT_BOUNDS = (1.0, 3.0)


class ModeBudgetExceeded(LinkModelError):
    """A cut-off that asks for more than :data:`MODE_BUDGET` fixed-interface modes.

    Attributes
    ----------
    cutoff_hz : float
        The cut-off asked for, Hz.
    estimate : int
        The number of modes below it, extrapolated (:func:`estimated_mode_count`).
    served_hz : float
        The cut-off up to which :data:`MODE_BUDGET` modes are estimated to reach, Hz.
    """

    def __init__(self, cutoff_hz: float, estimate: int, served_hz: float, frequencies_hz):
        self.cutoff_hz, self.estimate, self.served_hz = cutoff_hz, estimate, served_hz
        super().__init__(
            f"fixed-interface modes up to {cutoff_hz:.6g} Hz: about {estimate} of them (extrapolated from the "
            f"{len(frequencies_hz)} lowest, {frequencies_hz[0]:.4g} to {frequencies_hz[-1]:.4g} Hz), more than the "
            f"{MODE_BUDGET} a reduction keeps (they reach about {served_hz:.5g} Hz)")


def estimated_mode_count(frequencies_hz, cutoff_hz: float) -> tuple[int, float]:
    """The number of modes below a cut-off, extrapolated from the lowest ones.

    The count is taken to grow as ``N(f) = k (f / f_k)^p`` with ``p`` fitted
    to the upper half of the ``k`` frequencies known (bounded to 1 to 3).
    From the 8 lowest, on the coarse reference thrust rod: 41 modes below
    10 kHz (31 counted) and 81 below 20 kHz (56); on the reference casing
    47 below 1 kHz (41).

    Parameters
    ----------
    frequencies_hz : array_like
        The lowest frequencies, ascending, Hz (at least two, positive).
    cutoff_hz : float
        Hz.

    Returns
    -------
    estimate : int
        Modes below ``cutoff_hz``.
    served_hz : float
        Frequency below which :data:`MODE_BUDGET` modes are estimated to lie, Hz.
    """
    f = np.asarray(frequencies_hz, dtype=float)
    k, half = len(f), max(len(f) // 2, 1)
    ratio = f[-1] / f[half - 1]
    p = _EXPONENT_BOUNDS[1] if ratio <= 1 else float(np.clip(math.log(k / half) / math.log(ratio),
                                                                *_EXPONENT_BOUNDS))
    return math.ceil(k * (cutoff_hz / f[-1]) ** p), float(f[-1] * (MODE_BUDGET / k) ** (1 / p))


def fixed_interface_set(modes_of, n: int, count: int | None = None, cutoff_hz: float | None = None):
    """Lowest fixed-interface modes, by count or up to (and one past) a cut-off.

    With a cut-off the modes are computed in growing batches until the
    highest one reaches ``cutoff_hz``, so the kept set spans at least up to it;
    each batch after the first is sized from the modal density of the last
    (:func:`estimated_mode_count`), at least twice the last.

    Parameters
    ----------
    modes_of : callable
        ``modes_of(k)`` gives the lowest ``k`` frequencies (Hz) and mode shapes.
    n : int
        Size of the fixed-interface problem.
    count, cutoff_hz
        As in :func:`craig_bampton`.

    Raises
    ------
    ModeBudgetExceeded
        A cut-off estimated to lie above more than :data:`MODE_BUDGET`
        modes, refused before the batch that would compute them.
    """
    if count == 0:
        return np.zeros(0), None
    k = count if count is not None else 8
    while True:
        k_eff = min(k, n - 2)
        freqs, vec = modes_of(k_eff)
        if count is not None:
            return freqs, vec
        if np.any(freqs >= cutoff_hz) or k_eff == n - 2:
            return freqs, vec
        assert cutoff_hz is not None          # a cut-off, as there is no count
        estimate, served_hz = estimated_mode_count(freqs, cutoff_hz)
        if estimate > MODE_BUDGET or k_eff > MODE_BUDGET:
            raise ModeBudgetExceeded(cutoff_hz, max(estimate, k_eff + 1), served_hz, freqs)
        # each batch is a Lanczos run of its own: at least twice the last, one past the budget at most
        k = min(max(2 * k, math.ceil(_BATCH_MARGIN * estimate)), MODE_BUDGET + 1)


def kept_count(frequencies_hz, count: int | None = None, cutoff_hz: float | None = None) -> int:
    """How many of the lowest fixed-interface modes a count or a cut-off keeps.

    A cut-off keeps the modes up to it and the first one above it (all of
    them when none reaches it).
    """
    if count is not None:
        return min(count, len(frequencies_hz))
    reached = np.flatnonzero(np.asarray(frequencies_hz) >= cutoff_hz)
    return int(reached[0]) + 1 if reached.size else len(frequencies_hz)


def craig_bampton(stiffness, mass, boundary, *, count: int | None = None, cutoff_hz: float | None = None):
    """Craig-Bampton basis: static modes plus fixed-interface normal modes.

    Parameters
    ----------
    stiffness, mass : scipy.sparse matrix, shape (n_q, n_q)
        Coupled stiffness (N/m) and mass (kg).
    boundary : array of int
        Boundary (master) DOF; holding them must restrain every rigid-body motion.
    count : int, optional
        Number of fixed-interface modes to keep (0 = static modes only).
    cutoff_hz : float, optional
        Keep fixed-interface modes up to this frequency and the first one above
        it. Exactly one of ``count`` and ``cutoff_hz`` is given.

    Returns
    -------
    CraigBamptonBasis
    """
    import scipy.sparse as sp

    from .eigen import factorize, lowest_modes

    if (count is None) == (cutoff_hz is None):
        raise ValueError("give exactly one of count and cutoff_hz")
    K = sp.csr_matrix(stiffness)
    M = sp.csr_matrix(mass)
    n = K.shape[0]
    boundary = np.asarray(boundary, dtype=int)
    interior = np.setdiff1d(np.arange(n), boundary)
    K_ii = K[interior][:, interior].tocsc()
    K_ib = K[interior][:, boundary].toarray()
    factor = factorize(K_ii)
    vectors = np.zeros((n, len(boundary)))
    vectors[interior] = -factor.solve(K_ib)
    vectors[boundary, np.arange(len(boundary))] = 1.0
    M_ii = M[interior][:, interior].tocsc()
    freqs, phi = fixed_interface_set(lambda k: lowest_modes(K_ii, M_ii, k, 0.0, factor), len(interior),
                                     count=count, cutoff_hz=cutoff_hz)
    keep = kept_count(freqs, count, cutoff_hz)
    fixed = np.zeros((n, keep))
    if keep:
        fixed[interior] = phi[:, :keep]
    return CraigBamptonBasis(np.hstack([vectors, fixed]), boundary, freqs[:keep])


def elastic_coefficients(cb: CraigBamptonBasis, stiffness, mass):
    """The elastic modes of a free-floating Craig-Bampton basis as combinations of its vectors.

    Parameters
    ----------
    cb : CraigBamptonBasis
    stiffness, mass : scipy.sparse matrix
        The coupled matrices the basis was made from.

    Returns
    -------
    coefficients : ndarray, shape (n_basis, n_elastic)
        The elastic modes are ``cb.vectors @ coefficients``, mass-normalised.
    frequencies_hz : ndarray, shape (n_elastic,)
        Free-free frequencies of the reduced body, Hz.
    """
    import scipy.linalg as sla

    K_r = cb.project(stiffness)
    M_r = cb.project(mass)
    lam, X = sla.eigh(K_r, M_r)
    freqs = np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)
    n_rigid = int(np.sum(freqs < _RIGID_FRACTION * freqs[-1]))
    if n_rigid != 6:
        raise LinkModelError(
            f"expected 6 rigid-body modes in the free link, found {n_rigid}: "
            "the interfaces do not see the body as one free solid"
        )
    return X[:, 6:], freqs[6:]


def elastic_modes(cb: CraigBamptonBasis, stiffness, mass):
    """Orthonormalise a free-floating Craig-Bampton basis and drop its rigid-body modes.

    Parameters
    ----------
    cb : CraigBamptonBasis
    stiffness, mass : scipy.sparse matrix
        The coupled matrices the basis was made from.

    Returns
    -------
    modes : ndarray, shape (n_q, n_elastic)
        Mass-normalised elastic modes in coupled coordinates.
    frequencies_hz : ndarray, shape (n_elastic,)
        Free-free frequencies of the reduced body, Hz.
    """
    coefficients, freqs = elastic_coefficients(cb, stiffness, mass)
    return cb.vectors @ coefficients, freqs
