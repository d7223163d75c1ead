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
  made from a simulation (:mod:`workbook.rig.synthetic`);
- ``mountwb rig frf RECORD [--map MAP.json] [--segment S] [--band LOW HIGH] [--case [CASE]] [--rigid]
  [--run NAME] [--points N] [--output OUT.png] [--json]``: H1 of the pylon force per unit
  excitation per direction with coherence, its peaks, and with ``--case`` the
  simulated sweep of the run (:mod:`workbook.rig.frf`);
- ``mountwb rig order RECORD [--map MAP.json] [--frame S] [--case [CASE]] [--rigid] [--run NAME]
  [--points N] [--output OUT.png] [--json]``: the 1x order track of a run-up
  record against the rotor frequency, and the simulated T of the run;
- ``mountwb rig modes [CASE] (--test MODES.uff | --record RECORD) [--rigid] [--upper HZ]
  [--output MAC.png] [--csv OUT.csv] [--json]``: the case's mounted modes against
  test modes (UFF 55 + 15, or peaks of a record's H1): frequency errors and
  the MAC matrix (:mod:`workbook.rig.modal`).

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
from workbook.cli.params import at_least_one, not_negative, positive
from workbook.errors import UsageError
from workbook.model.case import AnalysisSettings, Case

if TYPE_CHECKING:
    from workbook.rig.records import RigRecord

__all__ = ["arguments", "simulate_run", "simulated_transmissibility", "read_any_record"]

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

    excitation = _excitation(case, run)
    if histories:
        return run_excitation(case, excitation)
    return run_case(dataclasses.replace(case, excitations=(excitation,))).runs[0]


def _excitation(case: Case, run: str):
    """The single-frequency excitation named *run* of *case* (UsageError naming those it has)."""
    excitations = {e.name: e for e in case.single_frequency_excitations()}
    if run not in excitations:
        raise UsageError(f"case {case.name!r} has no excitation {run!r}; it has {', '.join(excitations)} "
                         "(--run NAME)")
    return excitations[run]


def simulated_transmissibility(case: Case, run: str, low_hz: float, high_hz: float, points: int):
    """T per direction of a simulated sweep of the excitation *run* of *case* over a band.

    Parameters
    ----------
    case : Case
    run : str
        A single-frequency excitation of *case*: the sweep's template.
    low_hz, high_hz : float
        Band, Hz.
    points : int
        Frequencies, evenly spaced.

    Returns
    -------
    frequencies : ndarray, shape (points,)
        Hz.
    transmissibility : ndarray, shape (points, 3)

    Raises
    ------
    UsageError
        No excitation of that name.
    """
    from workbook.model.case import Sweep
    from workbook.solve.sweep import run_sweep

    sweep = Sweep.band(f"{run} sweep", _excitation(case, run), max(low_hz, 0.1), high_hz, points, "linear")
    answer = run_sweep(dataclasses.replace(case, excitations=(sweep,)), sweep)
    return answer.frequencies, answer.transmissibility()


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
        sub.add_argument("--periods", type=at_least_one, default=_DEFAULT_PERIODS,
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
    synthesize.add_argument("--noise", type=not_negative, default=0.005, help="noise / transducer amplitude (0.005)")
    synthesize.add_argument("--drift", type=float, default=0.002, help="relative speed drift (0.002)")
    synthesize.add_argument("--seed", type=int, default=0, help="noise seed (0)")
    synthesize.add_argument("--rate", type=positive, default=None,
                            help="sample rate, Hz (default: the power of two that samples the case's highest rotor "
                                 "frequency at least 12.5 times a period; 4096 for the reference mount)")
    synthesize.add_argument("--duration", type=positive, default=4.0, help="record length, s (4)")

    _correlation_arguments(modes)

    def rig(args) -> int:
        if args.mode == "synthesize":
            return _synthesize(args)
        if args.mode in ("frf", "order"):
            return _frf_or_order(args)
        if args.mode == "modes":
            return _modes(args)
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
    from workbook.rig.correlation import MIN_SAMPLES_PER_PERIOD
    from workbook.rig.records import write_record
    from workbook.rig.synthetic import REFERENCE_TRANSDUCERS, default_sample_rate, synthetic_record
    from workbook.rig.uff import UFF_SUFFIXES

    check_output("output", args.output, (".csv", *UFF_SUFFIXES), [args.case])
    case = load_case(args.case, rigid=args.rigid)
    # a record of any run of the case can be compared (MIN_SAMPLES_PER_PERIOD at its highest frequency)
    rate = args.rate if args.rate is not None else default_sample_rate(e.frequency_hz for e in case.single_frequency_excitations())
    frequency = _excitation(case, args.run).frequency_hz
    if rate < MIN_SAMPLES_PER_PERIOD * frequency:
        raise UsageError(f"--rate {rate:g}: {rate / frequency:.3g} samples per period of {args.run!r} at "
                         f"{frequency:g} Hz; a record needs at least {MIN_SAMPLES_PER_PERIOD} (a rate of "
                         f"{MIN_SAMPLES_PER_PERIOD * frequency:g} Hz or more)")
    result = simulate_run(case, args.run, histories=True)
    pylon = sorted(h.name for h in case.pylon_hinges)
    reference = sorted(h for hinges in REFERENCE_TRANSDUCERS.values() for h in hinges)
    # the seed study's rig on the reference mount, else one transducer per pylon-side hinge
    transducers = REFERENCE_TRANSDUCERS if pylon == reference else {name: (name,) for name in pylon}
    record = synthetic_record(result, transducers, sample_rate_hz=rate, duration=args.duration,
                              noise=args.noise, drift=args.drift, seed=args.seed)
    write_output(args.output, "rig record", "rig", lambda target: write_record(target, record))
    return 0


def _correlation_arguments(modes) -> None:
    frf = modes.add_parser("frf", help="H1 of the pylon force per unit excitation with coherence, per direction, "
                                       "of a broadband or swept record")
    order = modes.add_parser("order", help="1x order track of a run-up record against the rotor frequency")
    for sub in (frf, order):
        sub.add_argument("record", help="rig record: CSV, or UFF dataset 58 time histories (.uff, .unv)")
        sub.add_argument("--map", metavar="MAP.json", help="channel map of a lab's CSV (docs/rig-correlation.md)")
        sub.add_argument("--case", nargs="?", const="", metavar="CASE",
                         help="also simulate a sweep of the run over the band (JSON or .xlsx workbook; --case "
                              "alone: the reference mount)")
        sub.add_argument("--rigid", action="store_true", help="make every link rigid")
        sub.add_argument("--run", help="excitation of the case to sweep (default: the record's run)")
        sub.add_argument("--points", type=int, default=40, help="frequencies of the simulated sweep (40)")
        sub.add_argument("--output", metavar="OUT.png", help="also plot T (and coherence) to this PNG")
        sub.add_argument("--json", action="store_true", help="print the curves as JSON")
    frf.add_argument("--segment", type=positive, default=1.0, help="Welch segment, s: resolution 1/S Hz (1)")
    frf.add_argument("--band", type=float, nargs=2, metavar=("LOW", "HIGH"),
                     help="frequencies shown, Hz (default: 1/S up to 0.4 x the sample rate)")
    order.add_argument("--frame", type=positive, default=1.0, help="frame length, s (1); frames overlap by half")
    modal = modes.add_parser("modes", help="the case's mounted modes against test modes: frequency errors and MAC")
    modal.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    source = modal.add_mutually_exclusive_group(required=True)
    source.add_argument("--test", metavar="MODES.uff", help="test modes: UFF datasets 55 and 15 (node coordinates, m)")
    source.add_argument("--record", metavar="RECORD", help="identify test modes by peak picking on a record's H1")
    modal.add_argument("--map", metavar="MAP.json", help="channel map of the record (a lab's CSV)")
    modal.add_argument("--segment", type=positive, default=1.0, help="Welch segment of the record's H1, s (1)")
    modal.add_argument("--rigid", action="store_true", help="make every link rigid")
    modal.add_argument("--upper", type=positive, default=None,
                       help="highest frequency, Hz (default: 1.5 x the highest test mode)")
    modal.add_argument("--output", metavar="MAC.png", help="plot the MAC matrix (test modes with shapes)")
    modal.add_argument("--csv", metavar="OUT.csv", help="also write the pairing table")
    modal.add_argument("--json", action="store_true", help="print the pairing as JSON")


def _simulated(args, record: RigRecord, low: float, high: float):
    if args.case is None:
        return None
    case = load_case(args.case or None, rigid=args.rigid)
    return simulated_transmissibility(case, args.run or record.run, low, high, args.points)


def _curves(frequencies, values) -> dict:
    from workbook.model.case import DIRECTIONS

    return {"frequency_hz": [float(f) for f in frequencies],
            **{direction: [None if v != v else float(v) for v in values[:, i]] for i, direction in enumerate(DIRECTIONS)}}


def _frf_or_order(args) -> int:
    import json

    import numpy as np

    from workbook.model.case import DIRECTIONS
    from workbook.rig import frf as frfs

    check_output("--output", args.output, (".png",), [args.record, args.map, args.case or None])
    record = read_any_record(args.record, args.map)
    if args.mode == "frf":
        answer = frfs.record_frf(record, args.segment)
        low, high = args.band if args.band else (1.0 / answer.segment_s, 0.4 * record.sample_rate_hz)
        if low >= high:
            raise UsageError(f"--band {low:g} {high:g}: expected LOW < HIGH, Hz")
        shown = answer.band(low, high)
        if not shown.any():
            raise UsageError(f"--band {low:g} {high:g}: no frequency of the H1 in it; it has "
                             f"{answer.frequencies_hz[1]:g} to {answer.frequencies_hz[-1]:g} Hz")
        frequencies, measured = answer.frequencies_hz[shown], answer.transmissibility[shown]
    else:
        track = frfs.order_track(record, args.frame)
        frequencies, measured = track.frequency_hz, track.transmissibility
        low, high = float(frequencies.min()), float(frequencies.max())
    simulated = _simulated(args, record, low, high)
    errors = None
    if simulated is not None:
        interpolated = np.column_stack([np.interp(frequencies, simulated[0], simulated[1][:, a]) for a in range(3)])
        with np.errstate(divide="ignore", invalid="ignore"):
            errors = 100 * (interpolated - measured) / measured
    if args.json:
        output: dict = {"record": record.path, "run": record.run, "T": _curves(frequencies, measured)}
        if args.mode == "frf":
            output.update(segment_s=answer.segment_s, averages=answer.averages,
                          coherence=_curves(frequencies, answer.coherence[shown]))
        else:
            output.update(frame_s=track.frame_s, time_s=[float(t) for t in track.time_s],
                          excitation_N=[float(v) for v in track.excitation_amplitude],
                          pylon_N=_curves(frequencies, track.pylon_amplitude))
        if simulated is not None:
            output["simulated T"] = _curves(*simulated)
        print(json.dumps(output, indent=1))
    elif args.mode == "frf":
        coherence = answer.coherence[shown]
        print(f"{record.path}: run {record.run!r}, H1 of pylon force / excitation, {answer.averages} averages of "
              f"{answer.segment_s:g} s, {low:g} to {high:g} Hz")
        for axis, direction in enumerate(DIRECTIONS):
            if np.isnan(answer.h1[:, axis]).all():
                print(f"{direction}: not excited")
                continue
            line = f"{direction}: mean coherence {np.mean(coherence[:, axis]):.3f}, T max {np.nanmax(measured[:, axis]):.4g}"
            if errors is not None:
                good = coherence[:, axis] >= 0.8
                line += f", simulated - test: median |error| {np.nanmedian(np.abs(errors[good, axis])):.2f} % " \
                        f"where coherence >= 0.8"
            print(line)
        from workbook.rig.modal import identify_peaks

        peaks = identify_peaks(answer, low, high)
        for number, (f, zeta) in enumerate(zip(peaks.frequencies_hz, peaks.damping_ratios, strict=True), start=1):
            print(f"peak {number}: {f:.3f} Hz, half-power damping ratio {100 * zeta:.2f} %")
    else:
        print(f"{record.path}: run {record.run!r}, 1x order track, {len(frequencies)} frames of {track.frame_s:g} s")
        step = max(1, len(frequencies) // 20)
        for index in range(0, len(frequencies), step):
            t = "  ".join(f"T {d} {v:9.4g}" for d, v in zip(DIRECTIONS, measured[index], strict=True))
            extra = "" if errors is None else "  error % " + " ".join(f"{e:+7.2f}" for e in errors[index])
            print(f"{frequencies[index]:8.3f} Hz  |F_exc| {track.excitation_amplitude[index]:9.4g} N  {t}{extra}")
    if args.output:
        import matplotlib

        matplotlib.use("Agg")
        from workbook.answers.saving import save_figure

        figure = frfs.plot_frf(answer, simulated) if args.mode == "frf" else frfs.plot_order_track(track, simulated)
        write_output(args.output, "FRF plot" if args.mode == "frf" else "order track plot", "rig",
                     lambda target: save_figure(figure, target))
    return 0


def _modes(args) -> int:
    import json

    import numpy as np

    from workbook.rig import modal

    inputs = [args.test, args.record, args.map, args.case]
    check_output("--output", args.output, (".png",), inputs)
    check_output("--csv", args.csv, (".csv",), inputs)
    if args.test:
        test = modal.read_uff_modes(args.test)
    else:
        from workbook.rig.frf import record_frf

        record = read_any_record(args.record, args.map)
        frf = record_frf(record, args.segment)
        test = modal.identify_peaks(frf, 1.0 / frf.segment_s, 0.4 * record.sample_rate_hz)
        if not len(test.frequencies_hz):
            raise UsageError(f"{args.record}: no peak in the record's H1 to pair (coherence >= 0.8)")
    if args.output and test.shapes is None:
        raise UsageError("--output draws the MAC matrix: it needs test shapes (--test MODES.uff)")
    case = load_case(args.case, rigid=args.rigid)
    upper = args.upper if args.upper is not None else 1.5 * float(np.max(test.frequencies_hz))
    simulated = modal.case_modes(case, upper)
    if not simulated:
        raise UsageError(f"case {case.name!r} has no mounted mode up to {upper:g} Hz (--upper)")
    shapes = None
    if test.shapes is not None:
        shapes = modal.shapes_at_points(np.array([m.engine_shape for m in simulated]), np.array(case.engine.center_of_mass),
                                        test.points, test.dofs)
    pairing = modal.pair_modes(test, np.array([m.frequency_hz for m in simulated]), shapes)
    table = pairing.to_pandas()
    table["sim motion"] = [simulated[j - 1].description for j in table["sim mode"]]
    if args.json:
        print(json.dumps({"test": test.source, "pairs": json.loads(table.reset_index().to_json(orient="records")),
                          "MAC": None if pairing.mac is None else pairing.mac.round(4).tolist()}, indent=1))
    else:
        print(f"{test.source}: {len(test.frequencies_hz)} test modes, {len(simulated)} mounted modes of "
              f"{case.name!r} up to {upper:g} Hz; error = (sim - test) / test x 100 %")
        print(table.to_string(float_format=lambda v: f"{v:9.4g}"))
    if args.csv:
        write_output(args.csv, "mode pairing", "rig", lambda target: save_csv(table, target))
    if args.output:
        import matplotlib

        matplotlib.use("Agg")
        from workbook.answers.saving import save_figure

        figure = modal.plot_mac(pairing)
        write_output(args.output, "MAC plot", "rig", lambda target: save_figure(figure, target))
    return 0
