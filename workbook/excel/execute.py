"""Run the runs of a case workbook."""
from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Callable, Iterable

from workbook.errors import Problem, SimulationError, WorkbookError, interruption
from workbook.excel.reader import CaseBook
from workbook.excel.runs import RunSpec
from workbook.excel.writer import RunResult

__all__ = ["select_runs", "run_book", "RunFailure"]

log = logging.getLogger(__name__)


def select_runs(book: CaseBook, names: Iterable[str] | None = None) -> list[RunSpec]:
    """The runs named *names* (all runs for None), in the Runs sheet's order.

    Raises
    ------
    WorkbookError
        A name that is not a run of the workbook.
    """
    if names is None:
        return list(book.runs)
    names = list(names)
    known = [run.name for run in book.runs]
    unknown = [name for name in names if name not in known]
    if unknown:
        raise WorkbookError([Problem(book.path.name, "Runs", None, "run", name, f"a run name ({', '.join(known)})")
                             for name in unknown])
    return [run for run in book.runs if run.name in names]


@dataclass(frozen=True)
class RunFailure:
    """A run of a workbook that stopped, and why.

    Attributes
    ----------
    spec : RunSpec
    error : Exception
        Numerical trouble (:class:`~workbook.errors.SimulationError`) or
        input found bad only while running (:attr:`bad_input`).
    """

    spec: RunSpec
    error: Exception

    @property
    def bad_input(self) -> bool:
        """True if the run stopped on the input, not on the solution."""
        return not isinstance(self.error, SimulationError)

    def __str__(self) -> str:
        trouble = "bad input" if self.bad_input else "numerical trouble"
        return f"run '{self.spec.name}' (excitation '{self.spec.excitation}') failed, {trouble}: {self.error}"


def run_book(book: CaseBook, runs: list[RunSpec], *, progress=None,
             finished: Callable[[RunResult], None] | None = None) -> tuple[list[RunResult], list[RunFailure]]:
    """Run each of *runs* of *book*; a run that fails does not stop the runs after it.

    Parameters
    ----------
    book : CaseBook
    runs : list of RunSpec
    progress : callable, optional
        Progress factory of :func:`workbook.solve.pipeline.run_case`.
    finished : callable, optional
        Called with each run that finished, at once (the report's pictures start from it).

    Returns
    -------
    results : list of RunResult
        The runs that finished, in order.
    failures : list of RunFailure
        The runs that stopped on numerical trouble or on input found bad
        while running, in order. An interrupt, and an error that is neither
        (a defect of the package), is raised.
    """
    from workbook.solve.pipeline import run_case

    results, failures = [], []
    for spec in runs:
        log.info("run %s (%s)", spec.name, spec.excitation)
        try:
            result = RunResult(spec, run_case(book.run_case(spec), progress=progress))
        except (SimulationError, ValueError, OSError) as error:    # what the command line reports as such
            if interruption(error) is not None:
                raise
            log.info("run %s failed: %s", spec.name, error)
            failures.append(RunFailure(spec, error))
            continue
        results.append(result)
        if finished is not None:
            finished(result)
    return results, failures
