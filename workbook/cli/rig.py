"""``mountwb rig``: measured rig records against simulation.

A record is a CSV (:mod:`workbook.rig.records`) or UFF dataset 58 time
histories (``.uff``, ``.unv``; :mod:`workbook.rig.uff`).

A lab's CSV with its own channel names is read with ``--map MAP.json``
(:mod:`workbook.rig.channel_map`).

- ``mountwb rig measure RECORD.csv [--map MAP.json] [--periods N] [--at-nominal]``: measured T
  and eta per direction of a rig record (DFT at the spectral peak next to
  the nominal rotor frequency, or at the nominal one);
- ``mountwb rig compare RECORD.csv [CASE] [--rigid] [--periods N] [--csv OUT.csv]``:
  simulate the record's run of the case (default: the reference mount) and
  print the validation table, error = (sim - test) / test x 100 %;
- ``mountwb rig plot RECORD.csv [--map MAP.json] [--case [CASE]] [--rigid] --output OUT.png``:
  time histories and amplitude spectra of every channel
  (:mod:`workbook.rig.plots`); with ``--case``, measured against simulated T;
- ``mountwb rig synthesize OUT.csv [CASE] [--run NAME] [--rigid] [--noise F]
  [--drift F] [--seed N] [--rate HZ] [--duration S]``: a synthetic record
  made from a simulation (:mod:`workbook.rig.synthetic`).

A bad record exits with code 2 and a message naming file, line and column.
"""
from __future__ import annotations

import argparse
import dataclasses
from typing import TYPE_CHECKING, Callable

from workbook.answers.results import ExcitationResult
from workbook.answers.saving import save_csv
from workbook.cli.loading import load_case
from workbook.cli.outputs import check_output, write_output
from workbook.errors import UsageError
from workbook.model.case import AnalysisSettings, Case

if TYPE_CHECKING:
    from workbook.rig.records import RigRecord

__all__ = ["arguments", "simulate_run", "read_any_record"]

_DEFAULT_PERIODS = AnalysisSettings().measured_periods


def simulate_run(case: Case, run: str, *, histories: bool = False) -> ExcitationResult:
    """Simulate the excitation named *run* of *case*.

    Parameters
    ----------
    case : Case
    run : str
        Name of a single-frequency excitation of *case* (a sweep point
        included).
    histories : bool
        True: in the time domain, with force histories (for a synthetic
        record); False: by the method the case asks for.

    Returns
    -------
    ExcitationResult

    Raises
    ------
    UsageError
        No excitation of that name.
    """
    from workbook.solve.pipeline import run_case, run_excitation

    excitations = {e.name: e for e in case.single_frequency_excitations()}
    if run not in excitations:
        raise UsageError(f"case {case.name!r} has no excitation {run!r}; it has {', '.join(excitations)}")
    if histories:
        return run_excitation(case, excitations[run])[0]
    return run_case(dataclasses.replace(case, excitations=(excitations[run],))).runs[0]


def read_any_record(path: str, channel_map: str | None = None) -> RigRecord:
    """The rig record at *path*: the package's CSV, a UFF file, or with *channel_map* a lab's CSV.

    Raises
    ------
    RecordError
        A record (or map) that cannot be used.
    """
    from workbook.rig.channel_map import read_mapped_record
    from workbook.rig.records import read_record

    return read_record(path) if channel_map is None else read_mapped_record(path, channel_map)


def arguments(parser: argparse.ArgumentParser) -> Callable:
    modes = parser.add_subparsers(dest="mode", required=True)
    measure = modes.add_parser("measure", help="measured T and eta per direction of a rig record")
    compare = modes.add_parser("compare", help="simulate the record's run and print the validation table")
    plot = modes.add_parser("plot", help="time histories and amplitude spectra of a rig record (PNG); with --case, "
                                         "measured against simulated T")
    for sub in (measure, compare, plot):
        sub.add_argument("record", help="rig record: CSV, or UFF dataset 58 time histories (.uff, .unv)")
        sub.add_argument("--periods", type=int, default=_DEFAULT_PERIODS,
                         help=f"whole rotor periods per window (default {_DEFAULT_PERIODS})")
        sub.add_argument("--map", metavar="MAP.json",
                         help="channel map of a lab's CSV: channel -> sensor, direction, unit, sign (docs/rig-correlation.md)")
        sub.add_argument("--at-nominal", action="store_true",
                         help="DFT at the nominal rotor frequency, not at the spectral peak next to it")
    compare.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    plot.add_argument("--case", nargs="?", const="", metavar="CASE",
                      help="also plot measured against simulated T of the record's run of this case (JSON or .xlsx "
                           "workbook; --case alone: the reference mount)")
    plot.add_argument("--output", required=True, metavar="OUT.png", help="PNG file to write")
    for sub in (compare, plot):
        sub.add_argument("--rigid", action="store_true", help="make every link rigid")
    compare.add_argument("--csv", metavar="OUT.csv", help="also write the validation table")
    synthesize = modes.add_parser("synthesize", help="write a synthetic rig record made from a simulation")
    synthesize.add_argument("output", help="record to write: CSV, or UFF dataset 58 (.uff, .unv)")
    synthesize.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    synthesize.add_argument("--run", default="LP rotor", help="excitation to simulate (default 'LP rotor')")
    synthesize.add_argument("--rigid", action="store_true", help="make every link rigid")
    synthesize.add_argument("--noise", type=float, default=0.005, help="noise / transducer amplitude (0.005)")
    synthesize.add_argument("--drift", type=float, default=0.002, help="relative speed drift (0.002)")
    synthesize.add_argument("--seed", type=int, default=0, help="noise seed (0)")
    synthesize.add_argument("--rate", type=float, default=None,
                            help="sample rate, Hz (default: the power of two that samples the case's highest rotor "
                                 "frequency at least 12.5 times a period; 4096 for the reference mount)")
    synthesize.add_argument("--duration", type=float, default=4.0, help="record length, s (4)")

    def rig(args) -> int:
        if args.mode == "synthesize":
            return _synthesize(args)
        from workbook.rig.correlation import PEAK_SEARCH, comparison_frame, measure

        inputs = [args.record, args.map, getattr(args, "case", None) or None]
        check_output("--csv", getattr(args, "csv", None), (".csv",), inputs)
        check_output("--output", getattr(args, "output", None), (".png",), inputs)
        record = read_any_record(args.record, args.map)
        compared = args.mode == "compare" or (args.mode == "plot" and args.case is not None)
        if compared:
            case = load_case(args.case or None, rigid=args.rigid)
            record.check_hinges([h.name for h in case.pylon_hinges])
        elif args.mode == "plot":
            return _plot(args, record, None)
        measurement = measure(record, args.periods, search=0.0 if args.at_nominal else PEAK_SEARCH)
        print(f"{record.path}: run {record.run!r}, rotor at {measurement.frequency_hz:.4f} Hz (nominal "
              f"{measurement.nominal_hz:g} Hz), |F_exc| {measurement.excitation_amplitude:.1f} N, "
              f"{args.periods}-period windows differ by {100 * measurement.steady_change:.2f} %\n")
        if args.mode == "measure":
            for axis, t, eta in zip("xyz", measurement.transmissibility, measurement.efficiency, strict=True):
                print(f"{axis}: T {t:.5f}  eta {eta:7.3f} %")
            return 0
        table = comparison_frame(measurement, simulate_run(case, record.run))
        print(table.to_string(float_format=lambda v: f"{v:10.5g}"))
        if args.mode == "plot":
            return _plot(args, record, table)
        if args.csv:
            write_output(args.csv, "validation table", "rig", lambda target: save_csv(table, target))
        return 0

    return rig


def _plot(args, record: RigRecord, table) -> int:
    import matplotlib

    matplotlib.use("Agg")
    from workbook.answers.saving import save_figure
    from workbook.rig.plots import plot_record

    figure = plot_record(record, table)
    write_output(args.output, "rig record plot", "rig", lambda target: save_figure(figure, target))
    return 0


def _synthesize(args) -> int:
    from workbook.rig.records import write_record
    from workbook.rig.synthetic import REFERENCE_TRANSDUCERS, default_sample_rate, synthetic_record
    from workbook.rig.uff import UFF_SUFFIXES

    check_output("output", args.output, (".csv", *UFF_SUFFIXES), [args.case])
    case = load_case(args.case, rigid=args.rigid)
    result = simulate_run(case, args.run, histories=True)
    pylon = sorted(h.name for h in case.pylon_hinges)
    reference = sorted(h for hinges in REFERENCE_TRANSDUCERS.values() for h in hinges)
    # the seed study's rig on the reference mount, else one transducer per pylon-side hinge
    transducers = REFERENCE_TRANSDUCERS if pylon == reference else {name: (name,) for name in pylon}
    # a record of any run of the case can be compared (MIN_SAMPLES_PER_PERIOD at its highest frequency)
    rate = args.rate if args.rate is not None else default_sample_rate(e.frequency_hz for e in case.single_frequency_excitations())
    record = synthetic_record(result, transducers, sample_rate_hz=rate, duration=args.duration,
                              noise=args.noise, drift=args.drift, seed=args.seed)
    write_output(args.output, "rig record", "rig", lambda target: write_record(target, record))
    return 0
