"""Cost of a Campbell diagram: the preparation (reductions, preload, linearisation) once, then the modes
at every speed with their crossings, for the reference mount with its spools as gyroscopic rotors.

Medians of ``--repeats`` diagrams (the link reductions come from the cache after the first). Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_campbell.py [--points 200] [--repeats 3]
"""
from __future__ import annotations

import argparse
import os
import statistics

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import workbook as wb  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print("| links | independent coordinates | branches | speeds | critical speeds | prepare (median) | "
          "modes and crossings (median) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for label, case in (("rigid", wb.reference_case(rotors=True).with_rigid_links()),
                        ("flexible", wb.reference_case(rotors=True))):
        diagrams = [wb.campbell(case, points=args.points) for _ in range(args.repeats)]
        last = diagrams[-1]
        prepare = statistics.median(d.timings["prepare"] for d in diagrams)
        trace = statistics.median(d.timings["modes and crossings"] for d in diagrams)
        truncation = last.truncation
        print(f"| {label} | {last.coordinates} | {truncation['basis modes']} modes to {truncation['basis Hz']:.0f} Hz | "
              f"{truncation['largest frequency error']:.1e} | {len(last.descriptions)} | {len(last.speeds_rpm)} | "
              f"{len(last.crossings)} | {prepare:.2f} s | {trace:.2f} s |")


if __name__ == "__main__":
    main()
