"""Resident memory against the number of runs in one process: it must stay flat.

Each mode runs in a fresh process: ``time`` and ``frequency`` run
``run_case(reference_case())`` (flexible links as the reference asks, every
excitation) by that method again and again; ``worker`` runs study rows as a
study worker does (:func:`workbook.studies.parallel.run_row`, the hinge
stiffness varied from row to row). Link reductions come from the disk cache,
filled before the first printed run. Printed: resident memory (RSS) after
every ``--every`` runs, and the growth per run fitted over the runs after the
first ``--every`` (allocator pools and caches settle in those). Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_memory.py [--runs 100] [--every 10] [--modes time frequency worker]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

import numpy as np

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

CHILD = """
import dataclasses, json, sys
import psutil
from workbook.model.reference import reference_case
from workbook.solve.pipeline import run_case
from workbook.studies.parallel import run_row
from workbook.studies.parametric import row_case

mode, runs, every = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
case = reference_case()
if mode in ("time", "frequency"):
    case = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method=mode))
    run = lambda i: run_case(case)
else:
    run = lambda i: run_row(i, row_case(case, {"hinge_stiffness": 1e7 * (1 + i % 4)}, i))
run(0)  # fills the reduction cache
process = psutil.Process()
print(json.dumps([0, process.memory_info().rss / 2**20]), flush=True)
for i in range(1, runs + 1):
    run(i)
    if i % every == 0:
        print(json.dumps([i, process.memory_info().rss / 2**20]), flush=True)
"""


def measure(mode: str, runs: int, every: int) -> list[tuple[int, float]]:
    """RSS (MB) after 0, every, 2 every, ... runs of *mode* in a fresh process."""
    output = subprocess.run([sys.executable, "-c", CHILD, mode, str(runs), str(every)], check=True,
                            capture_output=True, text=True).stdout
    return [tuple(json.loads(line)) for line in output.splitlines() if line.startswith("[")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=100)
    parser.add_argument("--every", type=int, default=10)
    parser.add_argument("--modes", nargs="+", choices=("time", "frequency", "worker"),
                        default=["time", "frequency", "worker"])
    args = parser.parse_args()
    for mode in args.modes:
        points = measure(mode, args.runs, args.every)
        runs, rss = np.array(points).T
        settled = runs >= args.every
        slope = np.polyfit(runs[settled], rss[settled], 1)[0] if settled.sum() >= 2 else float("nan")
        print(f"{mode}: RSS against runs of the reference mount")
        print(f"{'runs':>6} {'RSS (MB)':>9}")
        for count, value in points:
            print(f"{count:6d} {value:9.1f}")
        print(f"growth after the first {args.every} runs: {slope:.3f} MB per run "
              f"({rss[-1] - rss[settled][0]:.1f} MB over runs {args.every}-{int(runs[-1])})\n", flush=True)


if __name__ == "__main__":
    main()
