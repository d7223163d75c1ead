"""Accuracy against time: one case through a ladder of fidelities and methods.

The rungs:

- link fidelity, each solved exactly in the frequency domain: rigid links;
  static modes only; Craig-Bampton with 2, 6, 12 and 20 fixed-interface
  modes on every link;
- method, at the case's own link fidelity: time domain at 20, 40 and 80
  steps per period; frequency domain;
- every link with its fixed-interface modes up to 4 x f_exc (at least
  one, whatever the low-frequency rule says), time domain, amplitude by DFT
  of the steady window;
- the seed study's complete-MNF model: every link with 20 fixed-interface
  modes, time domain + DFT. Against it the study reports the low-frequency
  approximation's (the case's own links: static modes where the rule
  holds) DOF reduction and speed-up, in the time domain at the same step and
  in the frequency domain.

The reference (the most accurate rung) is Craig-Bampton with 20
fixed-interface modes in the frequency domain: the richest link model, and
the harmonic solution is exact for the linear scene (no time-step error,
no transient left). For each rung: DOF of the scene, wall time (median of
repeats; link reductions come from the disk cache, filled before timing)
and the relative error of T_x, T_y, T_z of every excitation against the
reference.
"""
from __future__ import annotations

import dataclasses
import logging
import statistics
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from flexbodies.atomic import replacing
from flexbodies.selection import MODE_MARGIN
from workbook._renamed import renamed
from workbook.answers.saving import free_stem, save_figure, save_text
from workbook.errors import InputError
from workbook.model.case import DIRECTIONS, Case, ModeCutoff, SingleFrequencyExcitation
from workbook.solve.method import FREQUENCY, TIME, Method, MethodChoice
from workbook.solve.pipeline import prepare, run_excitation, solve_frequencies

__all__ = ["Rung", "RungResult", "AccuracyStudy", "ladder", "run_study", "REFERENCE_RUNG"]

log = logging.getLogger(__name__)

#: Label of the reference rung.
REFERENCE_RUNG = "Craig-Bampton, 20 modes"
#: Label of the seed study's complete-MNF rung.
SEED_RUNG = "seed study's complete-MNF model (20 modes on every link, time domain + DFT)"
#: Label of the frequency-domain rung of the case's own links.
FREQUENCY_RUNG = "frequency domain"


@dataclass(frozen=True)
class Rung:
    """One rung of the ladder.

    Attributes
    ----------
    label : str
    links : str
        Link fidelity: ``"rigid"``, ``"static"``, a mode count as text, ``"case"``
        (the case's own choice) or ``"margin"`` (every link's modes to 4 f_exc).
    method : {"time", "frequency"}
    steps_per_period : int or None
        Time-domain step (None: the case's).
    """

    label: str
    links: str
    method: Method
    steps_per_period: int | None = None

    @property
    def description(self) -> str:
        links = {"rigid": "rigid links", "static": "static modes only", "case": "links as the case asks",
                 "margin": f"every link: fixed-interface modes to {MODE_MARGIN:g} x f_exc (at least 1)"}
        fidelity = links.get(self.links, f"{self.links} fixed-interface modes per link")
        method = (f"time domain, {self.steps_per_period} steps/period" if self.method == TIME and
                  self.steps_per_period else f"{self.method} domain")
        return f"{fidelity}; {method}"


def ladder(steps_per_period: int = 40) -> list[Rung]:
    """The rungs of the study; *steps_per_period* is the time step of the two time-domain rungs at the top."""
    rungs = [Rung("rigid links", "rigid", FREQUENCY), Rung("static modes only", "static", FREQUENCY)]
    rungs += [Rung(f"Craig-Bampton, {n} modes", str(n), FREQUENCY) for n in (2, 6, 12, 20)]
    rungs += [Rung(f"time domain, {n} steps/period", "case", TIME, n) for n in (20, 40, 80)]
    rungs += [Rung(FREQUENCY_RUNG, "case", FREQUENCY),
              Rung("modes to 4 f_exc on every link (time domain + DFT)", "margin", TIME, steps_per_period),
              Rung(SEED_RUNG, "20", TIME, steps_per_period)]
    return rungs


def _margin_modes(link, excitation: SingleFrequencyExcitation):
    """Modes of a link up to 4 f_exc, at least one."""
    from flexbodies import reduce_link

    cutoff = ModeCutoff(MODE_MARGIN * excitation.frequency)
    kept = reduce_link(link.model, modes=cutoff, excitation_hz=excitation.frequency).n_fixed_interface
    return cutoff if kept > 0 else 1


def rung_case(case: Case, rung: Rung, excitation: SingleFrequencyExcitation) -> Case:
    """The case as *rung* models and solves it for *excitation* (one excitation)."""
    analysis = dataclasses.replace(case.analysis, method=rung.method,
                                   steps_per_period=rung.steps_per_period or case.analysis.steps_per_period)
    case = dataclasses.replace(case, excitations=(excitation,), analysis=analysis)
    if rung.links == "rigid":
        return case.with_rigid_links()
    if rung.links == "case":
        return case
    effects = dataclasses.replace(case.effects, flexible_links=True)
    links = []
    for link in case.links:
        modes = (_margin_modes(link, excitation) if rung.links == "margin"
                 else "static" if rung.links == "static" else int(rung.links))
        links.append(dataclasses.replace(link, modes=modes, flexible=True))
    return dataclasses.replace(case, links=tuple(links), effects=effects)


@dataclass(frozen=True)
class RungResult:
    """What one rung gave.

    Attributes
    ----------
    rung : Rung
    dof : int
        Degrees of freedom of the scene (largest over the excitations).
    wall_time : float
        Median over the repeats of the wall time of all excitations, s.
    transmissibility : dict of str to ndarray, shape (3,)
        Pylon T_x, T_y, T_z per excitation.
    """

    rung: Rung
    dof: int
    wall_time: float
    transmissibility: dict


def _solve(case: Case, excitation: SingleFrequencyExcitation, method: Method):
    """T (3,) and DOF of one excitation of a prepared rung case."""
    if method == FREQUENCY:
        prepared = prepare(case, excitation)
        choice = MethodChoice(FREQUENCY, "accuracy study rung")
        with prepared.scene:
            (run,) = solve_frequencies(case, prepared, (excitation,), choice)
    else:
        run = run_excitation(case, excitation)
    assert run.model_card is not None      # a solver's result carries its card
    return run.transmissibility, run.model_card.total_dof


def run_rung(case: Case, rung: Rung, repeats: int = 3) -> RungResult:
    """Run *rung* on every single-frequency excitation of *case*."""
    from workbook.scene.build import reduce_links

    excitations = list(case.single_frequency_excitations())
    cases = {e.name: rung_case(case, rung, e) for e in excitations}
    for excitation in excitations:          # fill the reduction cache before timing
        reduce_links(cases[excitation.name], excitation)
    times, answers, dof = [], {}, 0
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        for excitation in excitations:
            answers[excitation.name], size = _solve(cases[excitation.name], excitation, rung.method)
            dof = max(dof, size)
        times.append(time.perf_counter() - start)
    log.info("rung %r: %d DOF, %.3g s", rung.label, dof, statistics.median(times))
    return RungResult(rung, dof, statistics.median(times), answers)


@dataclass
class AccuracyStudy:
    """The ladder's results with errors against the reference rung.

    Attributes
    ----------
    case_name : str
    results : list of RungResult
    reference : str
        Label of the reference rung.
    repeats : int
    """

    case_name: str
    results: list
    reference: str
    repeats: int

    def _reference(self) -> RungResult:
        return next(r for r in self.results if r.rung.label == self.reference)

    def errors(self, result: RungResult) -> dict:
        """Relative error of T per excitation and direction against the reference, %."""
        reference = self._reference().transmissibility
        return {name: 100 * (np.asarray(t) / reference[name] - 1) for name, t in result.transmissibility.items()}

    def worst_error(self, result: RungResult) -> float:
        """Largest |error| over excitations and directions, %."""
        return float(max(np.abs(e).max() for e in self.errors(result).values()))

    def to_pandas(self):
        """One row per rung: method, links, DOF, wall time (s), error of
        T_x, T_y, T_z per excitation (%), worst |error| (%).

        Returns
        -------
        pandas.DataFrame
        """
        import pandas as pd

        rows = []
        for result in self.results:
            row = {"rung": result.rung.label + (" (reference)" if result.rung.label == self.reference else ""),
                   "model": result.rung.description, "DOF": result.dof, "wall time s": result.wall_time}
            for name, error in self.errors(result).items():
                row.update({f"{name} T_{axis} error %": e for axis, e in zip(DIRECTIONS, error, strict=True)})
            row["worst |error| %"] = self.worst_error(result)
            rows.append(row)
        return pd.DataFrame(rows).set_index("rung")

    frame = renamed("frame", "to_pandas()", lambda self: self.to_pandas())

    def _result(self, label: str) -> RungResult | None:
        return next((r for r in self.results if r.rung.label == label), None)

    def low_frequency_gain(self) -> list[tuple[str, int, int, float]]:
        """The low-frequency approximation (the case's own links) against the
        seed study's complete-MNF model, per method of the approximation.

        Returns
        -------
        list of (str, int, int, float)
            Rung label, its DOF, the complete-MNF model's DOF and the speed-up
            (the complete-MNF wall time over the rung's), for the time domain
            at the complete-MNF model's step and the frequency domain; empty
            when the ladder lacks those rungs.
        """
        seed = self._result(SEED_RUNG)
        if seed is None:
            return []
        peers = [f"time domain, {seed.rung.steps_per_period} steps/period", FREQUENCY_RUNG]
        return [(r.rung.label, r.dof, seed.dof, seed.wall_time / r.wall_time)
                for r in map(self._result, peers) if r is not None]

    def reference_frame(self):
        """T_x, T_y, T_z of the reference rung per excitation."""
        import pandas as pd

        reference = self._reference().transmissibility
        return pd.DataFrame({name: t for name, t in reference.items()},
                            index=[f"T_{d}" for d in DIRECTIONS]).T.rename_axis("excitation")

    def to_markdown(self) -> str:
        """The table as GitHub markdown, with the reference values and the study's rules."""
        frame = self.to_pandas()
        errors = [c for c in frame.columns if c.endswith("error %") and not c.startswith("worst")]
        header = ["rung", "DOF", "wall time (s)"] + [c.replace(" error %", " err %") for c in errors] + \
                 ["worst (%)"]
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        for label, row in frame.iterrows():
            cells = [label, f"{row['DOF']:d}", f"{row['wall time s']:.3g}"]
            cells += [f"{row[c]:+.3f}" for c in errors] + [f"{row['worst |error| %']:.3f}"]
            lines.append("| " + " | ".join(cells) + " |")
        values = "; ".join(f"{name}: " + ", ".join(f"T_{d} = {t:.5g}" for d, t in zip(DIRECTIONS, row, strict=True))
                           for name, row in self.reference_frame().iterrows())
        lines += ["", f"Case: {self.case_name}. Errors: (T - T_ref) / T_ref x 100 % per excitation and direction, "
                  f"against the reference rung '{self.reference}' (the richest link model solved exactly by the "
                  f"harmonic solution of the linear scene). Reference values: {values}. Wall time: median of "
                  f"{self.repeats} repeat(s), link reductions from the cache."]
        for label, dof, seed_dof, speed_up in self.low_frequency_gain():
            lines += ["", f"Low-frequency approximation ('{label}') against the seed study's complete-MNF model: "
                      f"{dof} DOF against {seed_dof} ({100 * (1 - dof / seed_dof):.0f} % fewer), "
                      f"{speed_up:.3g} x faster."]
        return "\n".join(lines) + "\n"

    def plot(self):
        """Pareto plot: worst |error| against wall time, log-log, rungs numbered
        as in the legend; the reference (zero error) is drawn at the bottom edge.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(11, 5.5), constrained_layout=True)
        errors = [self.worst_error(r) for r in self.results]
        positive = [e for e in errors if e > 0]
        floor = min(positive) / 3 if positive else 1e-6
        for number, (result, error) in enumerate(zip(self.results, errors, strict=True), start=1):
            is_reference = result.rung.label == self.reference
            marker = "*" if is_reference else ("s" if result.rung.method == TIME else "o")
            color = "C3" if is_reference else ("C1" if result.rung.method == TIME else "C0")
            label = f"{number}  {result.rung.label}" + (" (reference, error 0: drawn at the bottom)"
                                                         if is_reference else "")
            ax.loglog(result.wall_time, max(error, floor), marker, ms=10 if is_reference else 7, color=color,
                      label=label)
            ax.annotate(str(number), (result.wall_time, max(error, floor)), textcoords="offset points",
                        xytext=(6, 4), fontsize="small")
        ax.set_xlabel("wall time s (median of repeats)")
        ax.set_ylabel("worst |error| of T_x, T_y, T_z %")
        ax.set_title(f"{self.case_name}: accuracy against time\n"
                     f"circles: frequency domain, squares: time domain")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(loc="center left", bbox_to_anchor=(1.02, 0.5), fontsize="small", frameon=False)
        return fig

    def write(self, folder: str | Path, stem: str = "accuracy-study") -> list[Path]:
        """Write the markdown table, the Pareto plot (PNG) and the sheet (.xlsx, one sheet).

        Existing files are never overwritten: when any of ``stem.md``,
        ``stem.png``, ``stem.xlsx`` exists, the next free ``stem-2``,
        ``stem-3``, ... is used for all three.

        Returns
        -------
        list of Path
            The files written.
        """
        import matplotlib.pyplot as plt

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        name = free_stem(folder, stem, (".md", ".png", ".xlsx"))
        paths = [folder / f"{name}{suffix}" for suffix in (".md", ".png", ".xlsx")]
        save_text(self.to_markdown(), paths[0])
        figure = self.plot()
        save_figure(figure, paths[1], dpi=130)
        plt.close(figure)
        with replacing(paths[2], suffix=".xlsx.tmp") as temporary:
            self.to_pandas().to_excel(temporary, sheet_name="accuracy study", engine="openpyxl")
        return paths


def run_study(case: Case, *, repeats: int = 3, rungs: list | None = None,
              progress: Callable[[str], None] | None = None) -> AccuracyStudy:
    """Run *case* through the ladder.

    Parameters
    ----------
    case : Case
        Every single-frequency excitation (sweeps included, point by point)
        is run on every rung.
    repeats : int
        Repeats per rung for the median wall time.
    rungs : list of Rung, optional
        Default: :func:`ladder` with the case's steps per period for its top time-domain rungs.
    progress : callable, optional
        Called with each rung's label before it runs.

    Returns
    -------
    AccuracyStudy
    """
    rungs = rungs or ladder(case.analysis.steps_per_period)
    if REFERENCE_RUNG not in [r.label for r in rungs]:
        raise ValueError(f"the ladder must hold the reference rung {REFERENCE_RUNG!r}")
    if not case.single_frequency_excitations():
        raise InputError(f"case {case.name!r} has no excitation to study")
    results = []
    for rung in rungs:
        if progress is not None:
            progress(rung.label)
        results.append(run_rung(case, rung, repeats))
    return AccuracyStudy(case.name, results, REFERENCE_RUNG, max(1, repeats))
