"""Fast by default: the run times a user meets and the speed-ups behind them, side by side in one run.

Measured, each the median of its repeats:

- ``mountwb run`` with an empty reduction cache (a new process and a new,
  empty cache folder each time), both rotors;
- ``mountwb run`` again with the cache filled;
- ``mountwb run cases/reference.xlsx --report r.xlsx`` with the cache filled
  (both rotors and the Sweep row, written back into a fresh copy, plus the
  report);
- cold reduction of the reference mount's links for both rotors, as before
  (``bench_reduction.py``'s before path: K and M by scikit-fem's weak forms,
  a factorisation per eigenproblem, a new FE model per excitation, Exudyn's
  invariants, a link keyed by its exact length) and as now (one factorisation
  per unique link, the unique links side by side in worker processes as a
  run does it, and again all in one process), interleaved, with the largest
  relative difference of every frequency;
- both rotors in the frequency domain (the case's own links) against the
  seed study's complete-MNF model (every link with 20 fixed-interface
  modes, time domain + DFT) run as the seed study ran it, from rest, as the
  accuracy study times its rungs (links from the cache), with the largest
  difference of T; on the reference with the seed study's viscous hinge
  dampers (``hinge_damping="viscous"``);
- a 1000-point sweep (2 to 300 Hz) after the model is built: every point
  at once from one eigen-decomposition, and point by point.

Run from the repository's root::

    python benchmarks/bench_fast.py [--repeats 3] [--seed-repeats 1]
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from bench_reduction import _before, _now, _timed, largest_difference  # noqa: E402  (this folder is on the path of a script run from it)

from workbook.scene.link_workers import available_cores  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SWEEP_POINTS = 1000


def _command(args, cache: Path, cwd: Path) -> float:
    """Wall time of one ``mountwb`` process (this source tree), s."""
    env = dict(os.environ, MOUNTWB_CACHE=str(cache), PYTHONPATH=str(ROOT))
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "workbook.cli.main", *args], check=True, cwd=cwd, env=env,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def command_line(repeats: int, folder: Path) -> dict:
    """Cold and warm ``mountwb run``, and the reference workbook with its report, warm."""
    cold = []
    for i in range(repeats):
        cache = folder / f"cache-{i}"
        cold.append(_command(["run"], cache, folder))
    warm = [_command(["run"], cache, folder) for _ in range(repeats)]
    workbook = folder / "reference.xlsx"
    shutil.copy(ROOT / "cases" / "reference.xlsx", workbook)
    _command(["run", str(workbook), "--report", str(folder / "report.xlsx")], cache, folder)  # fills the cache
    report = []
    for i in range(repeats):
        copy = folder / f"reference-{i}.xlsx"
        shutil.copy(ROOT / "cases" / "reference.xlsx", copy)
        report.append(_command(["run", str(copy), "--report", str(folder / f"report-{i}.xlsx")], cache, folder))
    return {"cold": statistics.median(cold), "warm": statistics.median(warm), "report": statistics.median(report)}


def cold_reduction(case, repeats: int) -> dict:
    """Cold reduction of every link for both rotors, before and now (side by side in worker processes, and
    in one process), and the largest frequency difference."""
    frequencies_hz = sorted({e.frequency for e in case.excitations})
    before_times, now_times, alone_times = [], [], []
    for _ in range(repeats):  # interleaved, so that a change of the machine's load hits all alike
        seconds, before = _timed(lambda: _before(case, frequencies_hz), 1)
        before_times.append(seconds)
        seconds, now = _timed(lambda: _now(case, frequencies_hz), 1)
        now_times.append(seconds)
        seconds, _ = _timed(lambda: _now(case, frequencies_hz, workers=1), 1)
        alone_times.append(seconds)
    worst = largest_difference(case, before, now)
    unique = len({link.model.key() for link in case.links})
    return {"before": statistics.median(before_times), "now": statistics.median(now_times),
            "alone": statistics.median(alone_times), "worst": worst, "reductions before": len(before),
            "unique now": unique, "workers": min(available_cores(), unique)}


def frequency_against_seed(case, repeats: int, seed_repeats: int) -> dict:
    """The accuracy study's frequency-domain rung and its complete-MNF rung run as the seed study ran it
    (from rest, its transient integrated away before the DFT): wall times and T."""
    import dataclasses

    from workbook.studies.accuracy import FREQUENCY_RUNG, SEED_RUNG, ladder, run_rung

    rungs = {rung.label: rung for rung in ladder()}
    frequency = run_rung(case, rungs[FREQUENCY_RUNG], repeats)
    from_rest = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, start="rest"))
    seed = run_rung(from_rest, rungs[SEED_RUNG], seed_repeats)
    difference = max(float(np.abs(np.asarray(t) / seed.transmissibility[name] - 1).max())
                     for name, t in frequency.transmissibility.items())
    return {"frequency": frequency.wall_time, "seed": seed.wall_time, "difference": difference,
            "frequency DOF": frequency.dof, "seed DOF": seed.dof}


def sweep(case, repeats: int) -> dict:
    """A 1000-point sweep per rotor on its built model: at once, and point by point."""
    from workbook.solve.harmonic import excitation_phasor
    from workbook.solve.pipeline import prepare
    from workbook.solve.response_sweep import respond_many

    frequencies = np.geomspace(2.0, 300.0, SWEEP_POINTS)
    at_once, point_by_point, worst = [], [], 0.0
    for excitation in case.excitations:
        prepared = prepare(case, excitation)
        with prepared.scene:
            model, force = prepared.model, excitation_phasor(excitation)
            seconds, many = _timed(lambda model=model, force=force, excitation=excitation:
                                   respond_many(model, frequencies, force, excitation.point), repeats)
            at_once.append(seconds)
            seconds, single = _timed(lambda model=model, force=force, excitation=excitation:
                                     [model.respond(f, force, excitation.point) for f in frequencies], 1)
            point_by_point.append(seconds)
            worst = max(worst, max(float(np.abs(a - b.pylon_force).max() / np.abs(b.pylon_force).max())
                                   for a, b in zip(many.pylon_force, single, strict=True)))
    return {"at once": max(at_once), "point by point": max(point_by_point), "worst": worst}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed-repeats", type=int, default=1, help="repeats of the complete-MNF time domain")
    args = parser.parse_args(argv)
    folder = Path(tempfile.mkdtemp(prefix="bench-fast-"))
    os.environ["MOUNTWB_CACHE"] = str(folder / "cache-in-process")
    try:
        from workbook.model.reference import reference_case

        case = reference_case()
        cli = command_line(args.repeats, folder)
        print("command line done", file=sys.stderr)
        reduction = cold_reduction(case, args.repeats)
        print("cold reduction done", file=sys.stderr)
        # the seed study's model had viscous hinge dampers: with the loss factor's equivalent viscous
        # damping the time domain would settle for minutes (docs/reference-mount.md, time-domain damping)
        seed = frequency_against_seed(reference_case(hinge_damping="viscous"), args.repeats, args.seed_repeats)
        print("frequency against complete MNF done", file=sys.stderr)
        sweeps = sweep(case, max(args.repeats, 5))
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    load = os.getloadavg()[0]
    r, s = args.repeats, args.seed_repeats
    rows = [
        ("`mountwb run`, empty cache, both rotors", f"{cli['cold']:.1f} s", r, "<= 15 s", cli["cold"] <= 15),
        ("`mountwb run`, cache filled", f"{cli['warm']:.2f} s", r, "<= 2 s", cli["warm"] <= 2),
        ("`mountwb run cases/reference.xlsx --report r.xlsx`, cache filled", f"{cli['report']:.1f} s", r, "<= 10 s",
         cli["report"] <= 10),
        (f"cold reduction, {len(case.links)} links, both rotors: before ({reduction['reductions before']} "
         f"reductions)", f"{reduction['before']:.1f} s", r, "", None),
        (f"cold reduction: now (one per unique link, {reduction['unique now']} unique, side by side in "
         f"{reduction['workers']} worker processes)", f"{reduction['now']:.1f} s", r, "", None),
        ("  speed-up; largest relative frequency difference",
         f"{reduction['before'] / reduction['now']:.2f}x; {reduction['worst']:.1e}", r, ">= 4x; <= 1e-6",
         reduction["before"] / reduction["now"] >= 4 and reduction["worst"] <= 1e-6),
        ("  now in one process; its speed-up", f"{reduction['alone']:.1f} s; "
         f"{reduction['before'] / reduction['alone']:.2f}x", r, "", None),
        (f"both rotors, frequency domain ({seed['frequency DOF']} DOF)", f"{seed['frequency']:.2f} s", r, "", None),
        (f"both rotors, complete-MNF time domain from rest, as the seed study ({seed['seed DOF']} DOF)",
         f"{seed['seed']:.1f} s", s, "", None),
        ("  speed-up; largest difference of T", f"{seed['seed'] / seed['frequency']:.0f}x; "
         f"{100 * seed['difference']:.2f} %", "", ">= 100x; <= 1 %",
         seed["seed"] / seed["frequency"] >= 100 and seed["difference"] <= 0.01),
        (f"{SWEEP_POINTS}-point sweep on the built model, at once (slower rotor)", f"{sweeps['at once']:.3f} s",
         max(r, 5), "<= 0.1 s", sweeps["at once"] <= 0.1),
        ("  point by point (slower rotor); largest difference", f"{sweeps['point by point']:.2f} s; "
         f"{sweeps['worst']:.1e}", 1, "<= 1e-9", sweeps["worst"] <= 1e-9),
    ]
    print(f"Reference mount, medians, 1 BLAS thread, {os.cpu_count()} cores, load average {load:.1f} at the end")
    print("| what | time | repeats | target | met |\n|---|---|---|---|---|")
    for what, value, repeats, target, met in rows:
        print(f"| {what} | {value} | {repeats} | {target} | {'' if met is None else 'yes' if met else 'no'} |")


if __name__ == "__main__":
    main()
