"""``mountwb four-pole [CASE] [--from HZ --to HZ --points N] [--csv OUT] [--plot OUT.png] [--xlsx OUT]``.

The mount's four-pole parameters against frequency (driving-point and
blocked transfer dynamic stiffness per direction, see
:mod:`workbook.solve.four_pole`), and the rigid-pylon transmissibility of
each of the case's excitations that follows from them; with a pylon point
stiffness per pin (``--pylon-stiffness``, ``--pylon-mass``) the insertion loss
of the mount on that pylon. Everything is computed before a file is written;
an existing file is kept (the new one gets a new name) unless it is a
workbook this command wrote and nobody changed (:mod:`workbook.cli.outputs`).
"""
from __future__ import annotations

import argparse
from typing import Callable

from workbook.answers.saving import save_csv, save_figure
from workbook.cli.loading import load_case
from workbook.cli.outputs import check_output, write_output
from workbook.errors import UsageError
from workbook.solve.four_pole import REPORT_GRID

__all__ = ["arguments"]


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("--from", dest="start", type=float, default=REPORT_GRID[0], metavar="HZ",
                        help=f"lowest frequency, Hz (default {REPORT_GRID[0]:g})")
    parser.add_argument("--to", dest="stop", type=float, default=REPORT_GRID[1], metavar="HZ",
                        help=f"highest frequency, Hz (default {REPORT_GRID[1]:g})")
    parser.add_argument("--points", type=int, default=REPORT_GRID[2],
                        help=f"frequencies, log-spaced (default {REPORT_GRID[2]})")
    parser.add_argument("--rigid", action="store_true", help="make every link rigid")
    parser.add_argument("--csv", metavar="OUT.csv", help="write the table as CSV")
    parser.add_argument("--plot", metavar="OUT.png", help="write the magnitude plot as PNG")
    parser.add_argument("--xlsx", metavar="OUT.xlsx", help="write the table and a native chart as a workbook (.xlsx)")
    parser.add_argument("--pylon-stiffness", type=float, metavar="N/M",
                        help="pylon point stiffness at each pin in x, y and z, N/m: print the insertion loss")
    parser.add_argument("--pylon-mass", type=float, default=0.0, metavar="KG",
                        help="pylon mass at each pin, kg (point dynamic stiffness k - w^2 m; default 0)")
    return run


def run(args) -> int:
    import numpy as np

    from workbook.model.case import DIRECTIONS
    from workbook.solve.four_pole import QUANTITIES, frequency_grid
    from workbook.solve.harmonic import excitation_phasor
    from workbook.solve.pipeline import four_pole

    for option, path, suffix in (("--csv", args.csv, ".csv"), ("--plot", args.plot, ".png"),
                                 ("--xlsx", args.xlsx, ".xlsx")):
        check_output(option, path, (suffix,), [args.case])
    frequencies = frequency_grid(args.start, args.stop, args.points)
    pylon = _pylon(args, frequencies)
    case = load_case(args.case, rigid=args.rigid)
    pole = four_pole(case, frequencies)
    table = pole.to_pandas()
    # the force shape of each excitation at one point (imbalances of several planes have none)
    rigid = {x.name: pole.transmissibility(excitation_phasor(x), x.point_forces()[0][0])
             for x in case.single_frequency_excitations() if len(x.point_forces()) == 1}
    loss = None if pylon is None else pole.insertion_loss(pylon)
    figure = pole.plot() if args.plot else None
    print(f"{case.name}: four-pole parameters of the mount, engine (centre of gravity) to {len(pole.pins)} pylon "
          f"pins, about the preloaded equilibrium")
    for quantity, meaning in QUANTITIES.items():
        print(f"  {quantity}: {meaning}")
    print()
    print(table.to_string(float_format=lambda v: f"{v:10.4g}"))
    for name, values in rigid.items():
        print(f"\nrigid pylon, force shape of {name!r}: T = |F_pylon| / |F| from K11, K21 and the engine")
        print("frequency Hz  " + "  ".join(f"T {axis:<7}" for axis in DIRECTIONS))
        for frequency, row in zip(frequencies, values, strict=True):
            print(f"{frequency:12.4g}  " + "  ".join(f"{v:9.4g}" for v in np.asarray(row)))
    if loss is not None:
        print(f"\ninsertion loss on a pylon of {args.pylon_stiffness:g} N/m and {args.pylon_mass:g} kg per pin "
              f"(unit force at the centre of gravity; 20 log10 |F_bolted| / |F_mount|, dB)")
        print("frequency Hz  " + "  ".join(f"IL {axis} dB " for axis in DIRECTIONS))
        for frequency, row in zip(frequencies, loss, strict=True):
            print(f"{frequency:12.4g}  " + "  ".join(f"{v:9.2f}" for v in row))
    if args.csv:
        write_output(args.csv, "table", "four-pole", lambda target: save_csv(table, target))
    if figure is not None:
        write_output(args.plot, "plot", "four-pole", lambda target: save_figure(figure, target, dpi=120))
    if args.xlsx:
        from openpyxl import Workbook

        from workbook.excel.files import save_atomic, signed, untouched
        from workbook.excel.report import FOUR_POLE_SHEET, four_pole_sheet

        book = Workbook()
        book.active.title = FOUR_POLE_SHEET
        four_pole_sheet(book.active, pole)
        write_output(args.xlsx, "workbook", "four-pole",
                     lambda target: save_atomic(book, target, finish=lambda data: signed(data, "four-pole")),
                     replaceable=lambda existing: untouched(existing, "four-pole"))
    return 0


def _pylon(args, frequencies):
    """The pylon point dynamic stiffness per frequency (N/m), or None."""
    import numpy as np

    if args.pylon_stiffness is None:
        if args.pylon_mass:
            raise UsageError("--pylon-mass needs --pylon-stiffness (the pylon's point stiffness per pin, N/m)")
        return None
    if not (np.isfinite(args.pylon_stiffness) and args.pylon_stiffness > 0):
        raise UsageError(f"--pylon-stiffness: found {args.pylon_stiffness:g}, expected a stiffness > 0 N/m")
    if not (np.isfinite(args.pylon_mass) and args.pylon_mass >= 0):
        raise UsageError(f"--pylon-mass: found {args.pylon_mass:g}, expected a mass >= 0 kg")
    return args.pylon_stiffness - (2 * np.pi * frequencies) ** 2 * args.pylon_mass
