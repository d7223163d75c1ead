"""``mountwb campbell [CASE] [--rotor NAME] [--from RPM] [--to RPM] [--orders 1,2] [--operating LOW:HIGH]``.

The Campbell diagram (:mod:`workbook.solve.campbell`): the modes of the
mounted engine against rotor speed, with the gyroscopic split of the
case's rotors, the engine-order lines and the critical speeds where they
meet. Prints the critical speeds and the branches; ``--plot``, ``--csv``
and ``--json`` write the picture, the branches table and everything.
Everything is computed before a file is written; an existing file of an
output's name is kept and the new one goes beside it.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import sys
from typing import Callable

from workbook.cli.loading import load_case
from workbook.cli.outputs import check_output, write_output
from workbook.cli.params import positive
from workbook.errors import UsageError

__all__ = ["arguments"]


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount "
                                                "with its spools as gyroscopic rotors")
    parser.add_argument("--run", metavar="R", help="case workbook: take the case of this row of the Runs sheet")
    parser.add_argument("--rotor", metavar="NAME", help="the rotor whose speed is the abscissa (default: the first)")
    parser.add_argument("--from", dest="start", type=float, default=0.0, metavar="RPM", help="lowest speed, rpm (0)")
    parser.add_argument("--to", dest="stop", type=float, metavar="RPM",
                        help="highest speed, rpm (default 1.25 x the rotor's speed in the case)")
    parser.add_argument("--points", type=int, default=200, help="speeds, evenly spaced (200)")
    parser.add_argument("--orders", default="1", metavar="1,2", help="engine orders drawn for every rotor (1)")
    parser.add_argument("--up-to", dest="upper", type=positive, metavar="HZ",
                        help="highest frequency shown, Hz (default: the top of the highest order line)")
    parser.add_argument("--operating", metavar="LOW:HIGH", help="the rotor's operating range, rpm: shaded")
    parser.add_argument("--rigid", action="store_true", help="make every link rigid")
    parser.add_argument("--plot", metavar="OUT.png", help="write the diagram as PNG")
    parser.add_argument("--csv", metavar="OUT.csv", help="write the branches (speed, frequency, damping, whirl)")
    parser.add_argument("--json", action="store_true", help="print everything as JSON instead of tables")
    return run


def _numbers(text: str, option: str, separator: str) -> tuple[float, ...]:
    try:
        return tuple(float(part) for part in text.split(separator))
    except ValueError:
        raise UsageError(f"{option} {text!r}: expected numbers separated by {separator!r}") from None


def run(args) -> int:
    from workbook.answers.saving import save_csv, save_figure
    from workbook.model.reference import reference_case
    from workbook.solve.campbell import WHIRL, campbell

    for option, path, suffix in (("--plot", args.plot, ".png"), ("--csv", args.csv, ".csv")):
        check_output(option, path, (suffix,), [args.case])
    orders = _numbers(args.orders, "--orders", ",")
    operating = None
    if args.operating:
        bounds = _numbers(args.operating, "--operating", ":")
        if len(bounds) != 2 or not 0 <= bounds[0] < bounds[1]:
            raise UsageError(f"--operating {args.operating!r}: expected LOW:HIGH rpm with 0 <= LOW < HIGH")
        operating = (bounds[0], bounds[1])
    case = load_case(args.case, run=args.run, rigid=args.rigid) if args.case else reference_case(rotors=True)
    if args.rigid and not args.case:
        case = case.with_rigid_links()
    diagram = campbell(case, rotor=args.rotor, start_rpm=args.start, stop_rpm=args.stop, points=args.points,
                       orders=orders, upper_hz=args.upper, operating_rpm=operating)
    figure = diagram.plot() if args.plot else None
    if args.json:
        print(json.dumps(diagram.to_dict(), indent=1))
    else:
        speeds = diagram.speeds_rpm
        print(f"{case.name}: Campbell diagram, {diagram.reference.name} from {speeds[0]:g} to {speeds[-1]:g} rpm "
              f"({len(speeds)} speeds); rotors: "
              + ", ".join(f"{r.name} {60 * r.frequency_hz:g} rpm in the case"
                          + ("" if r.gyroscopic else " (no gyroscopic moment)") for r in diagram.rotors))
        print("\ncritical speeds (a mode on an engine-order line):")
        crossings = diagram.crossings_frame()
        print(crossings.to_string(index=False, float_format=lambda v: f"{v:.4g}") if len(crossings) else "  none")
        print("\nbranches (frequency at the lowest and highest speed):")
        for b, motion in enumerate(diagram.descriptions):
            f = diagram.frequencies_hz[b]
            print(f"  {b:3d}  {f[0]:9.3f} -> {f[-1]:9.3f} Hz  {diagram.branch_whirl(b):8s}  {motion}")
        truncation, timings = diagram.truncation, diagram.timings
        basis = ("the full model" if truncation["basis Hz"] is None else
                 f"{truncation['basis modes']} non-rotating modes up to {truncation['basis Hz']:.0f} Hz (at the top "
                 f"speed {100 * truncation['largest frequency error']:.1g} % from the full model)")
        print(f"\nsolved on {basis}, {diagram.coordinates} independent coordinates; "
              + ", ".join(f"{stage} {seconds:.2f} s" for stage, seconds in timings.items()))
        if any(WHIRL[int(w)] == "backward" for w in diagram.whirl.ravel()):
            print("\nAn imbalance (1x, forward) excites mainly the forward-whirl modes; backward-whirl crossings "
                  "matter for asymmetric mounts.")
    # where each file went goes to stderr with --json, so that stdout stays one JSON document
    with contextlib.redirect_stdout(sys.stderr) if args.json else contextlib.nullcontext():
        if args.csv:
            write_output(args.csv, "branches table", "campbell", lambda target: save_csv(diagram.to_pandas(), target,
                                                                                        index=False))
        if figure is not None:
            write_output(args.plot, "plot", "campbell", lambda target: save_figure(figure, target, dpi=120))
    return 0
