"""Designs answered together (``LinearMount.evaluate_many``), now and before, side by side: CPU time per design.

Each round starts a new process per source tree (this one and, with
``--before REV``, that git revision's, unpacked by ``git archive``). The
process prepares the reference mount, answers one batch to warm up, then
times ``--batches`` batches of ``BATCH_ROWS`` hinge designs (the parameter
studies' batches) of each kind:

- every hinge's stiffness scaled per direction by random factors 1 to 4;
- only the front hinges' (a study of one hinge group).

The designs are the same for every tree (fixed seeds). The trees alternate
round by round, so that a change of the machine's load hits both alike.
The table gives, per kind and tree, the median over the rounds of the
process's CPU time per design (the preparation left out), both rotors, and
the ratio of now to before. Run with
``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_design_batches.py [--before REV] [--rounds 3] [--batches 4]``.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_warm_paths import ROOT, source_tree

#: The hinge designs of each kind: the hinges whose stiffness a design scales (by their names' start).
KINDS = {"every hinge": "", "the front hinges": "front"}

_PROBE = """
import dataclasses, json, sys, time
import numpy as np
import workbook as wb
from workbook.studies.parallel import BATCH_ROWS

case = wb.reference_case()
mount = wb.LinearMount.prepare(case)
batches = int(sys.argv[1])
kinds = json.loads(sys.argv[2])

def designs(start, count, seed):
    rng = np.random.default_rng(seed)
    return [dataclasses.replace(case, hinges=tuple(
        dataclasses.replace(h, stiffness=tuple(h.values("stiffness") * rng.uniform(1.0, 4.0, 3)))
        if h.name.startswith(start) else h for h in case.hinges)) for _ in range(count)]

out = {}
for seed, (kind, start) in enumerate(kinds.items()):
    mount.evaluate_many(designs(start, BATCH_ROWS, 100 + seed))
    timed = designs(start, batches * BATCH_ROWS, seed)
    begin = time.process_time()
    for k in range(0, len(timed), BATCH_ROWS):
        mount.evaluate_many(timed[k:k + BATCH_ROWS])
    out[kind] = (time.process_time() - begin) / len(timed)
print("RESULT " + json.dumps(out))
"""


def _round(tree: Path, batches: int) -> dict:
    """CPU seconds per design of each kind, in a new process of the source tree *tree*."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    run = subprocess.run([sys.executable, "-c", _PROBE, str(batches), json.dumps(KINDS)], env=env, cwd=tree,
                         capture_output=True, text=True, check=True)
    line = next(line for line in run.stdout.splitlines() if line.startswith("RESULT "))
    return json.loads(line[len("RESULT "):])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", metavar="REV", help="also measure the source tree of this git revision")
    parser.add_argument("--rounds", type=int, default=3, help="alternating rounds (a new process each)")
    parser.add_argument("--batches", type=int, default=4, help="timed batches per kind in each round")
    args = parser.parse_args(argv)
    folder = Path(tempfile.mkdtemp(prefix="bench-batches-"))
    try:
        trees = {"now": ROOT}
        if args.before:
            trees = {f"before ({args.before})": source_tree(args.before, folder / "before"), **trees}
        times: dict = {name: {kind: [] for kind in KINDS} for name in trees}
        for _ in range(args.rounds):
            for name, tree in trees.items():
                for kind, seconds in _round(tree, args.batches).items():
                    times[name][kind].append(seconds)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    names = list(trees)
    print(f"Reference mount, both rotors, {args.rounds} rounds of {args.batches} batches per kind; CPU ms per "
          f"design (median), OPENBLAS_NUM_THREADS {os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}, load average "
          f"{os.getloadavg()[0]:.1f} at the end")
    ratio = " | now / before" if len(names) == 2 else ""
    print("| designs that scale | " + " | ".join(names) + ratio + " |")
    print("|---|" + "---|" * (len(names) + (1 if ratio else 0)))
    for kind in KINDS:
        medians = [statistics.median(times[name][kind]) for name in names]
        cells = " | ".join(f"{1e3 * m:.3f} ({1 / m:.0f}/s)" for m in medians)
        print(f"| {kind} | {cells}" + (f" | {medians[1] / medians[0]:.2f}" if ratio else "") + " |")


if __name__ == "__main__":
    main()
