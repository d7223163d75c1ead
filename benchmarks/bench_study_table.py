"""Time to write a parameter study's table file against its size: why a running study writes it at most
every ``WRITE_INTERVAL`` s instead of after every row.

Each size is one :meth:`StudyTable.flush` of that many finished rows (two runs each, as a study of both
rotors), the median of ``--repeats`` writes to CSV and Parquet. Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_study_table.py [--repeats 5]
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from workbook.studies.parallel import RowOutcome
from workbook.studies.sensitivity import StudyTable


def _outcome(index: int) -> RowOutcome:
    runs = [{"run": name, "frequency Hz": hz, "T x": 0.1, "T y": 0.2, "T z": 0.3,
             "eta % x": 90.0, "eta % y": 80.0, "eta % z": 70.0, "steady": True}
            for name, hz in (("LP rotor", 59.0), ("HP rotor", 248.5))]
    return RowOutcome(index, runs, wall_time=0.1)


def _write_time(rows: int, suffix: str, folder: Path, repeats: int) -> float:
    study = tuple({"hinge_stiffness": 1e7 + i} for i in range(rows))
    times = []
    for repeat in range(repeats):
        table = StudyTable(folder / f"table-{rows}-{repeat}{suffix}", study)
        table.outcomes = {i: _outcome(i) for i in range(rows)}
        start = time.perf_counter()
        table.flush()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        print("| finished rows | CSV write (median) | Parquet write (median) |")
        print("|---:|---:|---:|")
        for rows in (100, 1000, 10_000):
            csv, parquet = (_write_time(rows, suffix, Path(folder), args.repeats) for suffix in (".csv", ".parquet"))
            print(f"| {rows} | {csv * 1e3:.0f} ms | {parquet * 1e3:.0f} ms |")


if __name__ == "__main__":
    main()
