"""``mountwb run [CASE] [--json] [--rigid] [--method M] [--time-budget S] [--pylon-impedance CSV]``: run a case.

Prints the three-way isolation-efficiency table, the dB table and the model
card of each run, or the answers as JSON. A case workbook runs the rows of
its Runs sheet and gets its results written back (:mod:`workbook.cli.workbooks`).
"""
from __future__ import annotations

import argparse
from typing import Callable

from workbook.cli import workbooks
from workbook.cli.loading import is_workbook, load_case, progress_factory
from workbook.errors import UsageError
from workbook.model.case import ANALYSIS_METHODS

__all__ = ["arguments"]


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("--json", action="store_true", help="print the answers as JSON")
    parser.add_argument("--rigid", action="store_true", help="make every link rigid")
    parser.add_argument("--method", choices=ANALYSIS_METHODS,
                        help="analysis: auto (frequency domain for a linear scene, time domain when a clearance "
                             "law is built), time or frequency; default: as the case says (auto unless it says "
                             "otherwise)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    parser.add_argument("--time-budget", type=float, metavar="SECONDS",
                        help="wall time one run may take before it stops with an estimate of the time it needs")
    parser.add_argument("--pylon-impedance", metavar="TABLE.csv",
                        help="the pylon's point dynamic stiffness per pin against frequency (CSV, see "
                             "docs/four-pole.md): answers on that flexible pylon, frequency domain only")
    workbooks.add_run_arguments(parser)
    return run


def run(args) -> int:
    from workbook.solve.pipeline import run_case

    if is_workbook(args.case):
        if args.pylon_impedance:
            raise UsageError("--pylon-impedance: a case workbook takes the table as its 'Pylon impedance' sheet")
        return workbooks.run_workbook(args)
    if args.four_pole:
        raise UsageError("--four-pole adds a sheet to a case workbook's --report; for a JSON case or the reference "
                         "mount use mountwb four-pole")
    workbook_only = [option for option, value in (("--run", args.runs), ("--report", args.report)) if value]
    if workbook_only:
        raise UsageError(f"{' and '.join(workbook_only)} {'are' if len(workbook_only) > 1 else 'is'} for a case "
                         f"workbook (.xlsx), and {args.case or 'the reference mount'} is not one: a JSON case runs "
                         "every excitation it has and prints its answers (--json: as JSON); nothing was run")
    case = load_case(args.case, rigid=args.rigid, time_budget=args.time_budget, method=args.method,
                     pylon_impedance=args.pylon_impedance)
    result = run_case(case, progress=None if args.no_progress else progress_factory())
    if args.json:
        print(result.to_json(indent=2))
        return 0
    print(f"{case.name}: pylon isolation efficiency eta = (1 - T) x 100 % (T: pylon force / excitation)\n")
    print(result.table_text("efficiency"))
    print("\n20 log10 T (dB):")
    print(result.table_text("db", frequency=False))
    for run_result in result.runs:
        for warning in run_result.warnings:
            print(f"\nWARNING {run_result.name}: {warning}")
    for card in result.model_cards.values():
        print("\n" + card.to_text())
    return 0
