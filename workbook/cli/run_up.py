"""``mountwb run-up [CASE] [--excitation NAME --from S --to S --points N --unit rpm|Hz] [--csv OUT] [--plot OUT.png]
[--hinges NAME|GROUP [--hinges-plot OUT.png]]``.

A rotor imbalance over a speed range, its force growing as U w^2
(:mod:`workbook.solve.run_up`): per speed the excitation force, the
pylon-force amplitude and T per direction, the mounted modes, and one plot;
with ``--hinges`` also each chosen hinge's force amplitude and T per speed
(:mod:`workbook.answers.hinge_curves`).
Without ``--from``/``--to`` the case's own run-ups run (an Excitations row
with a run-up speed unit, or a :class:`~workbook.model.case.RunUp` in a JSON
case); with them, the imbalance ``--excitation`` (a rotating force or an
imbalance given by its unbalance, or made one with ``--unbalance``) is run
up over that range. Everything is computed before a file is written, and an
existing file is kept (the new one gets a new name, :mod:`workbook.cli.outputs`).
"""
from __future__ import annotations

import argparse
import dataclasses
from typing import Callable, cast

from workbook.answers.saving import save_csv, save_figure
from workbook.cli.loading import load_case
from workbook.cli.outputs import check_output, write_output
from workbook.errors import CaseError, UsageError
from workbook.model.case import SPEED_UNITS, Case, RotatingForce, RunUp, SingleFrequencyExcitation

__all__ = ["arguments"]

#: The options that give a run-up's fields (:meth:`RunUp.speeds`).
_OPTIONS = {"start": "--from", "stop": "--to", "points": "--points"}


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("--excitation", metavar="NAME",
                        help="the run-up to run, or with --from/--to the imbalance to run up (default: every "
                             "run-up of the case)")
    parser.add_argument("--from", dest="start", type=float, metavar="SPEED", help="first speed (in --unit)")
    parser.add_argument("--to", dest="stop", type=float, metavar="SPEED", help="last speed (in --unit)")
    parser.add_argument("--points", type=int, default=41, help="speeds, evenly spaced (default 41)")
    parser.add_argument("--unit", choices=tuple(SPEED_UNITS), default="rpm", help="speed unit (default rpm)")
    parser.add_argument("--unbalance", type=float, metavar="KG_M",
                        help="unbalance of a rotating force given by its amplitude, kg m (replaces the amplitude)")
    parser.add_argument("--rigid", action="store_true", help="make every link rigid")
    parser.add_argument("--csv", metavar="OUT.csv", help="write the table as CSV (one run-up)")
    parser.add_argument("--plot", metavar="OUT.png", help="write the plot as PNG (one run-up)")
    parser.add_argument("--hinges", metavar="NAME|GROUP",
                        help="also give the force amplitude and T of a hinge, or of every hinge whose name starts "
                             "with GROUP (e.g. front; 'pylon': the pylon-side hinges), against speed")
    parser.add_argument("--hinges-plot", metavar="OUT.png", help="with --hinges: draw their T against frequency")
    return run


def _run_ups(case: Case, args) -> list[RunUp]:
    """The run-ups the arguments ask for."""
    excitations = {e.name: e for e in case.excitations}
    if args.start is None and args.stop is None:
        if args.unbalance is not None:
            raise UsageError("--unbalance makes a run-up of --excitation over --from to --to; give those too")
        chosen = [e for e in case.excitations if isinstance(e, RunUp)
                  and (args.excitation is None or e.name == args.excitation)]
        if not chosen:
            have = ", ".join(e.name for e in case.excitations if isinstance(e, RunUp)) or "none"
            raise UsageError(f"--excitation {args.excitation!r}: expected a run-up of the case (run-ups: {have}); or "
                             f"give --from and --to to run up an imbalance" if args.excitation else
                             "the case has no run-up: name an imbalance with --excitation and give --from and --to")
        return chosen
    if args.start is None or args.stop is None or args.excitation is None:
        raise UsageError("a run-up of an imbalance needs --excitation NAME, --from and --to")
    template = excitations.get(args.excitation)
    if template is None or isinstance(template, RunUp) or not hasattr(template, "point_forces"):
        raise UsageError(f"--excitation {args.excitation!r}: expected a rotating force or an imbalance of the case "
                         f"({', '.join(excitations) or 'none'})")
    if args.unbalance is not None:
        if not isinstance(template, RotatingForce):
            raise UsageError(f"--unbalance: {args.excitation!r} is not a rotating force; give its planes' unbalance "
                             f"in the case")
        template = dataclasses.replace(template, amplitude=None, unbalance=args.unbalance)
    try:
        return [RunUp.speeds(f"{args.excitation} run-up", cast(SingleFrequencyExcitation, template), args.start,
                             args.stop, args.points, args.unit)]
    except CaseError as error:  # named by the option that gave it, not by the run-up's field
        if error.field == "unbalance":
            raise UsageError(f"--excitation {args.excitation!r}: found no unbalance, expected {error.expected}; or "
                             f"give --unbalance KG_M") from None
        if error.field not in _OPTIONS:
            raise
        found = f"{error.value:g}" if isinstance(error.value, float) else repr(error.value)
        raise UsageError(f"{_OPTIONS[error.field]} {found}: expected {error.expected}") from None


def run(args) -> int:
    from workbook.answers.warning_groups import warning_lines
    from workbook.solve.run_up import run_up

    check_output("--csv", args.csv, (".csv",), [args.case])
    check_output("--plot", args.plot, (".png",), [args.case])
    check_output("--hinges-plot", args.hinges_plot, (".png",), [args.case])
    if args.hinges_plot and not args.hinges:
        raise UsageError("--hinges-plot draws the curves of --hinges: give --hinges NAME|GROUP")
    case = load_case(args.case, rigid=args.rigid)
    if args.hinges:
        from workbook.answers.hinge_curves import select_hinges

        select_hinges([h.name for h in case.hinges], args.hinges, [h.name for h in case.pylon_hinges], "--hinges")
    items = _run_ups(case, args)
    if (args.csv or args.plot or args.hinges_plot) and len(items) > 1:
        raise UsageError(f"--csv/--plot/--hinges-plot write one run-up; the case has {len(items)}: choose one with "
                         f"--excitation")
    answers = [run_up(case, item) for item in items]
    figure = answers[0].plot() if args.plot else None
    curves = None
    if args.hinges:
        from workbook.answers.hinge_curves import hinge_curves

        curves = [hinge_curves(answer.result, args.hinges) for answer in answers]
    hinge_figure = curves[0].plot() if curves and args.hinges_plot else None
    for answer in answers:
        print(f"{case.name}: run-up {answer.sweep.name}, force U w^2 per plane; pylon force amplitude and "
              f"T = |F_pylon| / |F| per direction\n")
        print(answer.to_pandas().to_string(float_format=lambda v: f"{v:10.4g}"))
        print("\nmodes (marked on the plot at the speed equal to their frequency):")
        print(answer.modes.to_pandas().to_string(float_format=lambda v: f"{v:8.2f}"))
        for line in warning_lines(answer.result.runs, unit=answer.speed_unit):
            print("\n" + line)
        if curves is not None:
            print("\n" + curves[answers.index(answer)].to_text())
    if args.csv:
        write_output(args.csv, "table", "run-up", lambda target: save_csv(answers[0].to_pandas(), target))
    if figure is not None:
        write_output(args.plot, "plot", "run-up", lambda target: save_figure(figure, target, dpi=120))
    if hinge_figure is not None:
        write_output(args.hinges_plot, "hinge plot", "run-up",
                     lambda target: save_figure(hinge_figure, target, dpi=120))
    return 0
