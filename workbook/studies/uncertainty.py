"""Uncertainty of the transmissibility: Monte Carlo percentiles and Sobol' indices.

Each uncertain study parameter (:func:`workbook.studies.parametric.parameter`)
has a :class:`Distribution`:

==============================  ==================================================
text (:func:`parse_distribution`)  distribution
==============================  ==================================================
``normal:MEAN:STD``             normal, mean and standard deviation
``uniform:LOW:HIGH``            uniform between the bounds
``lognormal:MEDIAN:SIGMA``      log-normal: ln(value) is normal with mean
                                ln(MEDIAN) and standard deviation SIGMA (SIGMA 0.1:
                                about 10 % scatter)
``tol:NOMINAL:TOL[:K]``         from a tolerance NOMINAL ± TOL (TOL absolute, or
                                ``10%`` of NOMINAL) that holds K standard deviations
                                (default 3): normal, mean NOMINAL, std TOL / K
==============================  ==================================================

Values are in the parameter's SI unit. The samples are points of the unit
hypercube mapped through each distribution's inverse CDF
(:meth:`Distribution.ppf`), the parameters independent: for Monte Carlo
random points (``numpy.random.default_rng(seed)``); for the variance-based
(Sobol') analysis the points of SALib's Saltelli design
(``SALib.sample.sobol``: N base samples give N (d + 2) rows for d
parameters, N a power of two). Every sample is a study row run by
:func:`workbook.studies.parallel.run_rows` (the rows the base case's linear
mount follows in NumPy; local processes or a Dask cluster).

:class:`UncertaintyResult` holds the rows' table, the statistics of T and
η = (1 - T) x 100 % per run and direction (mean, standard deviation, P5,
P50, P95 over the rows that ran) and, for a Sobol' design, the first-order
and total indices of T with their 95 % confidence half-widths
(``SALib.analyze.sobol``, bootstrap). η is affine in T, so its indices are T's.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from workbook.errors import InputError
from workbook.model.case import DIRECTIONS, Case
from workbook.studies.parallel import SERIAL, RowOutcome, run_rows
from workbook.studies.parametric import _check_rows, parameter, study_cases

if TYPE_CHECKING:
    from workbook.design.linear_mount import LinearMount

__all__ = ["Distribution", "DISTRIBUTIONS", "parse_distribution", "sample_rows", "UncertaintyResult",
           "run_uncertainty", "PERCENTILES", "UQ_STEM", "CONFIDENCE"]

#: Distribution kinds and the text of each (:func:`parse_distribution`).
DISTRIBUTIONS = {"normal": "normal:MEAN:STD", "uniform": "uniform:LOW:HIGH", "lognormal": "lognormal:MEDIAN:SIGMA",
                 "tol": "tol:NOMINAL:TOL[:K] (TOL absolute or N% of NOMINAL, K sigma, default 3)"}
#: Percentiles given per run and quantity, %.
PERCENTILES = (5, 50, 95)
#: Confidence level of the Sobol' indices' intervals.
CONFIDENCE = 0.95
#: Name of an uncertainty study's files (``uncertainty.csv``, ``.xlsx``, ``.png``), before ``-2``... .
UQ_STEM = "uncertainty"
#: Sigma a tolerance holds when its text gives none.
TOLERANCE_SIGMA = 3.0
#: Quantities of a run the statistics are given for.
QUANTITIES = (*(f"T {d}" for d in DIRECTIONS), *(f"eta % {d}" for d in DIRECTIONS))


@dataclass(frozen=True)
class Distribution:
    """The distribution of one uncertain parameter (SI units).

    Attributes
    ----------
    kind : {"normal", "uniform", "lognormal"}
    a, b : float
        normal: mean, standard deviation; uniform: low, high bound;
        lognormal: median, standard deviation of ln(value).
    """

    kind: str
    a: float
    b: float

    def __post_init__(self):
        expected = {"normal": self.b > 0, "uniform": self.b > self.a, "lognormal": self.a > 0 and self.b > 0}
        if not expected.get(self.kind, False):
            raise InputError(f"distribution {self}: expected {', '.join(DISTRIBUTIONS.values())} with a positive "
                             f"STD or SIGMA, LOW < HIGH and a positive MEDIAN")

    def __str__(self) -> str:
        return f"{self.kind}:{self.a:g}:{self.b:g}"

    def ppf(self, u) -> np.ndarray:
        """The values at cumulative probabilities *u* (the inverse CDF; 0 and 1 are taken as 1e-12 from them)."""
        from scipy.stats import norm

        u = np.clip(np.asarray(u, dtype=float), 1e-12, 1 - 1e-12)
        if self.kind == "uniform":
            return self.a + u * (self.b - self.a)
        z = norm.ppf(u)
        return self.a + self.b * z if self.kind == "normal" else self.a * np.exp(self.b * z)


def parse_distribution(text: str) -> Distribution:
    """The distribution of a text of :data:`DISTRIBUTIONS` (``lognormal:2e7:0.1``, ``tol:2e7:10%:3``).

    Raises
    ------
    InputError
        An unknown kind, a wrong number of values or a value that is no number, naming the text.
    """
    kind, *values = [part.strip() for part in text.split(":")]
    counts = {"normal": (2,), "uniform": (2,), "lognormal": (2,), "tol": (2, 3)}
    if kind not in counts or len(values) not in counts[kind]:
        raise InputError(f"distribution {text!r}: expected one of {'; '.join(DISTRIBUTIONS.values())}")
    try:
        if kind != "tol":
            return Distribution(kind, float(values[0]), float(values[1]))
        nominal = float(values[0])
        tolerance = float(values[1][:-1]) / 100 * abs(nominal) if values[1].endswith("%") else float(values[1])
        sigma = float(values[2]) if len(values) == 3 else TOLERANCE_SIGMA
    except ValueError:
        raise InputError(f"distribution {text!r}: expected numbers in {DISTRIBUTIONS[kind]}") from None
    if not (tolerance > 0 and sigma > 0):
        raise InputError(f"distribution {text!r}: expected a positive tolerance and K")
    return Distribution("normal", nominal, tolerance / sigma)


def _problem(names: list[str]) -> dict:
    """SALib's problem over the unit hypercube of *names*."""
    return {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}


def sample_rows(distributions: dict[str, Distribution], samples: int, *, sobol: bool = False,
                seed: int = 0) -> tuple[dict, ...]:
    """The study rows of an uncertainty study.

    Parameters
    ----------
    distributions : dict of str to Distribution
        Per numeric study parameter.
    samples : int
        Monte Carlo: rows; Sobol': base samples N, a power of two (N (d + 2) rows).
    sobol : bool
        Rows of SALib's Saltelli design (first-order and total indices) instead of random ones.
    seed : int

    Returns
    -------
    tuple of dict

    Raises
    ------
    InputError
        No distribution, a text parameter, a sample count below 1 (Sobol': not a power of two) or over
        :data:`workbook.studies.parametric.MAX_STUDY_ROWS` rows.
    """
    names = list(distributions)
    if not names:
        raise InputError("an uncertainty study needs at least one parameter with a distribution")
    text = [name for name in names if not parameter(name).numeric]
    if text:
        raise InputError(f"a distribution needs a numeric parameter; {', '.join(text)} takes a list")
    if samples < 1 or (sobol and samples & (samples - 1)):
        raise InputError(f"samples: expected {'a power of two (base samples of the Sobol design)' if sobol else 'at least 1'}, "
                         f"got {samples}")
    rows = samples * (len(names) + 2) if sobol else samples
    _check_rows(rows, f"{samples:,} {'Sobol base samples' if sobol else 'samples'} of {len(names)} parameter(s)")
    if sobol:
        from SALib.sample import sobol as saltelli

        unit = saltelli.sample(_problem(names), samples, calc_second_order=False, seed=seed)
    else:
        unit = np.random.default_rng(seed).random((samples, len(names)))
    values = np.column_stack([distributions[name].ppf(unit[:, j]) for j, name in enumerate(names)])
    return tuple({name: float(v) for name, v in zip(names, row, strict=True)} for row in values)


@dataclass
class UncertaintyResult:
    """The rows of an uncertainty study with their statistics and Sobol' indices.

    Attributes
    ----------
    distributions : dict of str to Distribution
    rows : tuple of dict
        Parameter values of each row.
    frame : pandas.DataFrame
        The study table (:func:`workbook.studies.sensitivity.study_frame`): a row per sample and run.
    sobol : pandas.DataFrame or None
        Per run, quantity (``T x``...) and parameter: ``S1``, ``S1 conf``, ``ST``, ``ST conf`` (confidence
        half-widths at :data:`CONFIDENCE`); None without a Sobol' design or when a row failed.
    """

    distributions: dict
    rows: tuple
    frame: Any
    sobol: Any = None

    @classmethod
    def from_outcomes(cls, distributions: dict, rows: tuple, outcomes: list[RowOutcome], *, sobol: bool = False,
                      seed: int = 0) -> UncertaintyResult:
        """The result of the rows *rows* (from :func:`sample_rows`) and their *outcomes* (in row order);
        Sobol' indices for a Sobol' design whose rows all ran."""
        from workbook.studies.sensitivity import study_frame

        frame = study_frame(rows, outcomes)
        result = cls(distributions, rows, frame)
        if sobol and all(outcome.status == "ok" for outcome in outcomes):
            result.sobol = result._sobol_indices(seed)
        return result

    @property
    def failed(self) -> int:
        """Rows that did not run."""
        return int(self.frame.loc[self.frame["status"] != "ok", "row"].nunique())

    def _sobol_indices(self, seed: int):
        import pandas as pd
        from SALib.analyze import sobol as analysis

        names = list(self.distributions)
        records = []
        for run, data in self.frame.groupby("run", sort=False):
            for direction in DIRECTIONS:
                y = data.sort_values("row")[f"T {direction}"].to_numpy(float)
                indices = analysis.analyze(_problem(names), y, calc_second_order=False, conf_level=CONFIDENCE,
                                           seed=seed)
                for j, name in enumerate(names):
                    records.append({"run": run, "quantity": f"T {direction}", "parameter": name,
                                    **{key.replace("_", " "): float(indices[key][j])
                                       for key in ("S1", "S1_conf", "ST", "ST_conf")}})
        return pd.DataFrame.from_records(records)

    def to_pandas(self):
        """Statistics per run and quantity (T and eta % per direction) over the rows that ran.

        Returns
        -------
        pandas.DataFrame
            Columns ``run``, ``quantity``, ``samples``, ``mean``, ``std``, ``P5``, ``P50``, ``P95``.
        """
        import pandas as pd

        ok = self.frame[self.frame["status"] == "ok"]
        records = []
        for run, data in ok.groupby("run", sort=False):
            for quantity in QUANTITIES:
                values = data[quantity].to_numpy(float)
                records.append({"run": run, "quantity": quantity, "samples": len(values), "mean": values.mean(),
                                "std": values.std(ddof=1) if len(values) > 1 else math.nan,
                                **{f"P{p}": v for p, v in zip(PERCENTILES, np.percentile(values, PERCENTILES),
                                                               strict=True)}})
        return pd.DataFrame.from_records(records, columns=["run", "quantity", "samples", "mean", "std",
                                                           *(f"P{p}" for p in PERCENTILES)])

    def plot(self):
        """Histogram and CDF of T per run (the three directions), P5 to P95 marked; the total Sobol' indices
        with their confidence as bars when there are any.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        ok = self.frame[self.frame["status"] == "ok"]
        runs = list(dict.fromkeys(ok["run"])) or [""]
        columns = 2 if self.sobol is None else 3
        fig, axes = plt.subplots(len(runs), columns, squeeze=False, constrained_layout=True,
                                 figsize=(4.2 * columns, 3.0 * len(runs)))
        for i, run in enumerate(runs):
            data = ok[ok["run"] == run]
            for direction in DIRECTIONS:
                t = np.sort(data[f"T {direction}"].to_numpy(float))
                line = axes[i, 1].plot(t, np.arange(1, len(t) + 1) / len(t), label=f"T {direction}")[0]
                axes[i, 0].hist(t, bins=min(50, max(5, len(t) // 20)), histtype="step", color=line.get_color(),
                                label=f"T {direction}")
                if len(t):
                    low, high = np.percentile(t, (PERCENTILES[0], PERCENTILES[-1]))
                    axes[i, 1].axvspan(low, high, color=line.get_color(), alpha=0.1)
            axes[i, 0].set(xlabel="T", ylabel=f"{run}\nrows")
            axes[i, 1].set(xlabel=f"T (P{PERCENTILES[0]} to P{PERCENTILES[-1]} shaded)", ylabel="CDF")
            if self.sobol is not None:
                indices = self.sobol[self.sobol["run"] == run]
                names = list(self.distributions)
                for k, direction in enumerate(DIRECTIONS):
                    part = indices[indices["quantity"] == f"T {direction}"].set_index("parameter").loc[names]
                    axes[i, 2].bar(np.arange(len(names)) + (k - 1) * 0.27, part["ST"], 0.27, yerr=part["ST conf"],
                                   capsize=2, label=f"T {direction}")
                axes[i, 2].set_xticks(range(len(names)), names, rotation=20, fontsize="small")
                axes[i, 2].set(ylabel="total Sobol index", ylim=(0, 1.1))
        axes[0, 0].legend(fontsize="small")
        fig.suptitle(f"uncertainty of the pylon transmissibility: {len(self.rows)} rows, {self.failed} failed "
                     f"({'; '.join(f'{n} {d}' for n, d in self.distributions.items())})", fontsize="small")
        return fig

    def write(self, folder: str | Path, table_format: str = "csv", table: Path | None = None) -> list[Path]:
        """Write the rows' table (CSV or Parquet), a workbook (sheets: the rows, the statistics, the Sobol'
        indices) and the plot into *folder*, as ``uncertainty.*`` or ``uncertainty-2.*``... beside earlier files
        (*table*: this table file instead, e.g. the one written while the rows ran, the others beside it).

        Returns
        -------
        list of Path
        """
        import matplotlib.pyplot as plt

        from workbook.studies.sensitivity import new_study_table, write_study

        Path(folder).mkdir(parents=True, exist_ok=True)
        sheets = {"Statistics": self.to_pandas()}
        if self.sobol is not None:
            sheets["Sobol indices"] = self.sobol
        figure = self.plot()
        try:
            table = table or new_study_table(folder, table_format, UQ_STEM)  # type: ignore[arg-type]
            return write_study(self.frame, list(self.distributions), table, title="Uncertainty samples", sheets=sheets, figure=figure)
        finally:
            plt.close(figure)


def run_uncertainty(case: Case, distributions: dict[str, Distribution], samples: int, *, sobol: bool = False,
                    seed: int = 0, workers: int = SERIAL, dask: str | None = None,
                    design_model: LinearMount | None = None,
                    progress: Callable[[int, int], None] | None = None) -> UncertaintyResult:
    """Run an uncertainty study of *case*.

    Parameters
    ----------
    case : Case
        The base case.
    distributions, samples, sobol, seed
        As :func:`sample_rows`.
    workers, dask, design_model, progress
        As :func:`workbook.studies.parallel.run_rows` (*design_model*:
        :func:`workbook.studies.parallel.prepare_design_model` of *case*, to answer the rows in NumPy).

    Returns
    -------
    UncertaintyResult
    """
    rows = sample_rows(distributions, samples, sobol=sobol, seed=seed)
    outcomes = run_rows(study_cases(case, rows), workers=workers, dask=dask, design_model=design_model,
                        progress=progress)
    return UncertaintyResult.from_outcomes(distributions, rows, outcomes, sobol=sobol, seed=seed)
