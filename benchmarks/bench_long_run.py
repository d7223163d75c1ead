"""Memory and time of longer and longer runs: memory must not grow with the run.

Each run is the reference mount's LP rotor case with rigid links, started
from rest with a fixed settle time, in a fresh process (so the peak resident memory belongs to that
run alone); its wall time and peak memory are printed against the number of
steps. The time integration stores the hinge forces of the two measured
windows only (``workbook.solve.time_domain``), so the peak memory should stay flat
while the wall time grows with the steps. Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_long_run.py [--settle 1 10 100]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys

CHILD = """
import dataclasses, json, resource, sys, time
from workbook.model.reference import LP_ROTOR, reference_case
from workbook.solve.pipeline import run_excitation
case = reference_case().with_rigid_links()
case = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, settle_time=float(sys.argv[1]),
                                                             start="rest"))
start = time.perf_counter()
result = run_excitation(case, LP_ROTOR)
card = result.model_card
print(json.dumps({"steps": card.solver["steps"], "wall": time.perf_counter() - start,
                  "samples": len(result.time), "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def run(settle_time: float) -> dict:
    """Run one case in a fresh process; return steps, wall time (s), stored samples and peak memory (MB)."""
    output = subprocess.run([sys.executable, "-c", CHILD, str(settle_time)], check=True, capture_output=True,
                            text=True).stdout
    return json.loads(output.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--settle", type=float, nargs="+", default=[1.0, 10.0, 100.0],
                        help="settle times to run, s")
    args = parser.parse_args()
    print(f"{'settle (s)':>10} {'steps':>9} {'wall (s)':>9} {'stored samples':>15} {'peak RSS (MB)':>14}")
    for settle in args.settle:
        row = run(settle)
        print(f"{settle:10g} {row['steps']:9d} {row['wall']:9.2f} {row['samples']:15d} {row['peak_mb']:14.1f}")


if __name__ == "__main__":
    main()
