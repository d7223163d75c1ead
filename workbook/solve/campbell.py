"""The Campbell diagram: the modes of the mounted engine against rotor speed.

The scene is prepared once (reductions, preload, linearisation about the
preloaded equilibrium). Its rotors' gyroscopic matrix G is linear in their
spin, so at a speed that is the fraction s of the case's speeds the modes
are those of

    M x'' + (D_0 + s G) x' + K x = 0,      D_0 = D - G,

(:func:`workbook.solve.modes.eigenpairs`, undamped gyroscopic form) with no
other Exudyn call. Every rotor's speed scales with s: the case's speeds are
one point of the engine's operating line, taken as proportional. Without
gyroscopic rotors the lines are flat at the case's modes, and the speeds
are those of its rotating excitations (imbalances).

Modes are followed from speed to speed by their shapes (the mass-weighted
modal assurance criterion, one-to-one), so a branch is one mode however
the lines cross. A mode *whirls* forward when the engine's tilt turns with
the spin of the reference rotor, backward when against it (the sense of
``-Im(conj(r) x r)`` along the spin axis, r the engine's complex rotation).

A *critical speed* is where a branch meets an engine-order line
(``f = order x rotor speed``); it is found between two grid speeds and then
refined by root-finding on the eigenproblem itself, so it does not depend on
the grid.
"""
from __future__ import annotations

import dataclasses
import logging
import time
from dataclasses import dataclass, field

import numpy as np

from workbook.errors import CaseError, SimulationError
from workbook.model.case import ENGINE, Case, HarmonicForce, Imbalance, RotatingForce
from workbook.solve.modes import FREE_FREQUENCY_HZ, Linearization, Mode, eigenpairs, modes_from

__all__ = ["SpinningRotor", "Crossing", "CampbellDiagram", "spinning_rotors", "campbell", "modal_basis", "WHIRL",
           "BASIS_FACTOR", "TRUNCATION_WARNING"]

log = logging.getLogger(__name__)

#: Whirl labels by sign: +1 forward, -1 backward, 0 none (no engine tilt, or a planar one).
WHIRL = {1: "forward", -1: "backward", 0: "-"}
#: Least |whirl measure| (0 to 1: 1 a circular orbit) for a mode to count as whirling.
_WHIRL_THRESHOLD = 0.2
#: Candidate modes followed up to this factor above the diagram's top frequency.
_CANDIDATE_MARGIN = 1.5
#: With rotors, the modes at each speed are solved on the non-rotating modes up to this factor times
#: the diagram's top frequency (as the low-frequency rule keeps a link's modes to 4 f_exc).
BASIS_FACTOR = 4.0
#: Relative frequency error of the modal basis (at the top speed, against the full model) above which
#: the diagram warns.
TRUNCATION_WARNING = 1e-3


@dataclass(frozen=True)
class SpinningRotor:
    """A rotor whose speed sets an engine-order line.

    Attributes
    ----------
    name : str
    frequency_hz : float
        Its speed in the case, Hz.
    axis : ndarray, shape (3,)
        Unit spin axis.
    gyroscopic : bool
        Its gyroscopic moment acts on the engine (a :class:`~workbook.model.case.Rotor`), or it only
        sets a speed (a rotating excitation of a case without rotors).
    """

    name: str
    frequency_hz: float
    axis: np.ndarray
    gyroscopic: bool


@dataclass(frozen=True)
class Crossing:
    """A critical speed: a mode on an engine-order line.

    Attributes
    ----------
    rotor : str
    order : float
    speed_rpm : float
        Speed of the diagram's reference rotor, rpm.
    rotor_rpm : float
        Speed of *rotor* there, rpm.
    frequency_hz : float
    branch : int
        Number of the mode's branch in the diagram.
    whirl : str
        ``forward``, ``backward`` or ``-``.
    damping_ratio : float
    description : str
        The mode's motion.
    """

    rotor: str
    order: float
    speed_rpm: float
    rotor_rpm: float
    frequency_hz: float
    branch: int
    whirl: str
    damping_ratio: float
    description: str


@dataclass
class CampbellDiagram:
    """The modes of a case against rotor speed, with the engine-order lines and their crossings.

    Attributes
    ----------
    case_name : str
    reference : SpinningRotor
        The rotor whose speed is the diagram's abscissa.
    rotors : tuple of SpinningRotor
    orders : tuple of float
    speeds_rpm : ndarray, shape (s,)
        Reference rotor speeds, rpm.
    frequencies_hz, damping_ratios : ndarray, shape (b, s)
        Each branch's frequency (Hz) and damping ratio at each speed.
    whirl : ndarray of int, shape (b, s)
        +1 forward, -1 backward, 0 none (:data:`WHIRL`).
    descriptions : list of str
        Each branch's motion at the lowest speed.
    crossings : list of Crossing
    operating_rpm : (float, float) or None
        The reference rotor's operating range, rpm.
    coordinates : int
        Independent coordinates of the linearised scene.
    truncation : dict
        ``basis modes`` (the size of the modal basis the speeds were solved on), ``basis Hz`` (its
        top, None: the full model) and ``largest frequency error`` (of a branch at the top speed
        against the full model, relative).
    timings : dict of str to float
        Wall time of the preparation (reductions, preload, linearisation) and of the modes over
        the speeds with the crossings, s.
    """

    case_name: str
    reference: SpinningRotor
    rotors: tuple
    orders: tuple
    speeds_rpm: np.ndarray
    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    whirl: np.ndarray
    descriptions: list
    crossings: list = field(default_factory=list)
    operating_rpm: tuple | None = None
    coordinates: int = 0
    truncation: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)

    def branch_whirl(self, branch: int) -> str:
        """The whirl of *branch* at most of the speeds above zero."""
        values = self.whirl[branch, self.speeds_rpm > 0] if (self.speeds_rpm > 0).any() else self.whirl[branch]
        return WHIRL[int(np.sign(np.sum(values))) if np.abs(np.mean(values)) >= 0.5 else 0]

    def to_pandas(self):
        """The branches as a long table: branch, speed rpm, frequency Hz, zeta %, whirl, motion."""
        import pandas as pd

        rows = [{"branch": b, "speed rpm": speed, "frequency Hz": self.frequencies_hz[b, i],
                 "zeta %": 100 * self.damping_ratios[b, i], "whirl": WHIRL[int(self.whirl[b, i])],
                 "motion": self.descriptions[b]}
                for b in range(len(self.descriptions)) for i, speed in enumerate(self.speeds_rpm)]
        return pd.DataFrame(rows)

    def crossings_frame(self):
        """The critical speeds, slowest first."""
        import pandas as pd

        columns = ["rotor", "order", "speed rpm", "rotor rpm", "frequency Hz", "branch", "whirl", "zeta %", "motion"]
        rows = [[c.rotor, c.order, c.speed_rpm, c.rotor_rpm, c.frequency_hz, c.branch, c.whirl, 100 * c.damping_ratio,
                 c.description] for c in self.crossings]
        return pd.DataFrame(rows, columns=columns)

    def to_dict(self) -> dict:
        """Plain data for ``--json``."""
        return {"case": self.case_name, "reference rotor": self.reference.name,
                "rotors": [{"name": r.name, "case speed Hz": r.frequency_hz, "gyroscopic": r.gyroscopic}
                           for r in self.rotors],
                "orders": list(self.orders), "speeds rpm": self.speeds_rpm.tolist(),
                "branches": [{"branch": b, "motion": self.descriptions[b], "whirl": self.branch_whirl(b),
                              "frequency Hz": self.frequencies_hz[b].tolist(),
                              "zeta": self.damping_ratios[b].tolist()} for b in range(len(self.descriptions))],
                "critical speeds": [dataclasses.asdict(c) for c in self.crossings],
                "operating rpm": list(self.operating_rpm) if self.operating_rpm else None,
                "truncation": dict(self.truncation), "wall time s": dict(self.timings)}

    def plot(self, ax=None):
        """The diagram: branches (forward whirl solid blue, backward dashed red, others grey), the
        engine-order lines, the critical speeds marked and the operating range shaded; returns the figure."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(9, 6), constrained_layout=True)
        styles = {"forward": ("C0", "-"), "backward": ("C3", "--"), "-": ("0.45", "-")}
        shown = set()
        for b in range(len(self.descriptions)):
            whirl = self.branch_whirl(b)
            colour, dash = styles[whirl]
            label = None if whirl in shown else (f"{whirl} whirl" if whirl != "-" else "no whirl")
            shown.add(whirl)
            ax.plot(self.speeds_rpm, self.frequencies_hz[b], color=colour, ls=dash, lw=1.4, label=label)
        top = float(np.nanmax(self.frequencies_hz)) * 1.1 if self.frequencies_hz.size else 1.0
        scale = self.speeds_rpm / 60.0 / self.reference.frequency_hz
        for rotor in self.rotors:
            for order in self.orders:
                ax.plot(self.speeds_rpm, order * scale * rotor.frequency_hz, color="k", lw=0.9, ls=":")
                x, y = self.speeds_rpm[-1], order * scale[-1] * rotor.frequency_hz
                if y > top:                                  # labelled where it leaves the plot at the top
                    x, y = x * top / y, top
                ax.annotate(f"{order:g}x {rotor.name}", (x, y), fontsize=8, ha="right", va="top")
        for crossing in self.crossings:
            ax.plot(crossing.speed_rpm, crossing.frequency_hz, "o", mfc="none", color="k", ms=7)
        if self.operating_rpm:
            ax.axvspan(*self.operating_rpm, color="0.9", zorder=0, label="operating range")
        ax.set_ylim(0, top)
        ax.set_xlim(self.speeds_rpm[0], self.speeds_rpm[-1])
        ax.set_xlabel(f"{self.reference.name} speed (rpm)")
        ax.set_ylabel("frequency (Hz)")
        ax.set_title(f"{self.case_name}: Campbell diagram ({len(self.crossings)} critical speeds marked)")
        ax.legend(loc="upper left", fontsize=8)
        return ax.figure


def spinning_rotors(case: Case) -> tuple[SpinningRotor, ...]:
    """The case's rotors, or without rotors its rotating excitations (each a rotor's imbalance)."""
    if case.rotors:
        return tuple(SpinningRotor(r.name, float(r.frequency), np.asarray(r.axis, dtype=float), True)
                     for r in case.rotors)
    rotors: list[SpinningRotor] = []
    for x in case.excitations:
        if isinstance(x, (RotatingForce, Imbalance)) and x.name not in {r.name for r in rotors}:
            axis = np.asarray(x.axis, dtype=float)
            rotors.append(SpinningRotor(x.name, float(x.frequency), axis / np.linalg.norm(axis), False))
    return tuple(rotors)


def _mac(a: np.ndarray, b: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """Mass-weighted modal assurance criterion of every column of *a* against every column of *b*."""
    cross = np.abs(np.conj(a).T @ mass @ b) ** 2
    return cross / np.outer(np.real(np.sum(np.conj(a) * (mass @ a), axis=0)),
                            np.real(np.sum(np.conj(b) * (mass @ b), axis=0)))


@dataclass
class _Speed:
    """The candidate modes at one speed fraction: vectors, modes, whirl sign."""

    vectors: np.ndarray
    modes: list
    whirl: np.ndarray


def modal_basis(lin: Linearization, basis_hz: float) -> Linearization:
    """*lin* projected onto its non-rotating modes (``K x = w^2 M x``) up to *basis_hz*, mass-orthonormal."""
    squared, vectors = eigenpairs(dataclasses.replace(lin, gyroscopic=None))
    kept = np.real(vectors[:, squared <= (2 * np.pi * basis_hz) ** 2])
    factor = np.linalg.cholesky(kept.T @ lin.mass @ kept)
    basis = np.linalg.solve(factor, kept.T).T                       # basis^T M basis = I

    def project(matrix):
        return None if matrix is None else basis.T @ matrix @ basis

    return dataclasses.replace(lin, mass=np.eye(basis.shape[1]), stiffness=project(lin.stiffness),
                               damping=project(lin.damping), gyroscopic=project(lin.gyroscopic),
                               structural=project(lin.structural), basis=lin.basis @ basis)


class _Spectrum:
    """The modes of the linearisation at any speed fraction s of the case's rotor speeds."""

    def __init__(self, lin: Linearization, axis: np.ndarray, upper_hz: float):
        self.lin, self.axis, self.limit = lin, axis, _CANDIDATE_MARGIN * upper_hz
        self.gyroscopic = lin.gyroscopic
        self.rest = lin.damping if lin.gyroscopic is None else lin.damping - lin.gyroscopic
        self.engine = lin.body_coordinates[ENGINE]
        self._flat: _Speed | None = None

    def at(self, s: float) -> _Speed:
        """The candidate modes at the speed fraction *s* (without rotors: the same at every speed)."""
        if self.gyroscopic is None and self._flat is not None:
            return self._flat
        lin = self.lin
        if self.gyroscopic is not None:
            lin = dataclasses.replace(lin, damping=self.rest + s * self.gyroscopic, gyroscopic=s * self.gyroscopic)
        squared, vectors = eigenpairs(lin)
        free = (2 * np.pi * FREE_FREQUENCY_HZ) ** 2
        keep = (squared > free) & (squared <= (2 * np.pi * self.limit) ** 2)
        squared, vectors = squared[keep], vectors[:, keep]
        modes = modes_from(lin, squared, vectors)
        speed = _Speed(vectors, modes, self._whirl(vectors, modes))
        if self.gyroscopic is None:
            self._flat = speed
        return speed

    def _whirl(self, vectors: np.ndarray, modes: list[Mode]) -> np.ndarray:
        """+1, -1 or 0 per mode: the engine tilts about the spin axis turning with it, against it, or not."""
        engine = (self.lin.basis @ vectors)[self.engine]
        rotation = engine[3:6]
        turning = -np.imag(np.cross(np.conj(rotation).T, rotation.T)) @ self.axis
        size = np.sum(np.abs(rotation) ** 2, axis=0)
        measure = np.divide(turning, size, out=np.zeros_like(turning), where=size > 0)
        tilt = np.linalg.norm(rotation - np.outer(self.axis, self.axis @ rotation), axis=0)
        tilting = (tilt >= 0.1 * np.abs(engine).max(axis=0)) & np.array([m.engine_share >= 0.1 for m in modes])
        return np.where(tilting & (np.abs(measure) >= _WHIRL_THRESHOLD), np.sign(measure), 0).astype(int)


def _follow(previous: np.ndarray, current: _Speed, mass: np.ndarray) -> np.ndarray:
    """Index of the current candidate that continues each previous branch (one-to-one, largest MAC);
    -1 for a branch without one (fewer candidates than branches)."""
    from scipy.optimize import linear_sum_assignment

    rows, columns = linear_sum_assignment(-_mac(previous, current.vectors, mass))
    order = np.full(previous.shape[1], -1)
    order[rows] = columns
    return order


def _lost_branch(case: Case, spectrum: _Spectrum, description: str, last_hz: float, speeds: np.ndarray,
                 k: int) -> SimulationError:
    """The error for a branch that no candidate mode at ``speeds[k]`` (rpm) continues."""
    return SimulationError(
        f"case {case.name!r}: the Campbell diagram cannot follow the branch of {description} (at {last_hz:.4g} Hz "
        f"at {speeds[k - 1]:.6g} rpm) to {speeds[k]:.6g} rpm: no mode between {FREE_FREQUENCY_HZ:g} Hz and "
        f"{spectrum.limit:.4g} Hz continues it there (the gyroscopic moment, growing with the speed, slows a "
        f"backward whirl towards 0 Hz and speeds a forward whirl up). Narrow the speed range, or raise the "
        f"highest frequency shown")


def campbell(case: Case, *, rotor: str | None = None, start_rpm: float = 0.0, stop_rpm: float | None = None,
             points: int = 200, orders: tuple = (1.0,), upper_hz: float | None = None,
             operating_rpm: tuple[float, float] | None = None, basis_hz: float | None = None) -> CampbellDiagram:
    """The Campbell diagram of *case*.

    Parameters
    ----------
    case : Case
        With rotors (gyroscopic) or rotating excitations (their speeds).
    rotor : str, optional
        The rotor whose speed is the abscissa (default: the first).
    start_rpm, stop_rpm : float
        Speed range of that rotor, rpm (default 0 to 1.25 x its case speed).
    points : int
        Speeds, evenly spaced (at least 2).
    orders : tuple of float
        Engine orders drawn for every rotor (1: once per revolution).
    upper_hz : float, optional
        Highest frequency shown, Hz (default: where the highest order line of the fastest rotor ends, plus 10 %).
    operating_rpm : (float, float), optional
        The reference rotor's operating range (idle to red line), rpm: shaded.
    basis_hz : float, optional
        With rotors: the modes are solved on the non-rotating modes up to this frequency (default
        :data:`BASIS_FACTOR` x *upper_hz*); the top speed is solved on the full model too, and the largest
        frequency difference is the diagram's ``truncation``.

    Raises
    ------
    workbook.errors.CaseError
        No rotor and no rotating excitation, an unknown rotor, or a bad range.
    workbook.errors.SimulationError
        A mechanism or a failed equilibrium (preload).
    """
    from workbook.solve.pipeline import prepare

    rotors = spinning_rotors(case)
    if not rotors:
        raise CaseError(f"case {case.name!r}", "rotors", "none",
                        "a rotor or a rotating excitation (its speed sets the diagram's speeds)")
    names = [r.name for r in rotors]
    if rotor is not None and rotor not in names:
        raise CaseError("Campbell diagram", "rotor", rotor, f"one of {', '.join(names)}")
    reference = rotors[names.index(rotor) if rotor is not None else 0]
    stop_rpm = 1.25 * 60 * reference.frequency_hz if stop_rpm is None else float(stop_rpm)
    if not (0 <= start_rpm < stop_rpm and np.isfinite(stop_rpm)):
        raise CaseError("Campbell diagram", "speed range", (start_rpm, stop_rpm), "0 <= from < to, rpm")
    if points < 2:
        raise CaseError("Campbell diagram", "points", points, "at least 2 speeds")
    if not orders or min(orders) <= 0:
        raise CaseError("Campbell diagram", "orders", orders, "positive engine orders, e.g. 1, 2")
    speeds = np.linspace(start_rpm, stop_rpm, points)
    fractions = speeds / 60.0 / reference.frequency_hz
    if upper_hz is None:
        upper_hz = 1.1 * max(orders) * fractions[-1] * max(r.frequency_hz for r in rotors)
    probe = HarmonicForce("Campbell probe", point=case.engine.center_of_mass, direction=(1.0, 0.0, 0.0),
                          amplitude=1.0, frequency_hz=float(upper_hz))
    start = time.perf_counter()
    prepared = prepare(case, probe)
    with prepared.scene:
        assert prepared.model is not None       # prepared for the frequency domain: it has its harmonic model
        lin = prepared.model.linearization
    built = time.perf_counter()
    basis_hz = BASIS_FACTOR * upper_hz if basis_hz is None else float(basis_hz)
    reduced = lin if lin.gyroscopic is None else modal_basis(lin, basis_hz)
    spectrum = _Spectrum(reduced, reference.axis, upper_hz)
    diagram = _trace(case, spectrum, reference, rotors, tuple(float(o) for o in orders), speeds, fractions, upper_hz)
    diagram.coordinates = lin.mass.shape[0]
    diagram.operating_rpm = None if operating_rpm is None else (float(operating_rpm[0]), float(operating_rpm[1]))
    traced = time.perf_counter()
    diagram.truncation = _truncation(diagram, spectrum, _Spectrum(lin, reference.axis, upper_hz), fractions[-1],
                                     basis_hz)
    diagram.timings = {"prepare": built - start, "modes and crossings": traced - built,
                       "truncation check": time.perf_counter() - traced}
    if diagram.truncation["largest frequency error"] > TRUNCATION_WARNING:
        log.warning("%s: the modal basis to %.0f Hz moves a mode of the Campbell diagram by %.2g %% at %.0f rpm; "
                    "give a higher basis frequency", case.name, basis_hz,
                    100 * diagram.truncation["largest frequency error"], speeds[-1])
    return diagram


def _truncation(diagram: CampbellDiagram, reduced: _Spectrum, full: _Spectrum, fraction: float,
                basis_hz: float) -> dict:
    """How far the modal basis moves the branches at the top speed from the full eigenproblem."""
    size = reduced.lin.mass.shape[0]
    if reduced.lin is full.lin:
        return {"basis modes": size, "basis Hz": None, "largest frequency error": 0.0}
    mine, exact = reduced.at(fraction), full.at(fraction)
    lin = full.lin
    mac = _mac(reduced.lin.basis @ mine.vectors, lin.basis @ exact.vectors, lin.full_mass)
    error = 0.0
    for b in range(len(diagram.descriptions)):
        index = int(np.argmin(np.abs([m.frequency_hz for m in mine.modes] - diagram.frequencies_hz[b, -1])))
        twin = exact.modes[int(np.argmax(mac[index]))].frequency_hz
        error = max(error, abs(mine.modes[index].frequency_hz - twin) / twin)
    return {"basis modes": size, "basis Hz": float(basis_hz), "largest frequency error": float(error)}


def _trace(case: Case, spectrum: _Spectrum, reference: SpinningRotor, rotors: tuple, orders: tuple,
           speeds: np.ndarray, fractions: np.ndarray, upper_hz: float) -> CampbellDiagram:
    """Follow the branches over the speeds and find their crossings with the order lines."""
    mass = spectrum.lin.mass
    flat = spectrum.gyroscopic is None
    first = spectrum.at(fractions[0])
    branches = [i for i, m in enumerate(first.modes) if m.frequency_hz <= upper_hz]
    count = len(branches)
    frequencies, damping, whirl = (np.empty((count, len(speeds))) for _ in range(3))
    vectors = first.vectors[:, branches]
    states = []
    for k, s in enumerate(fractions):
        current = first if k == 0 or flat else spectrum.at(s)
        pick = np.array(branches) if k == 0 or flat else _follow(vectors, current, mass)
        if (pick < 0).any():
            lost = int(np.flatnonzero(pick < 0)[0])
            raise _lost_branch(case, spectrum, first.modes[branches[lost]].description, frequencies[lost, k - 1],
                               speeds, k)
        vectors = current.vectors[:, pick]
        states.append(vectors)
        for b, index in enumerate(pick):
            mode = current.modes[index]
            frequencies[b, k], damping[b, k], whirl[b, k] = mode.frequency_hz, mode.damping_ratio, current.whirl[index]
    descriptions = [first.modes[i].description for i in branches]
    diagram = CampbellDiagram(case.name, reference, rotors, orders, speeds, frequencies, damping,
                              whirl.astype(int), descriptions)
    diagram.crossings = sorted(_crossings(diagram, spectrum, fractions, states),
                               key=lambda c: (c.speed_rpm, c.frequency_hz))
    return diagram


def _crossings(diagram: CampbellDiagram, spectrum: _Spectrum, fractions: np.ndarray, states: list) -> list[Crossing]:
    """Every branch's meetings with every order line, refined on the eigenproblem."""
    from scipy.optimize import toms748

    found = []
    reference = diagram.reference
    for rotor in diagram.rotors:
        for order in diagram.orders:
            line = order * fractions * rotor.frequency_hz
            for b in range(len(diagram.descriptions)):
                gap = diagram.frequencies_hz[b] - line
                for k in np.flatnonzero(np.sign(gap[:-1]) * np.sign(gap[1:]) < 0):
                    def mode_at(s, k=k, b=b):       # the branch's mode by its shape at the interval's end
                        current = spectrum.at(s)      # (at speed 0 a whirl pair is one degenerate mode)
                        index = int(np.argmax(_mac(states[k + 1][:, [b]], current.vectors, spectrum.lin.mass)[0]))
                        return current, index

                    def residual(s, rotor=rotor, order=order, mode_at=mode_at):
                        current, index = mode_at(s)
                        return current.modes[index].frequency_hz - order * s * rotor.frequency_hz

                    s = toms748(residual, fractions[k], fractions[k + 1], xtol=1e-10 * max(fractions[k + 1], 1e-12))
                    current, index = mode_at(s)
                    mode = current.modes[index]
                    found.append(Crossing(rotor.name, order, s * 60 * reference.frequency_hz,
                                          s * 60 * rotor.frequency_hz, mode.frequency_hz, b,
                                          WHIRL[int(current.whirl[index])], mode.damping_ratio, mode.description))
    return found
