"""``mountwb study accuracy [CASE] [--run R] [--repeats N] [--output DIR]``.

Runs one case through the accuracy ladder of :mod:`workbook.study`, prints
the markdown table and writes it, the Pareto plot and the sheet into the
output folder (new names when files of the same name exist).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Callable

from .parametric_cli import add_params_arguments, run_parameter_study

__all__ = ["study_arguments", "load_study_case"]


def load_study_case(path: str | None, run: str | None):
    """The case to study: the reference mount, a JSON case, or a case workbook
    (one row of its Runs sheet with *run*, else its whole case).

    Raises
    ------
    ValueError
        A run name given for a case that is not a workbook.
    workbook.excel.WorkbookError
        A bad workbook or an unknown run name.
    """
    from .excel.commands import is_workbook

    if is_workbook(path):
        from .excel.execute import select_runs
        from .excel.reader import read_workbook

        book = read_workbook(path)
        return book.case if run is None else book.run_case(select_runs(book, [run])[0])
    if run is not None:
        raise ValueError("--run names a row of a case workbook's Runs sheet; give a .xlsx case")
    from .codec import from_json
    from .reference import reference_case

    return reference_case() if path is None else from_json(Path(path).read_text())


def study_arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("kind", choices=["accuracy", "params"],
                        help="the study: 'accuracy' (accuracy against time) or 'params' (a parameter study)")
    parser.add_argument("case", nargs="?", help="case workbook (.xlsx) or JSON case; default: the reference mount")
    parser.add_argument("--run", metavar="R", help="case workbook: study this row of the Runs sheet")
    parser.add_argument("--repeats", type=int, default=3, help="repeats per rung for the median wall time")
    parser.add_argument("--output", default=".", metavar="DIR",
                        help="folder for accuracy-study.md/.png/.xlsx (existing files are kept: new names)")
    add_params_arguments(parser)

    def study(args) -> int:
        import matplotlib

        matplotlib.use("Agg")
        from .excel.sheets import WorkbookError
        from .study import run_study

        if args.repeats < 1:
            raise ValueError(f"--repeats must be at least 1, got {args.repeats}")
        try:
            case = load_study_case(args.case, args.run)
        except WorkbookError as error:
            print(f"mountwb study: {error}", file=sys.stderr)
            return 2
        if args.kind == "params":
            return run_parameter_study(args, case)
        result = run_study(case, repeats=args.repeats,
                           progress=lambda label: print(f"rung: {label}", file=sys.stderr, flush=True))
        print(result.to_markdown())
        for path in result.write(args.output):
            print(path)
        return 0

    return study
