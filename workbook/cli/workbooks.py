"""The Excel subcommands of ``mountwb``: ``check``, ``template`` and ``run CASE.xlsx``.

Exit codes (:mod:`workbook.errors`): 0 done, 2 bad input (nothing
written), 1 numerical trouble or a file that could not be saved. Messages are plain words on stdout (results) and stderr
(problems).
"""
from __future__ import annotations

import argparse
import contextlib
import gc
import sys
from typing import Callable

from workbook.cli.loading import progress_factory
from workbook.cli.outputs import check_output, print_written
from workbook.errors import EXIT_BAD_INPUT, EXIT_OK, EXIT_TROUBLE

__all__ = ["check_arguments", "template_arguments", "add_run_arguments", "run_workbook"]


def _report_problems(error) -> int:
    problems = error.problems
    print(f"{len(problems)} problem{'s' if len(problems) != 1 else ''} found; nothing was written:", file=sys.stderr)
    for problem in problems:
        print(f"  {problem}", file=sys.stderr)
    return EXIT_BAD_INPUT


def check_arguments(parser: argparse.ArgumentParser) -> Callable:
    """``mountwb check CASE.xlsx``: validate a case workbook; nothing is run or written."""
    parser.add_argument("workbook", help="case workbook (.xlsx)")

    def check(args) -> int:
        from workbook.errors import WorkbookError
        from workbook.excel.reader import read_workbook

        try:
            book = read_workbook(args.workbook)
        except WorkbookError as error:
            return _report_problems(error)
        case = book.case
        print(f"{book.path.name}: OK - case '{case.name}': {len(case.links)} links, {len(case.hinges)} hinges, "
              f"{len(case.excitations)} excitations, {len(book.runs)} runs, {len(book.tests)} test values, "
              f"{len(case.load_cases)} load cases, {len(case.speed_spectra)} speed spectra")
        return EXIT_OK

    return check


def template_arguments(parser: argparse.ArgumentParser) -> Callable:
    """``mountwb template OUT.xlsx [--reference]``: write the case template (or the reference case)."""
    parser.add_argument("output", help="workbook to write, e.g. templates/case-template.xlsx")
    parser.add_argument("--reference", action="store_true",
                        help="write the reference case with the seed study's runs (cases/reference.xlsx)")
    parser.add_argument("--replace", action="store_true",
                        help="replace OUT if it exists (default: an existing file is kept and the workbook "
                             "is written beside it under a new name)")

    def template(args) -> int:
        from workbook.excel.template import reference_workbook, template_workbook, write_workbook

        check_output("output", args.output, (".xlsx", ".xlsm"))
        target, reason = write_workbook(reference_workbook() if args.reference else template_workbook(),
                                        args.output, args.replace)
        print_written(args.output, "template", target, reason)
        return EXIT_OK

    return template


def add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of ``mountwb run`` for a case workbook."""
    parser.add_argument("--run", action="append", dest="runs", metavar="NAME",
                        help="case workbook: run only this row of Runs (repeat for several)")
    parser.add_argument("--report", metavar="OUT.xlsx", help="case workbook: also write a report workbook")
    parser.add_argument("--four-pole", action="store_true",
                        help="case workbook: the report gets a Four-pole sheet, the mount's driving-point and "
                             "transfer dynamic stiffness per direction (as mountwb four-pole with its defaults)")


def _summary_text(efficiency) -> str:
    """The pylon isolation efficiency of the runs as a table: one row per run, point and frequency, one column per
    direction.

    Laid out as pandas lays out ``to_string(float_format=lambda v: f"{v:8.2f}")`` of the pivot table of
    *efficiency* (its ``eta %`` by run, point and frequency, its ``6g`` text, against direction, in the order
    met), without pandas.

    Parameters
    ----------
    efficiency : workbook.excel.writer.ResultTable
        The efficiency table of :func:`~workbook.excel.writer.result_tables`.
    """
    names = ("run", "point", "frequency Hz")
    values: dict[tuple, dict[str, float]] = {}
    directions: dict[str, None] = {}
    for record in efficiency.records():
        key = (record["run"], record["point"], f"{record['frequency Hz']:.6g}")
        values.setdefault(key, {})[record["direction"]] = record["eta %"]
        directions[record["direction"]] = None

    def shown(value: float | None) -> str:
        return "NaN" if value is None or value != value else f"{value:8.2f}"

    cells = {key: [shown(row.get(d)) for d in directions] for key, row in values.items()}
    levels = [max([len(name), *(len(key[i]) for key in values)]) for i, name in enumerate(names)]
    index = sum(levels) + len(levels) - 1
    widths = [max([len(d), *(len(row[j]) for row in cells.values())]) for j, d in enumerate(directions)]
    lines = ["direction".ljust(index) + "".join(" " + d.rjust(w) for d, w in zip(directions, widths, strict=True)),
             " ".join(name.ljust(w) for name, w in zip(names, levels, strict=True)) + " " * sum(w + 1 for w in widths)]
    previous: tuple = ()
    for key, row in cells.items():
        # pandas leaves out a level's label where it and the levels before it repeat the row above (not the last)
        labels = [label if i == len(key) - 1 or key[:i + 1] != previous[:i + 1] else ""
                  for i, label in enumerate(key)]
        lines.append(" ".join(label.ljust(w) for label, w in zip(labels, levels, strict=True))
                     + "".join(" " + text.rjust(w) for text, w in zip(row, widths, strict=True)))
        previous = key
    return "\n".join(lines)


def _print_summary(runs, tables: dict) -> None:
    """Print the efficiency table of *runs* (their result tables *tables*, :func:`~workbook.excel.writer.result_tables`)
    and their warnings."""
    print("Pylon isolation efficiency eta = (1 - T) x 100 %:")
    print(_summary_text(tables["efficiency"]))
    from workbook.answers.warning_groups import warning_lines

    for run in runs:
        for line in warning_lines(run.result.runs, run.spec.name):
            print(line)


def run_workbook(args) -> int:
    """Run the runs of a case workbook, write the results back and optionally a report.

    A run that fails is named and the others go on. When runs failed on
    numerical trouble only, the answers of the runs that finished are
    written and the exit code is 1; when a run found its input bad while
    running, nothing is written and the exit code is 2.
    """
    from workbook.errors import WorkbookError
    from workbook.excel.execute import select_runs
    from workbook.excel.pictures import start_pictures
    from workbook.excel.reader import read_workbook

    if getattr(args, "json", False) or getattr(args, "rigid", False) \
            or getattr(args, "time_budget", None) is not None or getattr(args, "method", None):
        print("mountwb run: --json, --rigid, --method and --time-budget are for JSON cases; a workbook sets its "
              "runs' fidelity in its Runs sheet and its method and time budget in its Case sheet", file=sys.stderr)
        return EXIT_BAD_INPUT
    check_output("--report", args.report, (".xlsx",), [args.case])
    if args.four_pole and not args.report:
        print("mountwb run: --four-pole adds a sheet to the report: give --report OUT.xlsx", file=sys.stderr)
        return EXIT_BAD_INPUT
    with _seldom_collections():
        try:
            book = read_workbook(args.case)
            selected = select_runs(book, args.runs)
        except WorkbookError as error:
            return _report_problems(error)
        progress = None if getattr(args, "no_progress", False) else progress_factory()
        # the report's pictures: a second process imports matplotlib while the runs are computed, and
        # draws each run's as it is done (the last while this one writes the results)
        pictures = start_pictures() if args.report else None
        try:
            return _run_and_write(args, book, selected, progress, pictures)
        finally:
            if pictures is not None:
                pictures.close()


#: Allocations between two runs of Python's youngest garbage collection while a workbook is run (default 700).
_YOUNG_COLLECTION = 50_000


@contextlib.contextmanager
def _seldom_collections():
    """Run Python's cyclic garbage collector seldom meanwhile.

    openpyxl makes an object per cell (and its style) of the workbook read
    and of the sheets written, which live until the file is saved: at the
    default thresholds the collector walks them again and again, a tenth of
    the command's time for nothing to collect.
    """
    thresholds = gc.get_threshold()
    gc.set_threshold(_YOUNG_COLLECTION, *thresholds[1:])
    try:
        yield
    finally:
        gc.set_threshold(*thresholds)


def _solved_loads(case):
    """The table of the case's load cases, solved and printed (None: the case has none)."""
    if not case.load_cases:
        return None
    from workbook.cli.loads import print_load_cases
    from workbook.excel.loads_sheet import loads_frame
    from workbook.solve.load_cases import solve_load_cases

    results = solve_load_cases(case)
    print_load_cases(case, results)
    return loads_frame(results)


def _solved_fatigue(case):
    """The table of the links' fatigue, solved (None: the case asks for no strength answers, having neither load
    cases nor speed spectra, or has no flexible link or a flexible pylon)."""
    if not (case.load_cases or case.speed_spectra) or case.flexible_pylon \
            or not any(case.link_is_flexible(link.name) for link in case.links):
        return None
    from workbook.excel.fatigue_sheet import fatigue_frame
    from workbook.solve.fatigue import solve_fatigue

    result = solve_fatigue(case)
    for name, life in result.life_hours().items():
        print(f"{name}: Miner life under the speed spectra "
              + (f"{life:.4g} h" if life < float("inf") else "infinite (no stress above the endurance strength)"))
    return fatigue_frame(result)


def _run_and_write(args, book, selected, progress, pictures) -> int:
    """The runs of :func:`run_workbook`, their results written back and the report."""
    from workbook.errors import SimulationError
    from workbook.excel.execute import run_book
    from workbook.excel.report import write_report
    from workbook.excel.writer import result_tables, write_results
    from workbook.solve.pipeline import report_four_pole

    runs, failures = run_book(book, selected, progress=progress, finished=None if pictures is None else pictures.add)
    for failure in failures:
        print(f"mountwb run: {failure}", file=sys.stderr)
    if any(failure.bad_input for failure in failures) or not runs:
        print(f"mountwb run: {len(failures)} of {len(selected)} run(s) failed; nothing was written",
              file=sys.stderr)
        return EXIT_BAD_INPUT if any(failure.bad_input for failure in failures) else EXIT_TROUBLE
    try:
        pole = report_four_pole(book.case) if args.four_pole else None
        loads = _solved_loads(book.case)
        fatigue = _solved_fatigue(book.case)
    except SimulationError as error:
        print(f"mountwb run: numerical trouble: {error}; nothing was written", file=sys.stderr)
        return EXIT_TROUBLE
    tables = result_tables(runs, book.tests)
    _print_summary(runs, tables)
    try:
        outcome = write_results(book.path, book.sha256, runs, book.tests, opened=book.opened, loads=loads,
                                fatigue=fatigue, tables=tables)
    except OSError as error:
        print(f"mountwb run: the results could not be saved ({error}); {book.path.name} is unchanged",
              file=sys.stderr)
        return EXIT_TROUBLE
    print_written(book.path.name, "results", outcome.path, outcome.reason)
    if args.report:
        try:
            report = write_report(args.report, book, runs, outcome, four_pole=pole, pictures=pictures, loads=loads,
                                  fatigue=fatigue)
        except OSError as error:
            print(f"mountwb run: no report: {error}", file=sys.stderr)
            return EXIT_TROUBLE
        print_written(args.report, "report", report.path, report.reason)
    if failures:
        print(f"mountwb run: the answers of {len(runs)} run(s) were written; "
              f"{', '.join(repr(f.spec.name) for f in failures)} failed (numerical trouble, above)", file=sys.stderr)
        return EXIT_TROUBLE
    return EXIT_OK
