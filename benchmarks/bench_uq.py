"""Studies on the fast path: a 10,000-row Latin-hypercube study, local processes against a local Dask cluster.

The reference mount (links as the case asks, both rotors), its linear mount
prepared once (:func:`workbook.studies.parallel.prepare_design_model`, timed
apart). Timed, each ``--repeats`` times (medians printed):

- ``--rows`` (10,000) Latin-hypercube rows over hinge stiffness 1e7 to 4e7 N/m
  and hinge loss factor 0.02 to 0.08 through
  :func:`workbook.studies.parallel.run_rows` on ``--workers`` local processes;
- ``--dask-rows`` of them on local processes and on a local Dask cluster of as
  many single-threaded workers (the linear mount scattered to them once):
  rows per second per worker.

It prints the CPU time, user and system, of the study's worker processes
(the kernel's share is mostly its mapping of freed memory again, see
:func:`workbook.processes.loosen_allocator`).

Some rows are checked against :func:`workbook.run_case` (Exudyn) to 1e-6,
and the time of a Sobol' analysis of ``--sobol`` base samples over the two
parameters (N (d + 2) rows) is extrapolated from the measured rate. Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_uq.py [--rows 10000] [--dask-rows 2000] [--workers 2]
"""
from __future__ import annotations

import argparse
import os
import statistics
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from workbook.model.reference import reference_case  # noqa: E402
from workbook.solve.pipeline import run_case  # noqa: E402
from workbook.studies.parallel import NUMPY_PATH, prepare, prepare_design_model, run_rows  # noqa: E402
from workbook.studies.parametric import latin_hypercube, study_cases  # noqa: E402
from workbook.studies.sensitivity import study_frame  # noqa: E402

BOUNDS = {"hinge_stiffness": (1e7, 4e7), "hinge_loss_factor": (0.02, 0.08)}


def timed(run, repeats: int) -> tuple[float, object]:
    """Median wall time of *repeats* calls of *run*, s, and the last answer."""
    times, answer = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        answer = run()
        times.append(time.perf_counter() - start)
    return statistics.median(times), answer


def main() -> None:
    from distributed import LocalCluster

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=10_000)
    parser.add_argument("--dask-rows", type=int, default=2000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--checked", type=int, default=5, help="rows checked against run_case")
    parser.add_argument("--sobol", type=int, default=100_000, help="base samples of the extrapolated Sobol' analysis")
    args = parser.parse_args()

    case = reference_case()
    prepare({0: case})                                          # the link reductions, outside the timing
    start = time.perf_counter()
    model = prepare_design_model(case)
    prepared = time.perf_counter() - start
    assert not isinstance(model, str), model
    rows = latin_hypercube(BOUNDS, args.rows, seed=1)
    cases = study_cases(case, rows)
    before = os.times()
    study, outcomes = timed(lambda: run_rows(cases, workers=args.workers, design_model=model), args.repeats)
    after = os.times()
    assert all(o.status == "ok" and o.path == NUMPY_PATH for o in outcomes)
    frame = study_frame(rows, outcomes)
    normwise = elementwise = 0.0         # normwise: per run, over its largest T (as tests/test_linear_mount.py)
    for index in np.linspace(0, len(rows) - 1, args.checked).astype(int):
        reference = np.array([run.transmissibility for run in run_case(cases[index]).runs])
        error = np.abs(frame[frame["row"] == index][["T x", "T y", "T z"]].to_numpy() - reference)
        normwise = max(normwise, float(np.max(error.max(axis=1) / np.abs(reference).max(axis=1))))
        elementwise = max(elementwise, float(np.max(error / np.abs(reference))))

    few = cases[:args.dask_rows]
    local, _ = timed(lambda: run_rows(few, workers=args.workers, design_model=model), args.repeats)
    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        dask, dask_outcomes = timed(lambda: run_rows(few, dask=cluster.scheduler_address, design_model=model),
                                    args.repeats)
    assert all(o.path == NUMPY_PATH for o in dask_outcomes)

    rate = len(rows) / study / args.workers
    sobol_rows = args.sobol * (len(BOUNDS) + 2)
    print(f"{case.name}, {'flexible' if any(case.link_is_flexible(link.name) for link in case.links) else 'rigid'} "
          f"links, both rotors; {os.cpu_count()} cores; medians of {args.repeats}")
    print("| what | wall time s | rows/s | rows/s per worker |")
    print("|---|---|---|---|")
    print(f"| prepare the linear mount | {prepared:.1f} | | |")
    print(f"| {len(rows):,}-row LHS study, {args.workers} local processes | {study:.1f} | {len(rows) / study:.0f} | "
          f"{rate:.1f} |")
    print(f"| {len(few):,} rows, {args.workers} local processes | {local:.1f} | {len(few) / local:.0f} | "
          f"{len(few) / local / args.workers:.1f} |")
    print(f"| {len(few):,} rows, local Dask cluster of {args.workers} workers | {dask:.1f} | {len(few) / dask:.0f} | "
          f"{len(few) / dask / args.workers:.1f} ({100 * local / dask:.0f} % of local processes) |")
    print(f"| Sobol', {args.sobol:,} base samples x {len(BOUNDS) + 2} = {sobol_rows:,} rows (extrapolated) | "
          f"{sobol_rows / (rate * args.workers):.0f} | | |")
    user, system = ((getattr(after, name) - getattr(before, name)) / args.repeats
                    for name in ("children_user", "children_system"))
    print(f"CPU of the {len(rows):,}-row study's worker processes: {user:.1f} s user, {system:.1f} s system "
          f"({100 * system / (user + system):.0f} % in the kernel)")
    print(f"T against run_case over {args.checked} rows: largest difference {normwise:.1e} of the run's largest T, "
          f"{elementwise:.1e} of the T itself")


if __name__ == "__main__":
    main()
