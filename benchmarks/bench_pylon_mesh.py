"""The mesh pylon's runs: the first ``mountwb run`` of a case (its pylon reduced) and the later ones (from the cache).

The case is the plate pylon of ``tests/test_pylon_mesh.py`` (the single-DOF
engine whose four pins hang in bores of a plate clamped on a column, three
excitations). Every run is a new process of this source tree sharing one
cache folder; ``--before REV`` measures the source tree of git revision REV
the same way, interleaved with this one, in its own cache folder.

Measured on the shared 2-core machine of the project, ``OPENBLAS_NUM_THREADS=1``,
with ``python benchmarks/bench_pylon_mesh.py --before a8cedaa --repeats 5``
(a8cedaa: the pylon reduced in every process, kept only in its memory; load
average about 3 from other work, so single runs scatter; one run of the
benchmark)::

    | tree   | first run | later runs: median (fastest to slowest) |
    | before | 9.60 s    | 8.82 s (6.53 to 15.01 s)                |
    | now    | 11.64 s   | 1.17 s (0.86 to 2.05 s)                 |

The first runs differ by the load alone (both reduce the pylon); a later run
now loads the reduction instead of making it again.

Run from the repository's root::

    python benchmarks/bench_pylon_mesh.py [--repeats 3] [--before REV]
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_warm_paths import ROOT, source_tree


def _run(tree: Path, case: Path, cache: Path) -> float:
    """Wall time of one ``mountwb run CASE`` process of the source tree *tree*, s."""
    env = dict(os.environ, MOUNTWB_CACHE=str(cache), PYTHONPATH=str(tree), OPENBLAS_NUM_THREADS="1")
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "workbook.cli.main", "run", str(case), "--no-progress"], check=True,
                   cwd=case.parent, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="later runs per tree")
    parser.add_argument("--before", help="git revision to measure as well")
    args = parser.parse_args()
    sys.path[:0] = [str(ROOT), str(ROOT / "tests")]
    from test_pylon_mesh import _plate_case

    from workbook.model.codec import to_json

    with tempfile.TemporaryDirectory(prefix="bench-pylon-") as name:
        folder = Path(name)
        case = folder / "plate.json"
        case.write_text(to_json(_plate_case(folder)))
        trees = {"now": ROOT}
        if args.before:
            trees = {"before": source_tree(args.before, folder / "before"), **trees}
        first = {tree: _run(path, case, folder / f"cache-{tree}") for tree, path in trees.items()}
        later: dict[str, list[float]] = {tree: [] for tree in trees}
        for _ in range(args.repeats):  # interleaved: a change of the machine's load hits every tree alike
            for tree, path in trees.items():
                later[tree].append(_run(path, case, folder / f"cache-{tree}"))
    print(f"load average {' '.join(open('/proc/loadavg').read().split()[:3])}")
    print("| tree | first run | later runs: median (fastest to slowest) |")
    print("|---|---|---|")
    for tree in trees:
        print(f"| {tree} | {first[tree]:.2f} s | {statistics.median(later[tree]):.2f} s "
              f"({min(later[tree]):.2f} to {max(later[tree]):.2f} s) |")


if __name__ == "__main__":
    main()
