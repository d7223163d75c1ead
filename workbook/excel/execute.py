"""Run the runs of a case workbook."""
from __future__ import annotations

import logging
from typing import Iterable

from workbook.errors import Problem, WorkbookError
from workbook.excel.reader import CaseBook
from workbook.excel.runs import RunSpec
from workbook.excel.writer import RunResult

__all__ = ["select_runs", "run_book"]

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


def run_book(book: CaseBook, runs: list[RunSpec], *, progress=None) -> list[RunResult]:
    """Run each of *runs* of *book*.

    Parameters
    ----------
    book : CaseBook
    runs : list of RunSpec
    progress : callable, optional
        Progress factory of :func:`workbook.solve.pipeline.run_case`.

    Returns
    -------
    list of RunResult
    """
    from workbook.solve.pipeline import run_case

    results = []
    for spec in runs:
        log.info("run %s (%s)", spec.name, spec.excitation)
        results.append(RunResult(spec, run_case(book.run_case(spec), progress=progress)))
    return results
