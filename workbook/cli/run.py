"""``mountwb run [CASE] [--json] [--rigid] [--method M] [--pylon-impedance CSV] [--hinges SEL] [--accuracy E]``.

Prints the three-way isolation-efficiency table, the dB table and the model
card of each run, or the answers as JSON; the warnings once per distinct
text, with the count and frequency range of the runs (a sweep's points)
that raised them. ``--hinges`` adds the force amplitude and T of a hinge or
hinge group against frequency (:mod:`workbook.answers.hinge_curves`), and
``--plot`` draws them; ``--compare complete`` overlays those of the complete
model (:func:`workbook.solve.truncation.complete_model`: the seed study's
Fig. 9). ``--accuracy 0.5%`` runs the case again with more fixed-interface
modes per link until the estimated truncation error of every T is within
it (:func:`workbook.solve.truncation.run_to_accuracy`). A case workbook runs
the rows of its Runs sheet and gets its results written back
(:mod:`workbook.cli.workbooks`).
"""
from __future__ import annotations

import argparse
import contextlib
import json
import sys
from typing import Callable

from workbook.cli import workbooks
from workbook.cli.loading import is_workbook, load_case, progress_factory
from workbook.cli.outputs import check_output, write_output
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
    parser.add_argument("--hinges", metavar="NAME|GROUP",
                        help="also give the force amplitude and T of a hinge, or of every hinge whose name starts "
                             "with GROUP (e.g. front; 'pylon': the pylon-side hinges), against frequency")
    parser.add_argument("--plot", metavar="OUT.png", help="with --hinges: draw their T against frequency as PNG")
    parser.add_argument("--compare", choices=("complete",),
                        help="with --hinges: overlay the complete model's curves (every flexible link with "
                             "20 fixed-interface modes) on the case's own (the low-frequency model by default)")
    parser.add_argument("--accuracy", type=_fraction, metavar="E",
                        help="largest estimated truncation error of T, e.g. 0.5%% or 0.005: the links whose "
                             "mode rule is auto get more fixed-interface modes (6, 12, 20) until every run's "
                             "estimate is within it")
    workbooks.add_run_arguments(parser)
    return run


def _fraction(text: str) -> float:
    """A fraction from ``0.5%`` or ``0.005`` (argparse type)."""
    try:
        value = float(text[:-1]) / 100 if text.endswith("%") else float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a fraction such as 0.5% or 0.005, got {text!r}") from None
    if not 0 < value < 1:
        raise argparse.ArgumentTypeError(f"expected a fraction between 0 and 100 %, got {text!r}")
    return value


def _rows(curves) -> list:
    table = curves.to_pandas()
    table.columns = [" ".join(key) for key in table.columns]
    return table.reset_index().to_dict(orient="records")


def run(args) -> int:
    from workbook.solve.pipeline import run_case

    if args.plot and not args.hinges:
        raise UsageError("--plot draws the curves of --hinges: give --hinges NAME|GROUP")
    if args.compare and not args.hinges:
        raise UsageError("--compare overlays the curves of --hinges: give --hinges NAME|GROUP")
    check_output("--plot", args.plot, (".png",), [args.case])
    if is_workbook(args.case):
        if args.hinges:
            raise UsageError("--hinges is for a JSON case or the reference mount; a case workbook's report has "
                             "every hinge's answers")
        if args.accuracy:
            raise UsageError("--accuracy is for a JSON case or the reference mount; in a case workbook give the "
                             "links' modes in the Links sheet")
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
    if args.hinges:
        from workbook.answers.hinge_curves import select_hinges

        select_hinges([h.name for h in case.hinges], args.hinges, [h.name for h in case.pylon_hinges], "--hinges")
    steps = []
    if args.accuracy:
        from workbook.solve.truncation import run_to_accuracy

        result, steps = run_to_accuracy(case, args.accuracy, progress=None if args.no_progress else progress_factory())
    else:
        result = run_case(case, progress=None if args.no_progress else progress_factory())
    curves = complete = None
    if args.hinges:
        from workbook.answers.hinge_curves import hinge_curves

        curves = hinge_curves(result, args.hinges)
        if args.compare:
            from workbook.solve.truncation import complete_model

            complete = hinge_curves(run_case(complete_model(case), progress=None if args.no_progress
                                             else progress_factory()), args.hinges)
    labels = ("(case's modes)", "(complete: 20 modes per link)")
    figure = curves.plot(complete, labels if complete else ("", "")) if curves is not None and args.plot else None
    if args.json:
        extra = ({"hinges": _rows(curves)} if curves else {}) | ({"hinges_complete": _rows(complete)}
                                                                  if complete else {})
        if steps:
            extra["accuracy"] = [{"modes": step.modes, "estimate %": 100 * step.estimate, "seconds": step.seconds}
                                 for step in steps]
        print(json.dumps({**json.loads(result.to_json()), **extra}, indent=2) if extra else result.to_json(indent=2))
    else:
        if steps:
            print(f"--accuracy {100 * args.accuracy:g} %: largest estimated truncation error of T per model run")
            for step in steps:
                print(f"  links' modes {step.modes:<18} {100 * step.estimate:8.3g} %  ({step.seconds:.1f} s)")
            print()
        _print_answers(case, result)
        if curves is not None:
            print("\n" + curves.to_text(f" {labels[0]}" if complete else ""))
        if complete is not None:
            print("\n" + complete.to_text(f" {labels[1]}"))
    with contextlib.redirect_stdout(sys.stderr) if args.json else contextlib.nullcontext():
        if figure is not None:
            from workbook.answers.saving import save_figure

            write_output(args.plot, "plot", "run", lambda target: save_figure(figure, target, dpi=120))
    return 0


def _print_answers(case, result) -> None:
    from workbook.answers.warning_groups import warning_lines

    print(f"{case.name}: pylon isolation efficiency eta = (1 - T) x 100 % (T: pylon force / excitation)\n")
    print(result.to_text("efficiency"))
    print("\n20 log10 T (dB):")
    print(result.to_text("db", frequency=False))
    for line in warning_lines(result.runs):
        print("\n" + line)
    for card in result.model_cards.values():
        print("\n" + card.to_text())
