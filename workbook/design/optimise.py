"""Design optimisation on the fast linear mount: the best isolation within stated constraints.

A problem is a case, its *variables* (study parameter names of
:func:`workbook.studies.parametric.parameter` with a range each), an
objective and constraints:

- objective ``"worst"``: the worst T over every run (rotor, sweep point) and
  direction, in dB, in the smooth epigraph form: minimise ``t`` subject to
  ``20 log10 T_k <= t`` for every run and direction k;
  ``"weighted"``: the weighted mean of T over runs and directions;
- constraints (:func:`constraint` reads their text): the engine's static
  displacement at its centre of gravity under the preload (``displacement``:
  its length, ``sag``: downwards, m), its static rotation (``rotation``: the
  length of its Rxyz angles, rad), and mounted modes outside a band
  (``modes_outside=LOW:HIGH``, Hz: ``((f - c) / h)^2 >= 1`` for the band's
  centre c and half-width h, the mounted mode nearest the band counting),
  every link's lowest Goodman fatigue factor over each excitation's points
  (``fatigue>=N``, :mod:`workbook.design.link_fatigue`) and its margin of
  safety under each limit load case (``margin>=M``,
  :mod:`workbook.design.link_margins`); every variable within its range;
- speed bands (*bands*, :mod:`workbook.design.bands`): a rotor's excitation
  a sweep over its band, the worst of each band and direction searched
  between its points, each such peak one more row of the objective.

:func:`optimise` runs SLSQP (SciPy) from several starts (the case's own
design, then a Latin hypercube) on variables scaled to [0, 1], on a
logarithmic scale for stiffness and damping, with the analytic derivatives
of :func:`workbook.design.sensitivity.design_sensitivity` (the mounted
modes' by their left and right eigenvectors). Every evaluation is on the
fast path (:class:`~workbook.design.linear_mount.LinearMount`). The links'
``section_scale`` needs a new link reduction per value: it is searched
outside, over a grid of scales (:mod:`workbook.design.section_search`), a
new linear mount prepared and the fast variables optimised at each scale
the search asks for. The starts run in worker processes with ``workers``
above 1, with the same result as one after another. The optimum
is run once more through :func:`workbook.run_case`, whose T the result
reports and ``mountwb run`` on the written case reproduces. :func:`pareto`
gives a two-objective front by NSGA-II (pymoo).
"""
from __future__ import annotations

import contextlib
import dataclasses
import logging
import multiprocessing
import signal
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.linalg as sla

from workbook.design.bands import BAND_POINTS, band_case, band_peaks, with_frequencies
from workbook.design.linear_mount import DesignAnswer, LinearMount, points_of
from workbook.design.link_fatigue import link_fatigue_factors
from workbook.design.link_margins import link_margins, load_case_mounts
from workbook.design.section_search import SECTION, SECTION_STEP, grid_minimum, section_grid
from workbook.design.sensitivity import amplitude_change, design_case, design_sensitivity, point_change
from workbook.errors import InfeasibleProblem, InputError, SimulationError
from workbook.model.case import DIRECTIONS, Case, Sweep
from workbook.processes import end_with_parent, stop_workers

if TYPE_CHECKING:
    from openpyxl import Workbook

    from workbook.excel.optimise_sheet import OptimiseSheet

__all__ = ["Variable", "Constraint", "constraint", "variable", "variable_name", "optimise", "pareto", "OptimisationResult",
           "ParetoFront", "OBJECTIVES", "QUANTITIES", "MARGIN"]

log = logging.getLogger(__name__)

#: Objectives of :func:`optimise`.
OBJECTIVES = ("worst", "weighted")
#: Constraint quantities bounded from above, and their units.
QUANTITIES = {"displacement": "m", "sag": "m", "rotation": "rad"}
#: The band constraint's name.
MODES_OUTSIDE = "modes_outside"
#: The fatigue constraint's name: every link's lowest Goodman factor at least the limit.
FATIGUE = "fatigue"
#: The static margin constraint's name: every link's margin of safety under every limit load case at least the limit.
LINK_MARGIN = "margin"
#: Relative margin inside each stated limit the optimiser aims at, so that its optimum meets the limit.
MARGIN = 1e-6
#: A constraint whose normalised slack is below this is reported active.
ACTIVE = 1e-4
#: Normalised violation above which a design counts as infeasible.
FEASIBLE = MARGIN / 2
#: Why a front refuses the section scale.
_FRONT_FAST_ONLY = f"a Pareto front varies the fast variables only; fix {SECTION} (or leave out the front)"
#: Parameters on a logarithmic scale when their range is positive.
_LOG = ("hinge_stiffness", "hinge_damping", "transducer_stiffness")
#: Parameters the fast path follows.
_FAST = ("hinge_stiffness", "hinge_damping", "hinge_loss_factor", "transducer_stiffness", "engine_mass")


@dataclass(frozen=True)
class Variable:
    """A design variable: a study parameter and its range (SI units)."""

    name: str
    low: float
    high: float

    @property
    def log(self) -> bool:
        """Whether it is scaled logarithmically (stiffness, damping with a positive range)."""
        return self.name.partition("/")[0] in _LOG and self.low > 0

    def value(self, x: float) -> float:
        """The value at the scaled position *x* in [0, 1]."""
        if self.log:
            return float(self.low * (self.high / self.low) ** x)
        return float(self.low + x * (self.high - self.low))

    def scaled(self, value: float) -> float:
        """The scaled position of *value* (the inverse of :meth:`value`)."""
        if self.log:
            return float(np.log(value / self.low) / np.log(self.high / self.low))
        return float((value - self.low) / (self.high - self.low))

    def slope(self, x: float) -> float:
        """d value / d x at *x*."""
        return self.value(x) * np.log(self.high / self.low) if self.log else self.high - self.low


def variable_name(name: str) -> None:
    """Check that *name* is a study parameter the optimiser varies: one the fast path follows, or
    ``section_scale`` (searched over a grid of scales, a new link reduction each).

    Raises
    ------
    InputError
        An unknown name, or one the optimiser does not vary.
    """
    from workbook.studies.parametric import parameter

    parameter(name)
    if name.partition("/")[0] not in _FAST and name != SECTION:
        raise InputError(f"variable {name!r}: the optimiser varies what the fast linear mount follows "
                         f"({', '.join(_FAST)}, per hinge group and direction) and {SECTION}; {name} needs a new "
                         "preparation per design: use 'mountwb study params' for it")


def variable(name: str, low: float, high: float) -> Variable:
    """The variable *name* over [low, high].

    Raises
    ------
    InputError
        A parameter the optimiser does not vary, an unknown name, an empty
        range, or a section scale range not above 0.
    """
    variable_name(name)
    if not (np.isfinite(low) and np.isfinite(high) and high > low):
        raise InputError(f"variable {name!r}: found the range {low:g}:{high:g}, expected LOW:HIGH with LOW < HIGH")
    if name.partition("/")[0] in _LOG and low < 0:
        raise InputError(f"variable {name!r}: found LOW {low:g}, expected a stiffness or damping >= 0")
    if name == SECTION and not low > 0:
        raise InputError(f"variable {name!r}: found LOW {low:g}, expected a factor on the links' section > 0")
    return Variable(name, float(low), float(high))


@dataclass(frozen=True)
class Constraint:
    """A constraint: ``quantity <= limit`` (``fatigue >= limit``), or mounted modes outside the band ``limit``
    (low, high), Hz."""

    quantity: str
    limit: Any          # float, or (low, high) for a band

    @property
    def text(self) -> str:
        """As :func:`constraint` reads it."""
        if self.quantity == MODES_OUTSIDE:
            return f"{MODES_OUTSIDE}={self.limit[0]:g}:{self.limit[1]:g}"
        if self.quantity in (FATIGUE, LINK_MARGIN):
            return f"{self.quantity}>={self.limit:g}"
        return f"{self.quantity}<={self.limit:g}"


def constraint(text: str) -> Constraint:
    """Read a constraint: ``displacement<=M``, ``sag<=M``, ``rotation<=RAD``, ``modes_outside=LOW:HIGH`` (Hz)
    ``fatigue>=N`` (every link's lowest Goodman factor over every excitation point, bands' peaks included)
    or ``margin>=M`` (every link's margin of safety under every limit load case of the case).

    Raises
    ------
    InputError
        Naming the text and what is expected.
    """
    expected = (f"expected {', '.join(f'{q}<=VALUE ({u})' for q, u in QUANTITIES.items())} or "
                f"{MODES_OUTSIDE}=LOW:HIGH (Hz), {FATIGUE}>=FACTOR or {LINK_MARGIN}>=MARGIN")
    quantity, sign, rest = text.replace(" ", "").partition(">=")
    try:
        if sign and quantity in (FATIGUE, LINK_MARGIN) and float(rest) > (0 if quantity == FATIGUE else -1):
            return Constraint(quantity, float(rest))
        quantity, sign, rest = text.replace(" ", "").partition("<=")
        if sign and quantity in QUANTITIES and float(rest) > 0:
            return Constraint(quantity, float(rest))
        quantity, sign, rest = text.replace(" ", "").partition("=")
        if sign and quantity == MODES_OUTSIDE:
            low, high = (float(v) for v in rest.split(":"))
            if 0 <= low < high:
                return Constraint(quantity, (low, high))
    except ValueError:
        pass
    raise InputError(f"constraint {text!r}: {expected}, the value positive and LOW < HIGH")


@dataclass
class _Point:
    """One design answered: T with its scaled gradient, and the constraints' rows."""

    x: np.ndarray
    values: dict
    answer: DesignAnswer
    t: np.ndarray                   # (R, 3)
    dt: np.ndarray                  # (R, 3, n) per scaled variable
    measures: list                  # per constraint row: (label, value, limit text)
    g: np.ndarray                   # normalised slack, >= 0 feasible
    dg: np.ndarray                  # (rows, n)
    rows: list = field(default_factory=list)     # per row of t: its excitation item
    peaks: dict = field(default_factory=dict)    # per band (sweep): its peaks' frequencies per direction, Hz


def _mounted_modes(solution, changes) -> tuple[np.ndarray, np.ndarray]:
    """Mounted mode frequencies (Hz) of an item and their derivatives (modes, P), undamped, without gyroscopics."""
    from workbook.solve.modes import ENGINE_SHARE

    mass, stiffness = solution.model.mass, solution.model.stiffness
    eigenvalues, left, right = sla.eig(stiffness, mass, left=True, right=True)
    free = solution.prepared.expansion.free
    engine = np.searchsorted(free, solution.prepared.engine)
    energy = np.einsum("im,ij,jm->m", right.conj(), mass, right).real
    share = np.einsum("im,ij,jm->m", right[engine].conj(), mass[np.ix_(engine, engine)], right[engine]).real / energy
    keep = np.isfinite(eigenvalues) & (eigenvalues.real > 0) & (share >= ENGINE_SHARE)
    lam, x, y = eigenvalues[keep].real, right[:, keep], left[:, keep]
    hz = np.sqrt(lam) / (2 * np.pi)
    norm = np.einsum("im,ij,jm->m", y.conj(), mass, x)
    d_lam = np.array([np.einsum("im,ij,jm->m", y.conj(), model.stiffness, x)
                      - lam * np.einsum("im,ij,jm->m", y.conj(), model.mass, x) for model, _ in changes]).T
    return hz, (d_lam / norm[:, None]).real / (8 * np.pi ** 2 * hz[:, None])


def _measure(item: str, rule: Constraint, static: np.ndarray, d_static: np.ndarray, modes) -> tuple:
    """One constraint on one excitation item's design.

    Parameters
    ----------
    static, d_static : ndarray, shapes (6,) and (6, P)
        The engine's static displacement and rotation, and their derivatives.
    modes : (ndarray, ndarray) or None
        Mounted mode frequencies (Hz) and their derivatives (modes, P); None without a band constraint.

    Returns
    -------
    (label, value, slack, slack's gradient (P,))
        The slack normalised (>= 0: met).
    """
    if rule.quantity == MODES_OUTSIDE:
        hz, d_hz = modes
        low, high = rule.limit
        centre, half = (low + high) / 2, (high - low) / 2 * (1 + MARGIN)
        k = int(np.argmin(np.abs(hz - centre)))
        return (f"nearest mounted mode, Hz ({item})", float(hz[k]), ((hz[k] - centre) / half) ** 2 - 1,
                2 * (hz[k] - centre) / half ** 2 * d_hz[k])
    part = slice(3, 6) if rule.quantity == "rotation" else slice(0, 3)
    vector, d_vector = static[part], d_static[part]
    if rule.quantity == "sag":
        value, gradient = float(-vector[2]), -d_vector[2]
    else:
        value = float(np.linalg.norm(vector))
        gradient = vector @ d_vector / max(value, 1e-300)
    return (f"{rule.quantity}, {QUANTITIES[rule.quantity]} ({item})", value,
            (rule.limit * (1 - MARGIN) - value) / rule.limit, -gradient / rule.limit)


class _Problem:
    """The scaled problem, each design answered once (the last one kept)."""

    def __init__(self, mount: LinearMount, variables: list[Variable], constraints: list[Constraint],
                 derivatives: bool = True, load_mounts: list | None = None):
        self.mount, self.variables, self.constraints = mount, variables, constraints
        self.derivatives = derivatives
        self.load_mounts = load_mounts or []       # (LoadCase, LinearMount) of the margin constraints
        self.items = [item.name for item in mount.case.excitations]
        self.evaluations = 0
        self._cache: dict = {}

    def __getstate__(self) -> dict:
        """Pickled for a worker process without the designs answered already."""
        return {**self.__dict__, "_cache": {}}

    def values(self, x: np.ndarray) -> dict:
        return {v.name: v.value(float(xi)) for v, xi in zip(self.variables, x, strict=True)}

    def point(self, x: np.ndarray) -> _Point:
        """The design at the scaled position *x* (put within [0, 1])."""
        x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
        key = x.tobytes()
        if key not in self._cache:
            slope = np.array([v.slope(float(xi)) for v, xi in zip(self.variables, x, strict=True)])
            self._cache = {key: self.answer(self.values(x), x, slope)}    # SLSQP asks for one design at a time
        return self._cache[key]

    def answer(self, values: dict, x: np.ndarray, slope: np.ndarray) -> _Point:
        """The design with the parameter *values*; derivatives per scaled variable (*slope*: d value / d x)."""
        self.evaluations += 1
        fatigue = any(rule.quantity == FATIGUE for rule in self.constraints)
        excitations = self.mount.case.excitations           # a design changes none of them
        if self.derivatives:
            s = design_sensitivity(self.mount, values)
            answer, solutions, changes, motions = s.answer, s.solutions, s.changes, s.motions
            t, dt = s.transmissibility, s.gradient * slope
        else:
            begin = time.perf_counter()
            case = design_case(self.mount, values)
            solutions = self.mount.solve_items(case)
            answer = self.mount.answer(case, solutions, begin)
            changes = [[] for _ in solutions]
            t = np.array([run.transmissibility for run in answer.result.runs])
            dt = np.zeros(t.shape + (len(x),))
            motions = [point_change(solution, [], excitation)[:2] if fatigue else None
                       for item, solution in zip(excitations, solutions, strict=True)
                       for excitation in points_of(item)]
        pylon = [self.mount.channels.index(name) for name in self.mount.pylon]
        rows = [item.name for item in excitations for _ in points_of(item)]
        extra_t, extra_dt, peaks = [], [], {}
        item_motions = []
        row = 0
        for item, solution, item_changes in zip(excitations, solutions, changes, strict=True):
            count = len(points_of(item))
            item_motions.append(list(motions[row:row + count]))
            models = [model for model, _ in item_changes]
            if isinstance(item, Sweep) and count > 1:
                peaks[item.name] = band_peaks(item, solution, pylon, t[row:row + count])
                for frequency in peaks[item.name]:
                    excitation = dataclasses.replace(item.template, frequency_hz=float(frequency), rpm=None)
                    motion, d_motion, forces, d_forces = point_change(solution, models, excitation)
                    force, d_force = forces[pylon].sum(axis=0), d_forces[pylon].sum(axis=0)
                    extra_t.append(np.abs(force) / excitation.force_amplitude)
                    extra_dt.append(amplitude_change(force[:, None], d_force) / excitation.force_amplitude * slope
                                    if self.derivatives else np.zeros((3, len(x))))
                    item_motions[-1].append((motion, d_motion))
                    rows.append(item.name)
            row += count
        if extra_t:
            t, dt = np.vstack([t, extra_t]), np.concatenate([dt, extra_dt])
        modes = [_mounted_modes(solution, item_changes) for solution, item_changes in zip(solutions, changes, strict=True)] \
            if any(rule.quantity == MODES_OUTSIDE for rule in self.constraints) else []
        measures, g, dg = [], [], []
        for k, (name, solution) in enumerate(zip(self.items, solutions, strict=True)):
            d_state = np.array([d for _, d in changes[k]]).T.reshape(len(solution.prepared.expansion.state), -1)
            static, d_static = solution.engine_static, d_state[solution.prepared.engine]
            for rule in self.constraints:
                if rule.quantity == FATIGUE:
                    for factor in link_fatigue_factors(solution, d_state, item_motions[k]):
                        measures.append((f"fatigue factor, Goodman ({name}, {factor.link})", factor.goodman,
                                         rule.text))
                        g.append((factor.goodman - rule.limit * (1 + MARGIN)) / rule.limit)
                        dg.append(factor.gradient * slope / rule.limit if self.derivatives else np.zeros(len(x)))
                    continue
                label, value, slack, d_slack = _measure(name, rule, static, d_static, modes[k] if modes else None)
                measures.append((label, value, rule.text))
                g.append(slack)
                dg.append(d_slack * slope if self.derivatives else np.zeros(len(x)))
        for rule in (rule for rule in self.constraints if rule.quantity == LINK_MARGIN):
            for load_case, load_mount in self.load_mounts:
                if self.derivatives:
                    s = design_sensitivity(load_mount, values)
                    solution, d_state = s.solutions[0], np.array([d for _, d in s.changes[0]]).T
                else:
                    solution = load_mount.solve_items(design_case(load_mount, values))[0]
                    d_state = np.zeros((len(solution.prepared.expansion.state), 0))
                for margin in link_margins(solution, d_state, load_case.factor_of_safety):
                    measures.append((f"link margin ({load_case.name}, {margin.link})", margin.margin, rule.text))
                    g.append(margin.margin - rule.limit - MARGIN)
                    dg.append(margin.gradient * slope if self.derivatives else np.zeros(len(x)))
        return _Point(x, values, answer, t, dt, measures, np.array(g), np.array(dg).reshape(len(g), len(x)),
                      rows, peaks)

    def violation(self, point: _Point) -> float:
        """The largest normalised violation (0: feasible)."""
        return float(max(0.0, -point.g.min())) if len(point.g) else 0.0


def _levels(point: _Point) -> tuple[np.ndarray, np.ndarray]:
    """20 log10 T per run and direction (flattened) and its gradient (R 3, n)."""
    t = np.maximum(point.t.reshape(-1), 1e-12)
    return 20 * np.log10(t), 20 / np.log(10) * point.dt.reshape(len(t), -1) / t[:, None]


def _objective_value(kind: str, weights: np.ndarray, point: _Point) -> float:
    """The objective at *point*: worst T in dB, or the weighted mean of T."""
    if kind == "worst":
        return float(_levels(point)[0].max())
    return float(weights.reshape(-1) @ point.t.reshape(-1) / weights.sum())


@dataclass
class ParetoFront:
    """A two-objective front (NSGA-II).

    Attributes
    ----------
    objectives : tuple of str
    designs : pandas.DataFrame
        One row per non-dominated design: the variables, then both objectives.
    evaluations : int
    seconds : float
    """

    objectives: tuple
    designs: Any
    evaluations: int
    seconds: float


@dataclass
class OptimisationResult:
    """What :func:`optimise` found.

    Attributes
    ----------
    case : Case
        The optimised case (written by :meth:`write`).
    before : Case
    variables, constraints : list
    objective : str
    values : dict
        The optimum's variable values, SI units.
    table : pandas.DataFrame
        Before and after: the objective, every constraint (value, limit,
        active) and each variable.
    history : pandas.DataFrame
        Per start and SLSQP iteration: objective and largest normalised violation.
    starts : list of dict
        Per start: its end, objective, violation, iterations, message.
    result : MountResult
        The optimum run by :func:`workbook.run_case` (the T reported).
    fast_difference : float
        Largest difference of the fast path's T from *result*'s at the optimum.
    evaluations : int
        Designs answered with derivatives.
    seconds : float
        Wall time (preparation, starts and the final run), s.
    pareto : ParetoFront or None
    sections : pandas.DataFrame or None
        With ``section_scale`` varied, per section scale tried: the best
        objective of the fast variables there and its violation, the
        distinct link reductions it needed and their time (computed, or
        loaded from the disk cache), the preparation's and the optimisation's
        time (s) and the designs answered; *history* and *starts* are those
        of the chosen scale.
    bands : dict of str to (float, float)
        The speed bands the problem judged T over, Hz.
    asked_starts : int
        The SLSQP starts asked for.
    """

    case: Case
    before: Case
    variables: list
    constraints: list
    objective: str
    values: dict
    table: Any
    history: Any
    starts: list
    result: Any
    fast_difference: float
    evaluations: int
    seconds: float
    pareto: ParetoFront | None = field(default=None)
    sections: Any = field(default=None)
    bands: dict = field(default_factory=dict)
    asked_starts: int = 1

    def to_pandas(self):
        """The before/after table."""
        return self.table

    def plot(self, path: str | Path | None = None):
        """Convergence of every start (and the Pareto front when there is one); saved as PNG at *path*.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        panels = 2 if self.pareto is not None else 1
        figure, axes = plt.subplots(1, panels, figsize=(6 * panels, 4), squeeze=False)
        ax = axes[0, 0]
        for start, rows in self.history.groupby("start"):
            feasible = rows["violation"] <= FEASIBLE
            ax.plot(rows["iteration"], rows["objective"], "-", color=f"C{start % 10}", label=f"start {start}")
            ax.plot(rows["iteration"][~feasible], rows["objective"][~feasible], "x", color=f"C{start % 10}")
        ax.set_xlabel("SLSQP iteration")
        ax.set_ylabel("worst T, dB" if self.objective == "worst" else "weighted mean T")
        ax.set_title("convergence (x: infeasible)")
        ax.legend(fontsize="small")
        if self.pareto is not None:
            first, second = self.pareto.objectives
            front = self.pareto.designs.sort_values(first)
            axes[0, 1].plot(front[first], front[second], "o-")
            axes[0, 1].set_xlabel(first)
            axes[0, 1].set_ylabel(second)
            axes[0, 1].set_title(f"Pareto front, {len(front)} designs")
        figure.tight_layout()
        if path is not None:
            figure.savefig(path, dpi=100)
        return figure

    def write(self, directory: str | Path) -> list[Path]:
        """Write the optimised case (``optimum.json``; ``optimum.xlsx`` when a case workbook can hold it), the
        table, the history (CSV), the Pareto front and the section scales tried (CSV) and the plot into
        *directory*.

        Returns
        -------
        list of Path
        """
        from workbook.errors import UnwritableCase
        from workbook.excel.files import save_atomic
        from workbook.model.codec import to_json

        folder = Path(directory)
        folder.mkdir(parents=True, exist_ok=True)
        written = [folder / "optimum.json", folder / "table.csv", folder / "history.csv", folder / "convergence.png"]
        written[0].write_text(to_json(self.case), encoding="utf-8")
        self.table.to_csv(written[1])
        self.history.to_csv(written[2], index=False)
        self.plot(written[3])
        if self.pareto is not None:
            written.append(folder / "pareto.csv")
            self.pareto.designs.to_csv(written[-1], index=False)
        if self.sections is not None:
            written.append(folder / "sections.csv")
            self.sections.to_csv(written[-1], index=False)
        try:
            book = self.workbook()
        except UnwritableCase as error:
            log.warning("optimum.xlsx not written: %s", error)
            return written
        written.append(save_atomic(book, folder / "optimum.xlsx"))
        return written

    def problem(self) -> OptimiseSheet:
        """The problem solved, as the optimum's Optimise sheet holds it: the variables with their ranges (a
        ``section_scale``'s divided by the scale chosen, the optimum's links the new 1), the objective, the
        constraints, the bands and the starts; not the weights of :func:`optimise`, nor its seed, iterations or
        section step."""
        from workbook.excel.optimise_sheet import OptimiseSheet

        scale = self.values.get(SECTION, 1.0)
        variables = {v.name: (v.low / scale, v.high / scale) if v.name == SECTION else (v.low, v.high)
                     for v in self.variables}
        return OptimiseSheet(variables, tuple(self.constraints), dict(self.bands), self.objective, self.asked_starts)

    def workbook(self) -> Workbook:
        """The optimised case as a case workbook: a run per excitation (what :attr:`result` ran), the problem
        solved on its Optimise sheet (:meth:`problem`), so that ``mountwb optimise`` on it starts from the optimum.

        Returns
        -------
        openpyxl.Workbook

        Raises
        ------
        workbook.errors.UnwritableCase
            A case no case workbook holds (e.g. a mesh link), or one optimised over speed bands: a banded rotor
            is a sweep over its band (its peaks added), no longer the single-frequency excitation a band row names.
        """
        from workbook.errors import UnwritableCase
        from workbook.excel.runs import RunSpec
        from workbook.excel.template import case_workbook

        if self.bands:
            raise UnwritableCase(f"speed bands ({', '.join(self.bands)}): a banded rotor is a sweep over its band "
                                 "(its peaks added), no longer the single-frequency excitation a band row names; "
                                 "optimum.json holds the optimum")
        return case_workbook(self.case, [RunSpec(item.name, item.name) for item in self.case.excitations],
                             optimise=self.problem())


def _run_start(problem: _Problem, kind: str, weights: np.ndarray, x0: np.ndarray, start: int,
               history: list, maxiter: int):
    """One SLSQP run from *x0*: returns (x, message, iterations)."""
    from scipy.optimize import minimize

    n = len(x0)
    epigraph = kind == "worst"

    def split(z):
        return z[:n] if epigraph else z

    def objective(z):
        if epigraph:
            return z[n]
        return _objective_value(kind, weights, problem.point(z))

    def objective_gradient(z):
        if epigraph:
            return np.eye(n + 1)[n]
        point = problem.point(z)
        return np.einsum("k,kn->n", weights.reshape(-1), point.dt.reshape(-1, n)) / weights.sum()

    def constraints(z):
        point = problem.point(split(z))
        rows = [point.g]
        if epigraph:
            rows.append(z[n] - _levels(point)[0])
        return np.concatenate(rows)

    def constraints_gradient(z):
        point = problem.point(split(z))
        rows = [np.hstack([point.dg, np.zeros((len(point.g), 1))]) if epigraph else point.dg]
        if epigraph:
            levels = _levels(point)[1]
            rows.append(np.hstack([-levels, np.ones((len(levels), 1))]))
        return np.vstack(rows)

    def record(z):
        point = problem.point(split(z))
        history.append({"start": start, "iteration": len([h for h in history if h["start"] == start]),
                        "objective": _objective_value(kind, weights, point), "violation": problem.violation(point)})

    z0 = np.append(x0, _levels(problem.point(x0))[0].max()) if epigraph else x0
    bounds = [(0.0, 1.0)] * n + ([(-400.0, 400.0)] if epigraph else [])
    record(z0)
    answer = minimize(objective, z0, jac=objective_gradient, method="SLSQP", bounds=bounds,
                      constraints=[{"type": "ineq", "fun": constraints, "jac": constraints_gradient}],
                      callback=record, options={"maxiter": maxiter, "ftol": 1e-7})
    return np.clip(split(answer.x), 0.0, 1.0), str(answer.message), int(answer.nit)


def _least_violation(problem: _Problem, x0: np.ndarray) -> np.ndarray:
    """The design within the bounds with the least squared violation, from *x0* (L-BFGS-B)."""
    from scipy.optimize import minimize

    def violation(x):
        point = problem.point(x)
        short = np.minimum(point.g, 0.0)
        return float(short @ short), 2 * short @ point.dg

    return minimize(violation, x0, jac=True, method="L-BFGS-B", bounds=[(0.0, 1.0)] * len(x0)).x


def _worst(rows: list, t: np.ndarray) -> dict:
    """The worst T per excitation item and direction (over a band's points and peaks)."""
    items = np.array(rows)
    return {(item, d): float(t[items == item, k].max()) for item in dict.fromkeys(rows)
            for k, d in enumerate(DIRECTIONS)}


def _table(kind: str, weights: np.ndarray, before: _Point, after: _Point, exact: tuple, variables: list):
    """Before and after; the T rows (the worst of each excitation item and direction) of *after* from *exact*
    (rows, T): the pipeline's run of the written optimum; *variables*: (Variable, before, after) each."""
    import pandas as pd

    rows = [("objective", "worst T (dB)" if kind == "worst" else "weighted mean T",
             _objective_value(kind, weights, before), _objective_value(kind, weights, after), "", "")]
    worst_before, worst_after = _worst(before.rows, before.t), _worst(*exact)
    rows += [("T", f"{item} {d}", value, worst_after[item, d], "", "") for (item, d), value in worst_before.items()]
    for (label, value_before, limit), (_, value_after, _), slack in zip(before.measures, after.measures, after.g,
                                                                         strict=True):
        rows.append(("constraint", label, value_before, value_after, limit, "active" if slack <= ACTIVE else ""))
    for v, value_before, value_after in variables:
        x = v.scaled(value_after)
        at = "at low" if x <= ACTIVE else "at high" if x >= 1 - ACTIVE else ""
        rows.append(("variable", v.name, value_before, value_after, f"{v.low:g}:{v.high:g}", at))
    return pd.DataFrame(rows, columns=["kind", "name", "before", "after", "limit", "active"]).set_index(["kind", "name"])


def _weights(weights, runs: int) -> np.ndarray:
    if weights is None:
        return np.ones((runs, 3))
    array = np.broadcast_to(np.asarray(weights, dtype=float), (runs, 3))
    if np.any(array < 0) or array.sum() <= 0:
        raise InputError(f"weights: found {np.asarray(weights).tolist()}, expected non-negative weights per run "
                         f"and direction, shape ({runs}, 3), not all zero")
    return array


def optimise(case: Case, variables: dict, objective: str = "worst", constraints=(), starts: int = 4,
             weights=None, seed: int = 0, maxiter: int = 60, pareto_objectives: tuple | None = None,
             population: int = 50, generations: int = 20, mount: LinearMount | None = None, bands: dict | None = None,
             band_points: int = BAND_POINTS, workers: int = 1, section_step: float = SECTION_STEP
             ) -> OptimisationResult:
    """The design of *case* within *variables* that minimises *objective* subject to *constraints*.

    Parameters
    ----------
    case : Case
    variables : dict of str to (float, float)
        Study parameter name to its range (low, high), SI units;
        ``section_scale`` (a factor on the case's link sections) searched
        over a grid of scales (:mod:`workbook.design.section_search`).
    objective : {"worst", "weighted"}
        Worst T over runs and directions (dB), or the weighted mean of T;
        a sweep's (a band's) runs include its peaks (:func:`~workbook.design.bands.band_peaks`).
    constraints : iterable of Constraint or str
        See :func:`constraint`.
    starts : int
        SLSQP starts: the case's own design (put within the ranges), then a Latin hypercube.
    weights : array_like, optional
        Per run and direction, shape (R, 3) or broadcastable (the ``weighted`` objective).
    seed : int
        Of the Latin hypercube (and of NSGA-II).
    maxiter : int
        SLSQP iterations per start.
    pareto_objectives : (str, str), optional
        Also a front of these two objectives (:func:`pareto`; not with ``section_scale``).
    population, generations : int
        Of the front's NSGA-II.
    mount : LinearMount, optional
        *case* prepared already (with *bands*: the case of :func:`~workbook.design.bands.band_case`).
    bands : dict of str to (float, float), optional
        Rotor excitation name to its speed band (idle, red line), Hz: the
        excitation becomes a sweep of *band_points* speeds over it
        (:func:`~workbook.design.bands.band_case`).
    band_points : int
    workers : int
        Processes the starts run in (1: one after another in this process); the result is the same.
    section_step : float
        Largest step between the section scales tried (``section_scale``'s tolerance).

    Returns
    -------
    OptimisationResult

    Raises
    ------
    InputError
        An unknown objective or constraint, or a variable the optimiser cannot vary.
    InfeasibleProblem
        No design within the ranges meets the constraints; names those that conflict.
    workbook.errors.SimulationError
        As :meth:`LinearMount.evaluate` at the case's own design; a worker process that died.
    """
    import pandas as pd
    from scipy.stats import qmc

    from workbook.solve.pipeline import run_case
    from workbook.studies.parametric import parameter_value

    begin = time.perf_counter()
    if objective not in OBJECTIVES:
        raise InputError(f"objective {objective!r}: expected one of {', '.join(OBJECTIVES)}")
    if starts < 1:
        raise InputError(f"starts: found {starts}, expected at least 1")
    chosen = [variable(name, *bounds) for name, bounds in variables.items()]
    section = next((v for v in chosen if v.name == SECTION), None)
    fast = [v for v in chosen if v.name != SECTION]
    if section is not None:
        grid = section_grid(section.low, section.high, section_step)
        if pareto_objectives:
            raise InputError(_FRONT_FAST_ONLY)
    rules = [rule if isinstance(rule, Constraint) else constraint(rule) for rule in constraints]
    mount = mount or LinearMount.prepare(band_case(case, bands, band_points) if bands else case)
    problem = _Problem(mount, fast, rules, load_mounts=_load_mounts(case, rules))
    before_values = {v.name: parameter_value(mount.case, v.name) for v in fast}
    start = np.array([v.scaled(before_values[v.name]) for v in fast])
    before = problem.answer(before_values, start, np.ones(len(fast)))
    weight = _weights(weights, len(before.rows))
    positions = [np.clip(start, 0, 1)]
    if starts > 1 and fast:
        positions += list(qmc.LatinHypercube(d=len(fast), seed=seed).random(starts - 1))
    with _start_pool(workers, len(positions)) as pool:
        if section is None:
            trials = [_trial(problem, objective, weight, positions, maxiter, pool)]
        else:
            tried: dict[int, _Trial] = {}

            def key(index: int) -> tuple:
                scaled, cost = (problem, {}) if grid[index] == 1.0 else \
                    _section_problem(case, float(grid[index]), fast, rules, bands, band_points)   # 1: the case's own
                tried[index] = _trial(scaled, objective, weight, positions, maxiter, pool, **cost)
                return tried[index].key

            grid_minimum(len(grid), key)
            trials = [tried[index] for index in sorted(tried)]
    chosen_trial = min(trials, key=lambda trial: trial.key)
    best = chosen_trial.best()
    if best["violation"] > FEASIBLE:
        _raise_infeasible(chosen_trial.problem, best.get("x", positions[0]), [] if section is None else [
            f"{SECTION} {chosen_trial.scale:g} (the least violating of the {len(trials)} scales tried)"])
    at = chosen_trial.problem
    after = at.point(best["x"])
    optimum = with_frequencies(design_case(at.mount, after.values), after.peaks)    # the bands' peaks as speeds
    result = run_case(optimum)
    exact = np.array([run.transmissibility for run in result.runs])
    fast_t = np.array([run.transmissibility for run in at.mount.evaluate(optimum).result.runs])
    front = pareto(mount.case, variables, pareto_objectives, rules, population, generations, seed, mount) \
        if pareto_objectives else None
    exact_rows = [item.name for item in optimum.excitations for _ in points_of(item)]
    rows = [(v, before_values[v.name], after.values[v.name]) for v in fast]
    values = dict(after.values)
    if section is not None:
        rows.append((section, 1.0, chosen_trial.scale))
        values[SECTION] = chosen_trial.scale
    sections = pd.DataFrame([trial.row() for trial in trials]) if section is not None else None
    return OptimisationResult(
        optimum, mount.case, chosen, rules, objective, values,
        _table(objective, weight, before, after, (exact_rows, exact), rows),
        pd.DataFrame(chosen_trial.history, columns=["start", "iteration", "objective", "violation"]),
        [{k: v for k, v in end.items() if k != "x"} for end in chosen_trial.ends], result,
        float(np.abs(exact - fast_t).max()),
        problem.evaluations + sum(trial.problem.evaluations for trial in trials if trial.problem is not problem),
        time.perf_counter() - begin, front, sections, dict(bands or {}), starts)


def _load_mounts(case: Case, rules: list) -> list:
    """The (load case, linear mount) pairs the margin constraints need (none without one)."""
    return load_case_mounts(case) if any(rule.quantity == LINK_MARGIN for rule in rules) else []


@dataclass
class _Trial:
    """The fast variables optimised on one prepared mount: at the case's own links, or at a section scale."""

    problem: _Problem
    ends: list                      # per start: its end (x, objective, violation, iterations, message)
    history: list
    seconds: float                  # the starts' wall time, s
    scale: float = 1.0
    reductions: int = 0
    reduction_seconds: float = 0.0
    preparation_seconds: float = 0.0

    def best(self) -> dict:
        """The best feasible end, else the least violating one."""
        feasible = [end for end in self.ends if end["violation"] <= FEASIBLE]
        if feasible:
            return min(feasible, key=lambda end: end["objective"])
        return min(self.ends, key=lambda end: end["violation"])

    @property
    def key(self) -> tuple:
        """Orders trials: feasible before infeasible, then by objective (feasible) or by violation."""
        end = self.best()
        return (0, end["objective"]) if end["violation"] <= FEASIBLE else (1, end["violation"])

    def row(self) -> dict:
        """Its row of :attr:`OptimisationResult.sections`."""
        end = self.best()
        return {SECTION: self.scale, "objective": end["objective"], "violation": end["violation"],
                "distinct link reductions": self.reductions, "reduction s": self.reduction_seconds,
                "preparation s": self.preparation_seconds, "optimisation s": self.seconds,
                "designs": self.problem.evaluations}


def _section_problem(case: Case, scale: float, fast: list, rules: list, bands: dict | None,
                     band_points: int) -> tuple[_Problem, dict]:
    """The problem of the fast variables on *case* with its links' sections scaled by *scale*: its links
    reduced (or loaded from the disk cache) and its linear mount prepared; and that cost (:class:`_Trial`'s
    fields)."""
    from workbook.scene.build import link_jobs, reduce_links
    from workbook.studies.parametric import parameter

    begin = time.perf_counter()
    scaled = parameter(SECTION).apply(case, scale)
    banded = band_case(scaled, bands, band_points) if bands else scaled
    reduce_links(banded)
    reduced = time.perf_counter()
    problem = _Problem(LinearMount.prepare(banded), fast, rules, load_mounts=_load_mounts(scaled, rules))
    return problem, {"scale": scale, "reductions": len(link_jobs(banded)), "reduction_seconds": reduced - begin,
                     "preparation_seconds": time.perf_counter() - begin}


def _trial(problem: _Problem, kind: str, weights: np.ndarray, positions: list, maxiter: int,
           pool: ProcessPoolExecutor | None, **cost) -> _Trial:
    """Every start on *problem* (in *pool*'s processes when there is one); *cost*: the preparation's
    (:class:`_Trial`'s fields)."""
    from concurrent.futures.process import BrokenProcessPool

    begin = time.perf_counter()
    if pool is None or len(positions) <= 1:
        outcomes = [_start(problem, kind, weights, x0, k, maxiter) for k, x0 in enumerate(positions)]
    else:
        futures = [pool.submit(_start, problem, kind, weights, x0, k, maxiter) for k, x0 in enumerate(positions)]
        try:
            outcomes = [future.result() for future in futures]
        except BrokenProcessPool:
            raise SimulationError("a worker process running an optimisation start died (killed, or out of "
                                  "memory); run with one worker to see the start's own error") from None
        problem.evaluations += sum(count for _, _, count in outcomes)
    return _Trial(problem, [end for end, _, _ in outcomes], [row for _, rows, _ in outcomes for row in rows],
                  time.perf_counter() - begin, **cost)


def _start(problem: _Problem, kind: str, weights: np.ndarray, x0: np.ndarray, start: int,
           maxiter: int) -> tuple[dict, list, int]:
    """One start, in this process or a worker's: its end (x included), its history rows and the designs it
    answered. BLAS runs single-threaded, so that a start gives the same digits wherever it runs."""
    from threadpoolctl import threadpool_limits

    history: list = []
    counted = problem.evaluations
    with threadpool_limits(limits=1):
        try:
            if len(x0):
                x, message, iterations = _run_start(problem, kind, weights, x0, start, history, maxiter)
            else:
                x, message, iterations = x0, "no fast variable: the design answered", 0
            point = problem.point(x)
        except SimulationError as error:
            return ({"start": start, "objective": np.nan, "violation": np.inf, "iterations": 0,
                     "message": str(error)}, history, problem.evaluations - counted)
    end = {"start": start, "x": x, "objective": _objective_value(kind, weights, point),
           "violation": problem.violation(point), "iterations": iterations, "message": message}
    if not history:
        history.append({"start": start, "iteration": 0, "objective": end["objective"], "violation": end["violation"]})
    return end, history, problem.evaluations - counted


def _start_worker() -> None:
    """Set up a worker process of the starts: Ctrl-C is the parent's to handle, and it ends with its parent."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    end_with_parent()


@contextlib.contextmanager
def _start_pool(workers: int, starts: int):
    """Worker processes for the starts (None: one worker or one start); stopped on an interrupt."""
    if workers <= 1 or starts <= 1:
        yield None
        return
    before = set(multiprocessing.active_children())
    pool = ProcessPoolExecutor(max_workers=min(workers, starts), mp_context=multiprocessing.get_context("spawn"),
                               initializer=_start_worker)
    try:
        yield pool
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        stop_workers(set(multiprocessing.active_children()) - before)
        raise
    pool.shutdown(wait=True)


def _raise_infeasible(problem: _Problem, x0: np.ndarray, held: list | None = None):
    closest = problem.point(_least_violation(problem, x0) if len(x0) else x0)
    violated = [f"{label}: {value:.4g} against {limit}"
                for (label, value, limit), slack in zip(closest.measures, closest.g, strict=True) if slack < -FEASIBLE]
    held = [f"{v.name} at its {'low' if x <= ACTIVE else 'high'} end {v.value(float(round(x))):g}"
            for v, x in zip(problem.variables, closest.x, strict=True) if x <= ACTIVE or x >= 1 - ACTIVE] + (held or [])
    raise InfeasibleProblem(violated or [f"{label}: {value:.4g} against {limit}" for label, value, limit
                                         in closest.measures], held)


def _pareto_measure(name: str, point: _Point) -> float:
    """One front objective of an evaluated design: ``worst`` or ``worst/ITEM`` (T, dB, a band's peaks
    included), or a displacement quantity."""
    if name.partition("/")[0] == "worst":
        item = name.partition("/")[2]
        t = point.t[[not item or row == item for row in point.rows]]
        return float(20 * np.log10(max(np.max(t), 1e-12)))
    rule = Constraint(name, 1.0)
    values = []
    for static in point.answer.engine_static.values():
        vector = static[3:6] if rule.quantity == "rotation" else static[:3]
        values.append(-vector[2] if rule.quantity == "sag" else float(np.linalg.norm(vector)))
    return max(values)


def pareto(case: Case, variables: dict, objectives: tuple = ("worst", "displacement"), constraints=(),
           population: int = 50, generations: int = 20, seed: int = 0, mount: LinearMount | None = None) -> ParetoFront:
    """The front of two objectives by NSGA-II (pymoo) on the fast path.

    Parameters
    ----------
    objectives : (str, str)
        Each ``worst`` (worst T over runs and directions, dB), ``worst/EXCITATION`` (of one excitation item, a band's peaks included), or one of
        :data:`QUANTITIES` (the largest over the excitation items).
    constraints
        As :func:`optimise`; ``modes_outside`` ones cost a modal solve each.
    population, generations : int

    Returns
    -------
    ParetoFront

    Raises
    ------
    InputError
        An unknown objective.
    """
    import pandas as pd
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.problem import ElementwiseProblem
    from pymoo.optimize import minimize

    begin = time.perf_counter()
    runs = [e.name for e in case.excitations]
    known = ["worst", *(f"worst/{run}" for run in runs), *QUANTITIES]
    for name in objectives:
        if name not in known:
            raise InputError(f"Pareto objective {name!r}: expected one of {', '.join(known)}")
    chosen = [variable(name, *bounds) for name, bounds in variables.items()]
    if any(v.name == SECTION for v in chosen):
        raise InputError(_FRONT_FAST_ONLY)
    rules = [rule if isinstance(rule, Constraint) else constraint(rule) for rule in constraints]
    mount = mount or LinearMount.prepare(case)
    problem = _Problem(mount, chosen, rules, derivatives=False, load_mounts=_load_mounts(case, rules))

    rows = len(problem.point(np.full(len(chosen), 0.5)).g)     # constraint rows (a fatigue rule: one per link)

    class Front(ElementwiseProblem):
        def __init__(self):
            super().__init__(n_var=len(chosen), n_obj=2, n_ieq_constr=rows, xl=0.0, xu=1.0)

        def _evaluate(self, x, out, *args, **kwargs):
            point = problem.point(x)
            out["F"] = [_pareto_measure(name, point) for name in objectives]
            if rows:
                out["G"] = -point.g

    answer = minimize(Front(), NSGA2(pop_size=population), ("n_gen", generations), seed=seed, verbose=False)
    designs = np.atleast_2d(answer.X) if answer.X is not None else np.zeros((0, len(chosen)))
    table = pd.DataFrame([problem.values(x) for x in designs], columns=[v.name for v in chosen])
    values = np.atleast_2d(answer.F) if answer.F is not None else np.zeros((0, 2))
    for k, name in enumerate(objectives):
        table[name] = values[:, k]
    return ParetoFront(tuple(objectives), table, problem.evaluations, time.perf_counter() - begin)
