"""Model updating on the fast path: 3 and 6 parameters fitted to both rotors' records.

The reference mount with test-rig transducers of 1e8 N/m (links flexible as
the case asks, or ``--rigid``) is the nominal model; the rig is the same
mount with its front hinges 30 % stiffer and transducers of 4e7 N/m,
answered by the Exudyn pipeline, recorded twice per rotor with 0.5 %
transducer noise (:func:`workbook.rig.synthetic.synthetic_record`). The linear
mount is prepared once (timed apart); each fit
(:func:`workbook.rig.updating.update_model`, its screening and starts as by
default) is timed ``--repeats`` times, the median printed with the
evaluations, and whether each parameter's truth lies within two standard
errors. First, the records' own error: ln(T measured / T simulated), %, of
records made without noise (with the default speed drift and without) and
the mean and standard deviation over ``--seeds`` noisy ones, per run and
direction: the bias of the measurement against its scatter. Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_updating.py [--rigid] [--repeats 3] [--seeds 20]
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from workbook.design.linear_mount import LinearMount  # noqa: E402
from workbook.model.case import ForceTransducers  # noqa: E402
from workbook.model.reference import reference_case  # noqa: E402
from workbook.rig.synthetic import REFERENCE_TRANSDUCERS, default_sample_rate, synthetic_record, synthetic_records  # noqa: E402
from workbook.rig.updating import update_model  # noqa: E402
from workbook.solve.pipeline import run_case  # noqa: E402
from workbook.studies.parametric import parameter  # noqa: E402

#: The rig's values that the nominal model lacks.
TRUTH = {"hinge_stiffness/front": 1.3 * 2e7, "transducer_stiffness": 4e7}
#: The parameters fitted, the first three or all six.
BOUNDS = {"hinge_stiffness/front": (5e6, 1e8), "hinge_stiffness/rear": (5e6, 1e8),
          "transducer_stiffness": (1e7, 1e9), "hinge_stiffness/thrust": (5e6, 1e8),
          "hinge_loss_factor": (0.01, 0.2), "engine_mass": (3000.0, 4200.0)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rigid", action="store_true", help="rigid links (default: as the case asks)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seeds", type=int, default=20,
                        help="noisy records per run for the measurement's scatter (0: no measurement table)")
    args = parser.parse_args()
    base = reference_case()
    nominal = dataclasses.replace(base.with_rigid_links() if args.rigid else base, test_rig=ForceTransducers((1e8,) * 3))
    truth = nominal
    for name, value in TRUTH.items():
        truth = parameter(name).apply(truth, value)
    result = run_case(truth)
    records = synthetic_records(truth, result, (3, 4), noise=0.005)
    if args.seeds:
        rate = default_sample_rate(e.frequency_hz for e in truth.excitations)
        measurement_error(result, truth, rate, nominal.analysis.measured_periods, args.seeds)
    start = time.perf_counter()
    mount = LinearMount.prepare(nominal)
    print(f"links {'rigid' if args.rigid else 'as the case asks'}; linear mount prepared in "
          f"{time.perf_counter() - start:.1f} s; load {os.getloadavg()[0]:.2f}")
    print(f"{'parameters':>10} {'median s':>9} {'evaluations':>11}  within 2 SE")
    for count in (3, 6):
        bounds = dict(list(BOUNDS.items())[:count])
        seconds, fit = [], None
        for _ in range(args.repeats):
            fit = update_model(nominal, records, bounds, mount=mount)
            seconds.append(fit.seconds)
        assert fit is not None
        expected = np.array([TRUTH.get(name, nominal_value(nominal, name)) for name in fit.parameters])
        within = np.abs(fit.values - expected) <= 2 * fit.standard_errors
        print(f"{count:>10} {statistics.median(seconds):>9.2f} {fit.evaluations:>11}  "
              + " ".join(f"{name}={'yes' if ok else 'no'}" for name, ok in zip(fit.parameters, within, strict=True)))
    print(f"load {os.getloadavg()[0]:.2f}")


def measurement_error(result, truth, rate: float, periods: int, seeds: int) -> None:
    """Print ln(T measured / T simulated), %, of clean and noisy records of each run and direction."""
    from workbook.rig.correlation import measure

    def errors(**options) -> np.ndarray:
        return 100 * np.array([np.log(measure(synthetic_record(run, REFERENCE_TRANSDUCERS, excitation=excitation,
                                                               sample_rate_hz=rate, duration=2.0, **options),
                                              periods).transmissibility / run.transmissibility)
                               for run, excitation in zip(result.runs, truth.excitations, strict=True)]).ravel()

    noisy = np.array([errors(noise=0.005, seed=seed) for seed in range(seeds)])
    rows = {"clean, drift 0.002": errors(noise=0.0), "clean, no drift": errors(noise=0.0, drift=0.0),
            f"0.5 % noise: mean of {seeds}": noisy.mean(axis=0), "0.5 % noise: std": noisy.std(axis=0, ddof=1)}
    labels = [f"{run.name[:2]} {d}" for run in result.runs for d in "xyz"]
    print("ln(T measured / T simulated), %")
    print(f"{'record':>22} " + " ".join(f"{label:>7}" for label in labels))
    for name, values in rows.items():
        print(f"{name:>22} " + " ".join(f"{v:>+7.3f}" for v in values))


def nominal_value(case, name: str) -> float:
    from workbook.studies.parametric import parameter_value

    return parameter_value(case, name)


if __name__ == "__main__":
    main()
