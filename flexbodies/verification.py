"""A link's reduced models against its full FE model, mode count by mode count.

The load case: the link clamped at eye A (all six DOF of A's master node
held) and forced at eye B's master node, ``F sin(2 pi f t)`` along a
direction of the link frame (default the link axis, A to B). For the full
coupled FE model (same mesh, bores tied to their master nodes, no
reduction) and for each count of fixed-interface modes:

- the static displacement of eye B along the force, m;
- the harmonic displacement amplitude at each frequency (undamped), m;
- the first natural frequencies of the clamped link, Hz;
- the wall time of the row, s.

Two reduced bases are compared (``basis``):

``"cb"``
    Craig-Bampton as the package reduces a link: eye B's six static modes
    and the lowest ``m`` fixed-interface modes. The static modes make the
    static response at the masters exact at any ``m``.
``"orthonormal"``
    The Craig-Bampton basis with the most modes asked for (``N``),
    orthonormalised as a modal neutral file (MNF) holds it: the eigenvectors
    of the reduced problem, 6 rigid-body and ``6 + N`` elastic modes. A row
    with ``m`` keeps the 6 rigid-body and the lowest ``6 + m`` elastic ones
    (as many coordinates as Craig-Bampton with ``m``) and clamps eye A by a
    constraint on them, as a multibody code does. Every orthonormal mode
    mixes static and fixed-interface content, so the static response is
    exact only with all ``N`` kept.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .eigen import factorize, free_dofs, lowest_modes
from .errors import LinkModelError

__all__ = ["LinkVerification", "VerificationSet", "verify_coupled", "verify_link_model", "BASES",
           "DEFAULT_MODES", "DEFAULT_FREQUENCIES_HZ", "SEED_FORCE"]

#: The reduced bases compared with the full FE model.
BASES = ("cb", "orthonormal")
#: Fixed-interface mode counts compared by default.
DEFAULT_MODES = (0, 2, 6, 12, 20)
#: Excitation frequencies of the harmonic load case by default, Hz.
DEFAULT_FREQUENCIES_HZ = (1000.0, 10000.0, 20000.0)
#: Force amplitude of the load case, N.
SEED_FORCE = 1e5
#: Natural frequencies of the clamped link reported per row.
FREQUENCY_COUNT = 6
#: The label of the reference row.
FULL = "full FE"


@dataclass(frozen=True)
class _Row:
    """One model's answers: static and harmonic tip displacement (m), frequencies (Hz), cost (s)."""

    model: str
    modes: float
    dof: int
    static: float
    harmonic: np.ndarray
    frequencies_hz: np.ndarray
    seconds: float
    highest_hz: float = math.nan


@dataclass(frozen=True)
class LinkVerification:
    """One link's reduced models against its full FE model.

    Attributes
    ----------
    name : str
        The link (or design) verified.
    description : str
        Its FE model, e.g. "quadratic tetrahedra, 6466 nodes, 19398 DOF".
    basis : {"cb", "orthonormal"}
    force : float
        Force amplitude at eye B, N.
    frequencies_hz : ndarray
        Excitation frequencies, Hz.
    full : _Row
        The full FE model's answers.
    reduced : tuple of _Row
        One per fixed-interface mode count, ascending.
    shared_seconds : float
        Cost shared by the reduced rows (factorisation, fixed-interface
        modes, orthonormalisation), s.
    fixed_interface_hz : ndarray
        The fixed-interface modes computed (both eyes held), Hz.
    """

    name: str
    description: str
    basis: str
    force: float
    frequencies_hz: np.ndarray
    full: _Row
    reduced: tuple
    shared_seconds: float
    fixed_interface_hz: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def modes(self) -> tuple:
        """The fixed-interface mode counts compared."""
        return tuple(int(row.modes) for row in self.reduced)

    def static_error(self) -> np.ndarray:
        """Relative error of each reduced row's static tip displacement (fraction, signed)."""
        return np.array([row.static / self.full.static - 1.0 for row in self.reduced])

    def harmonic_error(self) -> np.ndarray:
        """Relative error of the harmonic tip displacement, shape (rows, frequencies) (fraction, signed)."""
        return np.array([row.harmonic / self.full.harmonic - 1.0 for row in self.reduced])

    def to_pandas(self):
        """The table: the full FE row, then one row per mode count.

        Returns
        -------
        pandas.DataFrame
            Indexed by (link, model); tip displacements in m, errors in %,
            frequencies in Hz (the highest mode kept: a fixed-interface mode,
            both eyes held, or a free-free orthonormal mode; and the first
            of the clamped link), wall time in s.
        """
        import pandas as pd

        records = []
        for row in (self.full, *self.reduced):
            record = {"link": self.name, "model": row.model, "modes": row.modes, "DOF": row.dof,
                      "highest mode kept [Hz]": row.highest_hz,
                      "static tip [m]": row.static,
                      "static error [%]": 100 * (row.static / self.full.static - 1.0)}
            for f, value, reference in zip(self.frequencies_hz, row.harmonic, self.full.harmonic, strict=True):
                record[f"tip at {f:g} Hz [m]"] = value
                record[f"error at {f:g} Hz [%]"] = 100 * (value / reference - 1.0)
            for k in range(FREQUENCY_COUNT):
                record[f"f{k + 1} [Hz]"] = row.frequencies_hz[k] if k < len(row.frequencies_hz) else math.nan
            record["wall time [s]"] = row.seconds
            records.append(record)
        return pd.DataFrame(records).set_index(["link", "model"])

    def explanation(self) -> str:
        """What the rows show, in words (the same for every link of one set of options)."""
        n = max(self.modes, default=0)
        if self.basis == "orthonormal":
            return (f"Orthonormal basis: the Craig-Bampton basis with {n} fixed-interface modes "
                    f"orthonormalised (6 rigid-body and {6 + n} elastic modes, as a modal neutral file holds it) "
                    f"and truncated to its lowest 6 + m elastic modes. Each orthonormal mode mixes the static "
                    f"(constraint) modes with the fixed-interface ones, so the static response is exact only "
                    f"when all {6 + n} are kept (m = {n}); dropping the high ones drops static content.")
        return ("Craig-Bampton basis: eye B's static modes make the static response exact at any "
                "mode count; a harmonic response is accurate once the kept modes reach well above the "
                "excitation (the rule of 4: highest kept mode above 4 f_exc, or f_exc below f1 / 4 with "
                "static modes only).")

    def plot(self, axes=None):
        """Frequencies against modes kept and response error against modes kept, side by side.

        Parameters
        ----------
        axes : sequence of two matplotlib Axes, optional
            Where to draw; default a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        if axes is None:
            fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
        left, right = axes
        modes = np.array(self.modes, dtype=float)
        for k in range(FREQUENCY_COUNT):
            values = [row.frequencies_hz[k] if k < len(row.frequencies_hz) else np.nan for row in self.reduced]
            line, = left.plot(modes, values, "o-", label=f"f{k + 1}")
            if k < len(self.full.frequencies_hz):
                left.axhline(self.full.frequencies_hz[k], color=line.get_color(), ls=":", lw=0.8)
        left.set_yscale("log")
        left.set_xlabel("fixed-interface modes kept")
        left.set_ylabel("frequency of the clamped link [Hz] (dotted: full FE)")
        left.set_title(f"{self.name} ({self.basis}): frequencies")
        left.legend(fontsize=7, ncol=2)
        floor = 1e-12
        right.plot(modes, np.maximum(100 * np.abs(self.static_error()), floor), "ks-", label="static")
        for f, error in zip(self.frequencies_hz, self.harmonic_error().T, strict=True):
            right.plot(modes, np.maximum(100 * np.abs(error), floor), "o-", label=f"{f:g} Hz")
        right.set_yscale("log")
        right.set_xlabel("fixed-interface modes kept")
        right.set_ylabel("|error| of the tip displacement [%]")
        right.set_title(f"{self.name} ({self.basis}): response against full FE")
        right.legend(fontsize=7)
        figure = left.figure
        figure.tight_layout()
        return figure


@dataclass(frozen=True)
class VerificationSet:
    """The verifications of several links (one per distinct design).

    Attributes
    ----------
    items : tuple of LinkVerification
    """

    items: tuple

    def to_pandas(self):
        """All links' tables stacked (see :meth:`LinkVerification.to_pandas`)."""
        import pandas as pd

        return pd.concat([item.to_pandas() for item in self.items])

    def plot(self):
        """One row of the two panels per link; returns the matplotlib Figure."""
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(len(self.items), 2, figsize=(11, 4.2 * len(self.items)), squeeze=False)
        for item, row in zip(self.items, axes, strict=True):
            item.plot(row)
        return fig

    def to_json(self) -> dict:
        """JSON-able: per link its rows (NaN as None) and the explanation."""
        table = self.to_pandas().reset_index()
        records = [{k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in r.items()}
                   for r in table.to_dict(orient="records")]
        return {"links": [
            {"link": item.name, "fe_model": item.description, "basis": item.basis, "force_N": item.force,
             "frequencies_hz": [float(f) for f in item.frequencies_hz],
             "shared_seconds": item.shared_seconds,
             "rows": [r for r in records if r["link"] == item.name],
             "explanation": item.explanation()}
            for item in self.items]}


def _checked(modes, frequencies_hz, basis: str, force: float) -> tuple:
    if basis not in BASES:
        raise LinkModelError(f"verification basis {basis!r}: expected one of {', '.join(BASES)}")
    counts = sorted({int(m) for m in modes})
    if not counts or counts[0] < 0 or any(int(m) != m for m in modes):
        raise LinkModelError(f"mode counts {list(modes)}: expected whole numbers >= 0")
    freqs = np.asarray(frequencies_hz, dtype=float)
    if freqs.ndim != 1 or not np.all(np.isfinite(freqs)) or np.any(freqs <= 0):
        raise LinkModelError(f"frequencies {list(frequencies_hz)}: expected positive values in Hz")
    if not (math.isfinite(force) and force != 0):
        raise LinkModelError(f"force {force!r}: expected a non-zero amplitude in N")
    return tuple(counts), freqs


def _lowest(K: np.ndarray, M: np.ndarray, count: int) -> np.ndarray:
    lam = sla.eigh(K, M, eigvals_only=True)
    return np.sqrt(np.clip(lam[:count], 0.0, None)) / (2 * np.pi)


def _reduced_row(model: str, m: int, K: np.ndarray, M: np.ndarray, load: np.ndarray, tip: np.ndarray,
                 frequencies_hz: np.ndarray, start: float, highest_hz: float) -> _Row:
    """Answers of a reduced model ``K, M`` with generalised load ``load`` and tip row ``tip``."""
    static = float(tip @ np.linalg.solve(K, load))
    harmonic = np.array([tip @ np.linalg.solve(K - (2 * np.pi * f) ** 2 * M, load) for f in frequencies_hz])
    freqs = _lowest(K, M, FREQUENCY_COUNT)
    return _Row(model, float(m), K.shape[0], static, harmonic, freqs, time.perf_counter() - start, highest_hz)


def verify_coupled(coupled, name: str = "link", *, modes=DEFAULT_MODES, frequencies_hz=DEFAULT_FREQUENCIES_HZ,
                   basis: str = "cb", force: float = SEED_FORCE, direction=(1.0, 0.0, 0.0)) -> LinkVerification:
    """Verify the reduced models of a coupled link against its full FE model.

    Parameters
    ----------
    coupled : flexbodies.reduction.CoupledModel
        The link with its bores tied to master nodes (eye A first).
    name : str
        Label of the rows.
    modes : sequence of int
        Fixed-interface mode counts.
    frequencies_hz : sequence of float
        Excitation frequencies, Hz.
    basis : {"cb", "orthonormal"}
        See the module docstring.
    force : float
        Force amplitude at eye B, N.
    direction : sequence of 3 float
        Force direction at eye B in the model's frame (default +x, the link
        axis of a link in its link frame).

    Returns
    -------
    LinkVerification
    """
    from .interior import InteriorSolver

    counts, freqs = _checked(modes, frequencies_hz, basis, force)
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    K, M = sp.csr_matrix(coupled.stiffness), sp.csr_matrix(coupled.mass)
    masters = coupled.coupling.master_dofs
    n_q = K.shape[0]
    load = np.zeros(n_q)
    load[masters[1][:3]] = force * d

    # the full FE model clamped at eye A
    start = time.perf_counter()
    keep = free_dofs(n_q, masters[0])
    Kf, Mf = K[keep][:, keep].tocsc(), M[keep][:, keep].tocsc()
    tip_rows = np.searchsorted(keep, masters[1][:3])
    factor = factorize(Kf)
    static = float(d @ factor.solve(load[keep])[tip_rows])
    harmonic = np.array([d @ factorize(Kf - (2 * np.pi * f) ** 2 * Mf).solve(load[keep])[tip_rows] for f in freqs])
    full_hz, _ = lowest_modes(Kf, Mf, FREQUENCY_COUNT, 0.0, factor)
    full = _Row(FULL, math.nan, len(keep), static, harmonic, np.sort(full_hz), time.perf_counter() - start)

    # the shared pieces of every reduced row
    start = time.perf_counter()
    solver = InteriorSolver(K, M, coupled.coupling)
    n_max = counts[-1]
    fixed_hz, fixed = solver.fixed_interface_modes(n_max) if n_max else (np.zeros(0), np.zeros((n_q, 0)))
    if len(fixed_hz) < n_max:
        raise LinkModelError(f"{name}: {n_max} fixed-interface modes asked for, the FE model has {len(fixed_hz)}")
    static_modes = solver.static_modes()
    b_columns = np.arange(6, 12)  # eye B's static modes; eye A's are clamped
    rows = []
    if basis == "cb":
        V = np.hstack([static_modes[:, b_columns], fixed])
        K_r, M_r = V.T @ (K @ V), V.T @ (M @ V)
        K_r, M_r = 0.5 * (K_r + K_r.T), 0.5 * (M_r + M_r.T)
        f_r, tip_r = V.T @ load, d @ V[masters[1][:3]]
        shared = time.perf_counter() - start
        for m in counts:
            t0 = time.perf_counter()
            s = np.arange(6 + m)
            rows.append(_reduced_row(f"CB {m}", m, K_r[np.ix_(s, s)], M_r[np.ix_(s, s)], f_r[s], tip_r[s], freqs, t0,
                                     float(fixed_hz[m - 1]) if m else math.nan))
    else:
        V = np.hstack([static_modes, fixed])
        K_r, M_r = V.T @ (K @ V), V.T @ (M @ V)
        lam, X = sla.eigh(0.5 * (K_r + K_r.T), 0.5 * (M_r + M_r.T))
        lam = np.clip(lam, 0.0, None)           # the six rigid-body modes come out at round-off
        W = V @ X                                # mass-normalised, ascending: 6 rigid, then elastic
        shared = time.perf_counter() - start
        for m in counts:
            t0 = time.perf_counter()
            k = 12 + m                            # 6 rigid + 6 + m elastic
            null = sla.null_space(W[masters[0]][:, :k])   # eye A clamped: its master motion held at zero
            K_c = null.T @ (lam[:k, None] * null)
            M_c = null.T @ null
            rows.append(_reduced_row(f"orthonormal {m}", m, K_c, M_c, null.T @ (W[:, :k].T @ load),
                                     d @ W[masters[1][:3]][:, :k] @ null, freqs, t0,
                                     float(np.sqrt(lam[k - 1]) / (2 * np.pi))))
    return LinkVerification(name, coupled.fe_model.description, basis, float(force), freqs, full, tuple(rows),
                            shared, fixed_hz)


def verify_link_model(model, name: str = "link", **options) -> LinkVerification:
    """Mesh, assemble and couple a :class:`~flexbodies.link.LinkModel`, then :func:`verify_coupled` it.

    Parameters
    ----------
    model : LinkModel
    name : str
    **options
        As for :func:`verify_coupled`; the direction is in the link frame
        (x from eye A to eye B).

    Returns
    -------
    LinkVerification
    """
    from .link import build_fe_model
    from .reduction import couple

    fe, _ = build_fe_model(model)
    return verify_coupled(couple(fe, model.interface), name, **options)
