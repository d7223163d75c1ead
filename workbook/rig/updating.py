"""Model updating: the parameter values that make the simulated T agree with rig records.

Each record gives the measured T per direction of its run
(:func:`workbook.rig.correlation.measure`). The parameters (names of
:func:`workbook.studies.parametric.parameter`: hinge stiffness, damping or
loss factor per hinge group and direction, transducer stiffness, engine
mass) are fitted by weighted least squares on the fast linear model
(:class:`~workbook.design.linear_mount.LinearMount`), with its analytic
derivatives (:func:`~workbook.design.sensitivity.design_sensitivity`)::

    r_i = (T_sim,i(p) - T_test,i) / T_test,i     (i: record and direction)

the relative error, as the rig's T carries no uncertainty of its own (an
amplitude ratio, without phase). A parameter with positive bounds is fitted
on a log scale, ``x = ln p``; others as they are. scipy's trust-region
reflective solver keeps them within their bounds. At the solution::

    s^2 = |r|^2 / (m - n),   cov_x = s^2 (J^T J)^-1,

with m data and n parameters. T of a mount isolating by a cancellation of
its pylon forces is far from linear in the parameters, and the error has
local minima: the fit first screens :data:`SCREENING` designs of a Latin
hypercube over the (log) bounds, by their error alone, and then starts
the solver from the case's values and from the :data:`STARTS` - 1 best
designs screened, keeping the best solution. The standard error of p is ``p sd(x)`` on a
log scale. A parameter is not determined by the data when the condition
number of the column-scaled ``J^T J`` exceeds :data:`CONDITION_LIMIT`, or its
correlation with another exceeds :data:`CORRELATION_LIMIT` in magnitude: a
warning names it. The casing's modulus is not a parameter: the linear model
refuses a flexible engine casing.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from workbook.errors import UsageError
from workbook.model.case import DIRECTIONS, Case

__all__ = ["UpdateResult", "update_model", "CONDITION_LIMIT", "CORRELATION_LIMIT", "SCREENING", "STARTS"]

log = logging.getLogger(__name__)

#: Largest condition number of the column-scaled J^T J of determined parameters.
CONDITION_LIMIT = 1e6
#: Largest magnitude of the correlation of two determined parameters.
CORRELATION_LIMIT = 0.999
#: Designs screened for starting points.
SCREENING = 64
#: Starts of the solver: the case's values and the best designs screened.
STARTS = 2


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
        s, the standard deviation of the relative residual at the solution.
    warnings : list of str
    evaluations : int
        Model evaluations with derivatives (the screening's without not counted).
    seconds : float
        Wall time of the fit (without the model's preparation), s.
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

    def to_pandas(self):
        """The fitted values: one row per parameter (initial, fitted, standard error, bounds)."""
        import pandas as pd

        return pd.DataFrame({"initial": self.initial, "fitted": self.values, "standard error": self.standard_errors,
                             "standard error %": 100 * self.standard_errors / np.abs(self.values),
                             "low": self.bounds[:, 0], "high": self.bounds[:, 1]},
                            index=pd.Index(self.parameters, name="parameter"))

    def error_frame(self):
        """The before/after table: T measured, and the error (sim - test) / test x 100 % before and after,
        one row per record and direction."""
        import pandas as pd

        index = pd.MultiIndex.from_product([self.runs, DIRECTIONS], names=["run", "direction"])
        return pd.DataFrame({"T test": self.measured.ravel(),
                             "error before %": 100 * (self.before / self.measured - 1).ravel(),
                             "error after %": 100 * (self.after / self.measured - 1).ravel()}, index=index)

    def to_dict(self) -> dict:
        """The fit as plain data (for ``--json``)."""
        errors = self.error_frame()
        return {
            "parameters": {name: {"initial": float(a), "fitted": float(v), "standard error": float(e),
                                  "low": float(b[0]), "high": float(b[1])}
                           for name, a, v, e, b in zip(self.parameters, self.initial, self.values,
                                                       self.standard_errors, self.bounds, strict=True)},
            "correlation": self.correlation.tolist(), "condition": self.condition,
            "residual std": self.residual_std,
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


def update_model(case: Case, records, variables: dict, *, periods: int | None = None, mount=None,
                 max_evaluations: int = 30, screening: int = SCREENING, starts: int = STARTS,
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
    periods : int, optional
        Whole rotor periods per measured window (default: the case's).
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
        not around that value, a record of another run, or no more data than
        parameters.
    RecordError
        A record that cannot be measured or whose transducers do not carry the case's pylon-side hinges.
    OutsideDesignModel
        A case the linear model does not answer (a flexible casing, a flexible pylon, ...).
    """
    from scipy.optimize import least_squares

    from workbook.design.linear_mount import LinearMount
    from workbook.design.sensitivity import design_case, design_sensitivity
    from workbook.errors import InputError
    from workbook.rig.correlation import measure
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
    runs = [e.name for e in case.single_frequency_excitations()]
    for record in records:
        if record.run not in runs:
            raise UsageError(f"record {record.path or record.run!r} is of run {record.run!r}; case {case.name!r} "
                             f"has runs {', '.join(runs)}")
        record.check_hinges([h.name for h in case.pylon_hinges])
    if 3 * len(records) <= len(names):
        raise UsageError(f"{len(records)} record(s) give {3 * len(records)} values of T for {len(names)} "
                         "parameters: the fit needs more values than parameters (more records, or fewer --vary)")
    window = case.analysis.measured_periods if periods is None else periods
    measured = np.array([measure(record, window).transmissibility for record in records])
    mount = LinearMount.prepare(case) if mount is None else mount
    start = time.perf_counter()
    log_scale = bounds[:, 0] > 0
    rows = [runs.index(record.run) for record in records]
    answers: dict = {}

    def values_of(x: np.ndarray) -> np.ndarray:
        return np.where(log_scale, np.exp(x), x)

    def answer(x: np.ndarray):
        key = x.tobytes()
        if key not in answers:
            answers.clear()
            sensitivity = design_sensitivity(mount, dict(zip(names, values_of(x), strict=True)))
            by_run = [sensitivity.runs.index(run) for run in runs]
            t = sensitivity.transmissibility[by_run][rows]
            jacobian = sensitivity.gradient[by_run][rows] * np.where(log_scale, values_of(x), 1.0)
            answers[key] = (t, np.log(t / measured).ravel(), (jacobian / t[..., None]).reshape(-1, len(names)))
        return answers[key]

    counter = {"evaluations": 0}

    def residual(x):
        counter["evaluations"] += 1
        return answer(x)[1]

    def to_x(values: np.ndarray) -> np.ndarray:
        return np.where(log_scale, np.log(np.where(log_scale, values, 1.0)), values)

    x0, lower, upper = to_x(initial), to_x(bounds[:, 0]), to_x(bounds[:, 1])
    before = answer(x0)[0]
    screened = latin_hypercube(dict(zip(names, zip(lower, upper, strict=True), strict=True)), screening, seed) \
        if screening and starts > 1 else ()
    errors = [_screened_error(mount, dict(zip(names, values_of(np.array(list(row.values()))), strict=True)),
                              runs, rows, measured) for row in screened]
    candidates = [x0] + [np.array(list(screened[i].values())) for i in np.argsort(errors)[:starts - 1]]
    fits = [least_squares(residual, x, jac=lambda x: answer(x)[2], bounds=(lower, upper), method="trf",
                          x_scale="jac", max_nfev=max_evaluations) for x in candidates]
    fit = min(fits, key=lambda f: f.cost)
    after, r, jacobian = answer(fit.x)
    values = values_of(fit.x)
    dof = r.size - len(names)
    variance = float(r @ r) / dof
    scale = np.linalg.norm(jacobian, axis=0)
    scale[scale == 0] = 1.0
    scaled = jacobian / scale
    normal = scaled.T @ scaled
    condition = float(np.linalg.cond(normal))
    covariance = variance * np.linalg.pinv(normal, rcond=1e-13) / np.outer(scale, scale)
    sd = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    correlation = covariance / np.outer(np.where(sd > 0, sd, 1.0), np.where(sd > 0, sd, 1.0))
    standard_errors = np.where(log_scale, values * sd, sd)
    warnings = _determination_warnings(names, condition, correlation, np.linalg.norm(jacobian, axis=0))
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
                        [record.path or record.run for record in records], [record.run for record in records],
                        measured, before, after, float(np.sqrt(variance)), warnings, counter["evaluations"],
                        time.perf_counter() - start)


def _screened_error(mount, values: dict, runs: list, rows: list, measured: np.ndarray) -> float:
    """The sum of squared relative errors of T of the design *values* (inf where it cannot be answered)."""
    from workbook.design.sensitivity import design_case
    from workbook.errors import SimulationError

    try:
        answer = mount.evaluate(design_case(mount, values)).result
    except SimulationError:      # an unstable preload or a resonance within the bounds
        return float("inf")
    by_name = {run.name: run.transmissibility for run in answer.runs}
    simulated = np.array([by_name[runs[row]] for row in rows])
    return float(np.sum(np.log(simulated / measured) ** 2))


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
