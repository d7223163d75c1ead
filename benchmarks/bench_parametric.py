"""A 100-run parameter study, serial against local processes: wall time and parallel efficiency.

50 study rows (a Latin hypercube over hinge stiffness 1e7 to 4e7 N/m and
hinge damping 5e3 to 4e4 N s/m) of the reference mount, each run for the LP
and HP rotors (100 runs), with rigid links unless ``--flexible``. Link
reductions are made (or loaded from the disk cache) before timing, as the
study runner does in its parent process; the timed part is
:func:`workbook.studies.parallel.run_rows`, serial and then with ``--workers``
processes, whose answers must be identical. Parallel efficiency =
serial time / (workers x parallel time). Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_parametric.py [--rows 50] [--workers 2] [--flexible]
"""
from __future__ import annotations

import argparse
import os
import resource
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

from workbook.model.reference import reference_case  # noqa: E402
from workbook.studies.parallel import prepare, run_rows  # noqa: E402
from workbook.studies.parametric import latin_hypercube, study_cases  # noqa: E402
from workbook.studies.sensitivity import study_frame  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=50, help="study rows (two runs each)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--flexible", action="store_true", help="flexible links as the case asks")
    args = parser.parse_args()
    case = reference_case()
    case = case if args.flexible else case.with_rigid_links()
    rows = latin_hypercube({"hinge_stiffness": (1e7, 4e7), "hinge_damping": (5e3, 4e4)}, args.rows, seed=1)
    cases = study_cases(case, rows)
    prepare(dict(enumerate(cases)))  # fill the reduction cache outside the timing
    timings, frames = {}, {}
    for workers in (1, args.workers):
        start = time.perf_counter()
        frames[workers] = study_frame(rows, run_rows(cases, workers=workers))
        timings[workers] = time.perf_counter() - start
    serial, parallel = frames[1], frames[args.workers]
    runs = int((serial["status"] == "ok").sum())
    same = serial.drop(columns="wall time s").equals(parallel.drop(columns="wall time s"))
    efficiency = timings[1] / (args.workers * timings[args.workers])
    print(f"{case.name}, {'flexible' if args.flexible else 'rigid'} links: {len(rows)} rows, {runs} runs ok, "
          f"{os.cpu_count()} cores")
    print(f"serial:               {timings[1]:8.1f} s  ({timings[1] / runs:.2f} s per run; "
          f"sum of row wall times {serial['wall time s'].drop_duplicates().sum():.1f} s)")
    print(f"{args.workers} processes:          {timings[args.workers]:8.1f} s  "
          f"(speed-up {timings[1] / timings[args.workers]:.2f}, parallel efficiency {100 * efficiency:.0f} %)")
    print(f"answers identical: {same}; peak memory of this process "
          f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB")


if __name__ == "__main__":
    main()
