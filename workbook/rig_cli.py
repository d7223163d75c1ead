"""``mountwb rig``: measured rig records against simulation.

- ``mountwb rig measure RECORD.csv [--periods N] [--at-nominal]``: measured T
  and eta per direction of a rig record (DFT at the spectral peak next to
  the nominal rotor frequency, or at the nominal one);
- ``mountwb rig compare RECORD.csv [CASE] [--rigid] [--periods N] [--csv OUT.csv]``:
  simulate the record's run of the case (default: the reference mount) and
  print the validation table, error = (sim - test) / test x 100 %;
- ``mountwb rig synthesize OUT.csv [CASE] [--run NAME] [--rigid] [--noise F]
  [--drift F] [--seed N] [--rate HZ] [--duration S]``: a synthetic record
  made from a simulation (:mod:`workbook.synthetic_rig`).

A bad record exits with code 2 and a message naming file, line and column.
"""
from __future__ import annotations

import argparse
from typing import Callable

from .case import AnalysisSettings

__all__ = ["rig_arguments", "simulate_run"]

_DEFAULT_PERIODS = AnalysisSettings().measured_periods


def simulate_run(case, run: str):
    """Simulate the excitation named *run* of *case* (time domain).

    Returns
    -------
    ExcitationResult

    Raises
    ------
    ValueError
        No excitation of that name.
    """
    from .runner import run_excitation

    excitations = {e.name: e for e in case.single_frequency_excitations()}
    if run not in excitations:
        raise ValueError(f"case {case.name!r} has no excitation {run!r}; it has {', '.join(excitations)}")
    return run_excitation(case, excitations[run])[0]


def _case(path, rigid: bool):
    from .cli import _load_case

    return _load_case(path, rigid)


def rig_arguments(parser: argparse.ArgumentParser) -> Callable:
    modes = parser.add_subparsers(dest="mode", required=True)
    measure = modes.add_parser("measure", help="measured T and eta per direction of a rig record")
    compare = modes.add_parser("compare", help="simulate the record's run and print the validation table")
    for sub in (measure, compare):
        sub.add_argument("record", help="rig record (CSV)")
        sub.add_argument("--periods", type=int, default=_DEFAULT_PERIODS,
                         help=f"whole rotor periods per window (default {_DEFAULT_PERIODS})")
        sub.add_argument("--at-nominal", action="store_true",
                         help="DFT at the nominal rotor frequency, not at the spectral peak next to it")
    compare.add_argument("case", nargs="?", help="case file (JSON); default: the reference mount")
    compare.add_argument("--rigid", action="store_true", help="make every link rigid")
    compare.add_argument("--csv", metavar="OUT.csv", help="also write the validation table")
    synthesize = modes.add_parser("synthesize", help="write a synthetic rig record made from a simulation")
    synthesize.add_argument("output", help="record to write (CSV)")
    synthesize.add_argument("case", nargs="?", help="case file (JSON); default: the reference mount")
    synthesize.add_argument("--run", default="LP rotor", help="excitation to simulate (default 'LP rotor')")
    synthesize.add_argument("--rigid", action="store_true", help="make every link rigid")
    synthesize.add_argument("--noise", type=float, default=0.005, help="noise / transducer amplitude (0.005)")
    synthesize.add_argument("--drift", type=float, default=0.002, help="relative speed drift (0.002)")
    synthesize.add_argument("--seed", type=int, default=0, help="noise seed (0)")
    synthesize.add_argument("--rate", type=float, default=2048.0, help="sample rate, Hz (2048)")
    synthesize.add_argument("--duration", type=float, default=4.0, help="record length, s (4)")

    def rig(args) -> int:
        if args.mode == "synthesize":
            return _synthesize(args)
        from .correlation import PEAK_SEARCH, comparison_frame, measure
        from .rig import read_record

        record = read_record(args.record)
        if args.mode == "compare":
            case = _case(args.case, args.rigid)
            record.check_hinges([h.name for h in case.pylon_hinges])
        measurement = measure(record, args.periods, search=0.0 if args.at_nominal else PEAK_SEARCH)
        print(f"{record.path}: run {record.run!r}, rotor at {measurement.frequency_hz:.4f} Hz (nominal "
              f"{measurement.nominal_hz:g} Hz), |F_exc| {measurement.excitation_amplitude:.1f} N, "
              f"{args.periods}-period windows differ by {100 * measurement.steady_change:.2f} %\n")
        if args.mode == "measure":
            for axis, t, eta in zip("xyz", measurement.transmissibility, measurement.efficiency):
                print(f"{axis}: T {t:.5f}  eta {eta:7.3f} %")
            return 0
        table = comparison_frame(measurement, simulate_run(case, record.run))
        print(table.to_string(float_format=lambda v: f"{v:10.5g}"))
        if args.csv:
            table.to_csv(args.csv)
            print(args.csv)
        return 0

    return rig


def _synthesize(args) -> int:
    from .rig import write_record
    from .synthetic_rig import REFERENCE_TRANSDUCERS, synthetic_record

    case = _case(args.case, args.rigid)
    result = simulate_run(case, args.run)
    pylon = sorted(h.name for h in case.pylon_hinges)
    reference = sorted(h for hinges in REFERENCE_TRANSDUCERS.values() for h in hinges)
    # the seed study's rig on the reference mount, else one transducer per pylon-side hinge
    transducers = REFERENCE_TRANSDUCERS if pylon == reference else {name: (name,) for name in pylon}
    record = synthetic_record(result, transducers, sample_rate_hz=args.rate, duration=args.duration,
                              noise=args.noise, drift=args.drift, seed=args.seed)
    print(write_record(args.output, record))
    return 0
