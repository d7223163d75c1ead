"""Model updating: the parameter values that make the simulated T agree with rig records.

Each record gives the measured T per direction of its run
(:func:`workbook.rig.correlation.measure`). The parameters (names of
:func:`workbook.studies.parametric.parameter`: hinge stiffness, damping or
loss factor per hinge group and direction, transducer stiffness, engine
mass, a flexible casing's modulus) are fitted by weighted least squares on the fast linear model
(:class:`~workbook.design.linear_mount.LinearMount`), with its analytic
derivatives (:func:`~workbook.design.sensitivity.design_sensitivity`)::

    r_i = ln(T_sim,i(p) / T_test,i) / sigma_i     (i: record and direction)

the relative error (an amplitude ratio, without phase), weighted by each
record's :class:`Uncertainty` ``sigma_i`` (the standard deviation of its
ln T: a relative one as it is, an absolute one of T divided by T_test), or
unweighted (``sigma_i = 1``) when no record states one. A parameter with
positive bounds is fitted on a log scale, ``x = ln p``; others as they are.
scipy's trust-region reflective solver keeps them within their bounds. At
the solution, with m data and n parameters::

    s^2 = |r|^2 / (m - n),
    cov_x = (J^T J)^-1          (uncertainties stated: from the weights),
    cov_x = s^2 (J^T J)^-1      (none stated: from the residual).

With stated uncertainties, s^2 is the reduced chi-square: a value beyond
the :data:`CHI_SQUARE_LEVEL` quantile of its distribution is warned of (the
records scatter more than their uncertainties say, or the model misses). T of a mount isolating by a cancellation of
its pylon forces is far from linear in the parameters, and the error has
local minima: the fit first screens :data:`SCREENING` designs of a Latin
hypercube over the (log) bounds, by their error alone, then starts the
solver from the case's values and from the :data:`STARTS` - 1 best designs
screened, :data:`PRUNING` evaluations each, and goes on from the best of
them to convergence. The standard error of p is ``p sd(x)`` on a
log scale. A parameter is not determined by the data when the condition
number of the column-scaled ``J^T J`` exceeds :data:`CONDITION_LIMIT`, or its
correlation with another exceeds :data:`CORRELATION_LIMIT` in magnitude: a
warning names it.
"""
from __future__ import annotations

import logging
import re
import time
from dataclasses import dataclass

import numpy as np

from workbook.errors import UsageError
from workbook.model.case import DIRECTIONS, Case

__all__ = ["UpdateResult", "Uncertainty", "update_model", "update_to_transmissibility", "CONDITION_LIMIT",
           "CORRELATION_LIMIT", "SCREENING", "STARTS", "PRUNING", "CHI_SQUARE_LEVEL"]

log = logging.getLogger(__name__)

#: Largest condition number of the column-scaled J^T J of determined parameters.
CONDITION_LIMIT = 1e6
#: Largest magnitude of the correlation of two determined parameters.
CORRELATION_LIMIT = 0.999
#: Designs screened for starting points.
SCREENING = 64
#: Starts of the solver: the case's values and the best designs screened.
STARTS = 2
#: Model evaluations of each start before only the best one goes on.
PRUNING = 8
#: Quantile of chi-square above which the residual of weighted data is warned of.
CHI_SQUARE_LEVEL = 0.999


@dataclass(frozen=True)
class Uncertainty:
    """The measurement uncertainty of a record's T: one standard deviation.

    Attributes
    ----------
    value : float
        Relative (a fraction of T) or absolute (of T itself, dimensionless).
    relative : bool
    """

    value: float
    relative: bool = True

    def __post_init__(self):
        if not (np.isfinite(self.value) and self.value > 0):
            raise UsageError(f"a measurement uncertainty must be positive, got {self.value!r}")

    @classmethod
    def parse(cls, text: str) -> "Uncertainty":
        """``"2%"`` (relative) or ``"0.001"`` (absolute, of T).

        Raises
        ------
        UsageError
            Neither, naming the text.
        """
        match = re.fullmatch(r"\s*([0-9.]+(?:[eE][-+]?[0-9]+)?)\s*(%?)\s*", text)
        try:
            value = float(match.group(1)) if match else float("nan")
        except ValueError:
            value = float("nan")
        if not value > 0:
            raise UsageError(f"measurement uncertainty {text!r}: expected a relative one as a percentage "
                             "(2%) or an absolute one of T (0.001), positive")
        return cls(value / 100 if match and match.group(2) else value, bool(match and match.group(2)))

    def of_log(self, measured: np.ndarray) -> np.ndarray:
        """The standard deviation of ln T of the measured T *measured*."""
        return np.full(np.shape(measured), self.value) if self.relative else self.value / np.asarray(measured)


@dataclass(frozen=True)
class UpdateResult:
    """The fitted parameters and the model's error before and after.

    Attributes
    ----------
    case : Case
        The case with the fitted values.
    parameters : list of str
    bounds : ndarray, shape (n, 2)
        SI units.
    initial, values, standard_errors : ndarray, shape (n,)
        The case's values, the fitted ones and their standard errors, SI units.
    correlation : ndarray, shape (n, n)
    condition : float
        Condition number of the column-scaled ``J^T J``.
    records : list of str
        Each record's file (or run, for a record made in memory).
    runs : list of str
        Each record's run.
    measured, before, after : ndarray, shape (records, 3)
        T per direction: measured, simulated with the initial and with the fitted values.
    residual_std : float
        s at the solution: the standard deviation of the relative residual
        (unweighted), or the square root of the reduced chi-square (weighted).
    warnings : list of str
    evaluations : int
        Model evaluations with derivatives (the screening's without not counted).
    seconds : float
        Wall time of the fit (without the model's preparation), s.
    uncertainty : ndarray, shape (records, 3), optional
        The standard deviation of each measured ln T (the weights' inverse);
        None: unweighted, the standard errors from the residual.
    """

    case: Case
    parameters: list
    bounds: np.ndarray
    initial: np.ndarray
    values: np.ndarray
    standard_errors: np.ndarray
    correlation: np.ndarray
    condition: float
    records: list
    runs: list
    measured: np.ndarray
    before: np.ndarray
    after: np.ndarray
    residual_std: float
    warnings: list
    evaluations: int
    seconds: float
    uncertainty: np.ndarray | None = None

    def to_pandas(self):
        """The fitted values: one row per parameter (initial, fitted, standard error, bounds)."""
        import pandas as pd

        return pd.DataFrame({"initial": self.initial, "fitted": self.values, "standard error": self.standard_errors,
                             "standard error %": 100 * self.standard_errors / np.abs(self.values),
                             "low": self.bounds[:, 0], "high": self.bounds[:, 1]},
                            index=pd.Index(self.parameters, name="parameter"))

    def error_frame(self):
        """The before/after table: T measured, and the error (sim - test) / test x 100 % before and after,
        one row per record and direction (with the records' stated uncertainty, %, where weighted)."""
        import pandas as pd

        index = pd.MultiIndex.from_product([self.runs, DIRECTIONS], names=["run", "direction"])
        columns = {"T test": self.measured.ravel()}
        if self.uncertainty is not None:
            columns["sigma %"] = 100 * self.uncertainty.ravel()
        columns.update({"error before %": 100 * (self.before / self.measured - 1).ravel(),
                        "error after %": 100 * (self.after / self.measured - 1).ravel()})
        return pd.DataFrame(columns, index=index)

    def to_dict(self) -> dict:
        """The fit as plain data (for ``--json``)."""
        errors = self.error_frame()
        return {
            "parameters": {name: {"initial": float(a), "fitted": float(v), "standard error": float(e),
                                  "low": float(b[0]), "high": float(b[1])}
                           for name, a, v, e, b in zip(self.parameters, self.initial, self.values,
                                                       self.standard_errors, self.bounds, strict=True)},
            "correlation": self.correlation.tolist(), "condition": self.condition,
            "residual std": self.residual_std, "weighted": self.uncertainty is not None,
            "errors %": [{"run": run, "direction": d, "T test": float(row["T test"]),
                          "before": float(row["error before %"]), "after": float(row["error after %"])}
                         for (run, d), row in errors.iterrows()],
            "warnings": list(self.warnings), "evaluations": self.evaluations, "seconds": self.seconds}

    def plot(self):
        """Measured against simulated T, before and after, per record and direction; and the correlation matrix.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        figure, (bars, matrix) = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [2, 1]})
        labels = [f"{run}\n{d}" for run in self.runs for d in DIRECTIONS]
        position = np.arange(len(labels))
        for offset, (name, values) in zip((-0.27, 0.0, 0.27), (("test", self.measured), ("before", self.before),
                                                                ("after", self.after)), strict=True):
            bars.bar(position + offset, values.ravel(), width=0.27, label=name)
        bars.set_yscale("log")
        bars.set_xticks(position, labels, fontsize=7)
        bars.set_ylabel("T")
        bars.legend()
        image = matrix.imshow(self.correlation, vmin=-1, vmax=1, cmap="RdBu_r")
        ticks = np.arange(len(self.parameters))
        matrix.set_xticks(ticks, self.parameters, rotation=60, ha="right", fontsize=7)
        matrix.set_yticks(ticks, self.parameters, fontsize=7)
        matrix.set_title("correlation")
        figure.colorbar(image, ax=matrix)
        figure.tight_layout()
        return figure


def update_model(case: Case, records, variables: dict, *, uncertainty=None, periods: int | None = None,
                 mount=None, max_evaluations: int = 30, screening: int = SCREENING, starts: int = STARTS,
                 seed: int = 0) -> UpdateResult:
    """Fit the parameters *variables* of *case* to the measured T of *records*.

    Parameters
    ----------
    case : Case
        The model; its values of the parameters start the fit.
    records : sequence of RigRecord
        Records of runs (excitations) of *case*, several per run allowed.
    variables : dict of str to (float, float)
        Parameter name to its bounds (low, high), SI units.
    uncertainty : sequence of Uncertainty, optional
        Each record's measurement uncertainty (the weights); default: none
        stated, the fit unweighted.
    periods : int, optional
        Whole rotor periods per measured window (default: the case's).
    mount, max_evaluations, screening, starts, seed
        As :func:`update_to_transmissibility`.

    Returns
    -------
    UpdateResult

    Raises
    ------
    UsageError
        As :func:`update_to_transmissibility`, or a record of another run.
    RecordError
        A record that cannot be measured or whose transducers do not carry the case's pylon-side hinges.
    OutsideDesignModel
        A case the linear model does not answer (a flexible pylon, a casing modulus within the bounds that
        changes the casing's modes, ...).
    """
    from workbook.rig.correlation import measure

    runs = [e.name for e in case.single_frequency_excitations()]
    for record in records:
        if record.run not in runs:
            raise UsageError(f"record {record.path or record.run!r} is of run {record.run!r}; case {case.name!r} "
                             f"has runs {', '.join(runs)}")
        record.check_hinges([h.name for h in case.pylon_hinges])
    window = case.analysis.measured_periods if periods is None else periods
    measured = np.array([measure(record, window).transmissibility for record in records])
    return update_to_transmissibility(case, [record.run for record in records], measured, variables,
                                      uncertainty=uncertainty, labels=[record.path or record.run for record in records],
                                      mount=mount, max_evaluations=max_evaluations, screening=screening,
                                      starts=starts, seed=seed)


def update_to_transmissibility(case: Case, runs: list, measured: np.ndarray, variables: dict, *,
                               uncertainty=None, labels: list | None = None, mount=None, max_evaluations: int = 30,
                               screening: int = SCREENING, starts: int = STARTS, seed: int = 0) -> UpdateResult:
    """Fit the parameters *variables* of *case* to measured T per run and direction.

    Parameters
    ----------
    case : Case
        The model; its values of the parameters start the fit.
    runs : list of str
        The run of each measurement (several per run allowed).
    measured : array_like, shape (len(runs), 3)
        Measured T per direction.
    variables : dict of str to (float, float)
        Parameter name to its bounds (low, high), SI units.
    uncertainty : sequence of Uncertainty, optional
        Each measurement's uncertainty (the weights); default: unweighted.
    labels : list of str, optional
        Each measurement's name in the result (default: its run).
    mount : LinearMount, optional
        *case* prepared (default: prepared here).
    max_evaluations : int
        Most model evaluations of one start of the solver.
    screening : int
        Designs screened for starting points.
    starts : int
        Starts of the solver (the case's values and the best ``starts - 1`` designs screened).
    seed : int
        Seed of the screening's Latin hypercube.

    Returns
    -------
    UpdateResult

    Raises
    ------
    UsageError
        An unknown parameter or one without a single value in *case*, bounds
        not around that value, a run the case lacks, an uncertainty for some
        measurements only, or no more data than parameters.
    OutsideDesignModel
        A case the linear model does not answer.
    """
    from scipy.optimize import least_squares

    from workbook.design.linear_mount import LinearMount
    from workbook.design.sensitivity import design_case, design_sensitivity
    from workbook.errors import InputError
    from workbook.studies.parametric import latin_hypercube, parameter_value

    names = list(variables)
    try:
        initial = np.array([parameter_value(case, name) for name in names])
    except InputError as error:
        raise UsageError(f"model updating: {error}") from None
    bounds = np.array([variables[name] for name in names], dtype=float).reshape(-1, 2)
    for name, value, (low, high) in zip(names, initial, bounds, strict=True):
        if not low <= value <= high or not low < high:
            raise UsageError(f"model updating: bounds {low:g} to {high:g} of {name!r} do not hold its value "
                             f"{value:g} in case {case.name!r}")
    case_runs = [e.name for e in case.single_frequency_excitations()]
    unknown = sorted(set(runs) - set(case_runs))
    if unknown:
        raise UsageError(f"run(s) {', '.join(unknown)} not in case {case.name!r}; it has {', '.join(case_runs)}")
    measured = np.asarray(measured, dtype=float).reshape(len(runs), 3)
    labels = list(runs) if labels is None else list(labels)
    unusable = [f"{labels[i]} T {DIRECTIONS[d]} = {measured[i, d]:g}"
                for i, d in zip(*np.nonzero(~(measured > 0) | ~np.isfinite(measured)), strict=True)]
    if unusable:
        raise UsageError(f"model updating: measured {', '.join(unusable)}: the fit compares ln T, so every "
                         "measured T must be finite and above 0 (a direction whose pylon channels carry no force at "
                         "the rotor frequency cannot be fitted: check those transducers)")
    if 3 * len(runs) <= len(names):
        raise UsageError(f"{len(runs)} record(s) give {3 * len(runs)} values of T for {len(names)} "
                         "parameters: the fit needs more values than parameters (more records, or fewer --vary)")
    sigma = _log_uncertainty(uncertainty, measured, labels)
    weights = np.ones_like(measured) if sigma is None else 1.0 / sigma
    mount = LinearMount.prepare(case) if mount is None else mount
    start = time.perf_counter()
    log_scale = bounds[:, 0] > 0
    rows = [case_runs.index(run) for run in runs]
    answers: dict = {}
    counter = {"evaluations": 0}

    def values_of(x: np.ndarray) -> np.ndarray:
        return np.where(log_scale, np.exp(x), x)

    def answer(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """T per measurement of the design x and d r / d x (one solve gives both: the solver accepts
        nearly every step, so computing the derivatives at a rejected one costs less than a second solve
        of an accepted one)."""
        key = x.tobytes()
        if key not in answers:
            counter["evaluations"] += 1
            sensitivity = design_sensitivity(mount, dict(zip(names, values_of(x), strict=True)))
            by_run = [sensitivity.runs.index(run) for run in case_runs]
            t = sensitivity.transmissibility[by_run][rows]
            gradient = sensitivity.gradient[by_run][rows] * np.where(log_scale, values_of(x), 1.0)
            answers[key] = (t, ((gradient / t[..., None]) * weights[..., None]).reshape(-1, len(names)))
        return answers[key]

    def simulated(x: np.ndarray) -> np.ndarray:
        return answer(x)[0]

    def jacobian(x: np.ndarray) -> np.ndarray:
        return answer(x)[1]

    def residual(x: np.ndarray) -> np.ndarray:
        return (np.log(simulated(x) / measured) * weights).ravel()

    def to_x(values: np.ndarray) -> np.ndarray:
        return np.where(log_scale, np.log(np.where(log_scale, values, 1.0)), values)

    x0, lower, upper = to_x(initial), to_x(bounds[:, 0]), to_x(bounds[:, 1])
    before = simulated(x0)
    screened = latin_hypercube(dict(zip(names, zip(lower, upper, strict=True), strict=True)), screening, seed) \
        if screening and starts > 1 else ()
    errors = [_screened_error(mount, dict(zip(names, values_of(np.array(list(row.values()))), strict=True)),
                              case_runs, rows, measured, weights) for row in screened]
    candidates = [x0] + [np.array(list(screened[i].values())) for i in np.argsort(errors)[:starts - 1]]

    def solve(x: np.ndarray, evaluations: int):
        return least_squares(residual, x, jac=jacobian, bounds=(lower, upper), method="trf", x_scale="jac",
                             max_nfev=evaluations)

    if len(candidates) > 1:      # every start a few steps, then the best one on to convergence
        candidates = [min((solve(x, PRUNING) for x in candidates), key=lambda f: f.cost).x]
    fit = solve(candidates[0], max_evaluations)
    after, r, jac = simulated(fit.x), residual(fit.x), jacobian(fit.x)
    values = values_of(fit.x)
    dof = r.size - len(names)
    variance = float(r @ r) / dof
    scale = np.linalg.norm(jac, axis=0)
    scale[scale == 0] = 1.0
    scaled = jac / scale
    normal = scaled.T @ scaled
    condition = float(np.linalg.cond(normal))
    covariance = (1.0 if sigma is not None else variance) * np.linalg.pinv(normal, rcond=1e-13) \
        / np.outer(scale, scale)
    sd = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    correlation = covariance / np.outer(np.where(sd > 0, sd, 1.0), np.where(sd > 0, sd, 1.0))
    standard_errors = np.where(log_scale, values * sd, sd)
    warnings = _determination_warnings(names, condition, correlation, np.linalg.norm(jac, axis=0))
    if sigma is not None:
        warnings += _chi_square_warnings(variance, dof)
    if not fit.success:
        warnings.append(f"the fit stopped after {fit.nfev} evaluations: {fit.message}")
    for name, (low, high), value in zip(names, bounds, values, strict=True):
        if np.isclose(value, low, rtol=1e-6) or np.isclose(value, high, rtol=1e-6):
            warnings.append(f"{name} ended on a bound ({value:g}): its standard error is not meaningful; "
                            "widen the bounds or check the model")
    for warning in warnings:
        log.warning("model updating: %s", warning)
    updated = design_case(mount, dict(zip(names, values, strict=True)))
    return UpdateResult(updated, names, bounds, initial, values, standard_errors, correlation, condition,
                        labels, list(runs), measured, before, after, float(np.sqrt(variance)), warnings,
                        counter["evaluations"], time.perf_counter() - start, sigma)


def _log_uncertainty(uncertainty, measured: np.ndarray, labels: list) -> np.ndarray | None:
    """The standard deviation of each measured ln T (records, 3), or None when none is stated.

    Raises
    ------
    UsageError
        Uncertainties for some measurements only.
    """
    if uncertainty is None or all(u is None for u in uncertainty):
        return None
    uncertainty = list(uncertainty)
    missing = [label for label, u in zip(labels, uncertainty, strict=False) if u is None] \
        + labels[len(uncertainty):]
    if missing or len(uncertainty) != len(labels):
        raise UsageError(f"a measurement uncertainty for every record or none: {', '.join(missing) or 'extra ones'} "
                         f"{'has none' if missing else 'given'} ({len(uncertainty)} for {len(labels)} records)")
    return np.array([u.of_log(t) for u, t in zip(uncertainty, measured, strict=True)])


def _chi_square_warnings(variance: float, dof: int) -> list:
    """A warning when the reduced chi-square *variance* of *dof* degrees of freedom is improbably large."""
    from scipy.stats import chi2

    limit = float(chi2.ppf(CHI_SQUARE_LEVEL, dof)) / dof
    if variance <= limit:
        return []
    return [f"the records scatter about the fit more than their uncertainties say: reduced chi-square "
            f"{variance:.3g} (above {limit:.3g}, its {100 * CHI_SQUARE_LEVEL:g} % quantile); the standard errors, "
            "taken from the uncertainties, are too small by about a factor "
            f"{np.sqrt(variance):.2g} unless the model is at fault"]


def _screened_error(mount, values: dict, runs: list, rows: list, measured: np.ndarray, weights: np.ndarray) -> float:
    """The sum of squared weighted log errors of T of the design *values* (inf where it cannot be answered)."""
    from workbook.design.sensitivity import design_case
    from workbook.errors import SimulationError

    try:
        answer = mount.evaluate(design_case(mount, values)).result
    except SimulationError:      # an unstable preload or a resonance within the bounds
        return float("inf")
    by_name = {run.name: run.transmissibility for run in answer.runs}
    simulated = np.array([by_name[runs[row]] for row in rows])
    return float(np.sum((np.log(simulated / measured) * weights) ** 2))


def _determination_warnings(names: list, condition: float, correlation: np.ndarray, influence: np.ndarray) -> list:
    """Warnings naming the parameters the data do not determine."""
    warnings = [f"{name} does not change T at all: the data do not determine it"
                for name, size in zip(names, influence, strict=True) if size == 0]
    pairs = [(names[i], names[j], correlation[i, j]) for i in range(len(names)) for j in range(i + 1, len(names))
             if abs(correlation[i, j]) > CORRELATION_LIMIT]
    warnings += [f"{a} and {b} are not determined apart: their correlation is {rho:+.3f}; the data fix a "
                 "combination of them only (vary one of them)" for a, b, rho in pairs]
    if condition > CONDITION_LIMIT:
        warnings.append(f"the data do not determine every parameter: J^T J has condition number {condition:.2g} "
                        f"(more than {CONDITION_LIMIT:g})")
    return warnings
