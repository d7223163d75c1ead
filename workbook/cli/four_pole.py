"""``mountwb four-pole [CASE] [--from HZ --to HZ --points N] [--csv OUT] [--plot OUT.png]``.

The mount's four-pole parameters against frequency (driving-point and
blocked transfer dynamic stiffness per direction, see
:mod:`workbook.answers.four_pole`), and the rigid-pylon transmissibility of
each of the case's excitations that follows from them. Everything is
computed before a file is written.
"""
from __future__ import annotations

import argparse
from typing import Callable

from workbook.cli.loading import load_case

__all__ = ["arguments"]


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("--from", dest="start", type=float, default=10.0, metavar="HZ",
                        help="lowest frequency, Hz (default 10)")
    parser.add_argument("--to", dest="stop", type=float, default=500.0, metavar="HZ",
                        help="highest frequency, Hz (default 500)")
    parser.add_argument("--points", type=int, default=41, help="frequencies, log-spaced (default 41)")
    parser.add_argument("--rigid", action="store_true", help="make every link rigid")
    parser.add_argument("--csv", metavar="OUT", help="write the table as CSV")
    parser.add_argument("--plot", metavar="OUT.png", help="write the magnitude plot as PNG")
    return run


def run(args) -> int:
    import numpy as np

    from workbook.answers.four_pole import QUANTITIES, four_pole, frequency_grid
    from workbook.model.case import DIRECTIONS
    from workbook.solve.harmonic import excitation_phasor

    frequencies = frequency_grid(args.start, args.stop, args.points)
    case = load_case(args.case, rigid=args.rigid)
    pole = four_pole(case, frequencies)
    table = pole.table()
    rigid = {x.name: pole.transmissibility(excitation_phasor(x), x.point) for x in case.single_frequency_excitations()}
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
        for frequency, row in zip(frequencies, values):
            print(f"{frequency:12.4g}  " + "  ".join(f"{v:9.4g}" for v in np.asarray(row)))
    if args.csv:
        table.to_csv(args.csv)
    if figure is not None:
        figure.savefig(args.plot, dpi=120)
    return 0
