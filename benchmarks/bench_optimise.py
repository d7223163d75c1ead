"""The reference mount optimised over both rotors' speed bands, within static-displacement and fatigue limits.

Six variables (the hinge stiffness and loss factor of the front, rear and
thrust hinge groups), the worst T over the LP rotor's band 40-62 Hz and the
HP rotor's 200-260 Hz (each a sweep of the band's points, its peaks found
between them), the engine's static displacement at most 2 mm and every
link's Goodman fatigue factor at least 2. Prints the wall time (the
preparation apart; and the process's CPU time, which the machine's load
changes less), the designs answered, the worst T before and after and
the gain in dB, and which constraints and variables are active. The
starts run in *workers* processes (the CPU time is then this process's
only). Run with ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_optimise.py [starts] [band points]
[SLSQP iterations] [workers]``.
"""
import sys
import time

import workbook as wb
from workbook.design.bands import band_case

BANDS = {"LP rotor": (40.0, 62.0), "HP rotor": (200.0, 260.0)}
GROUPS = ("front", "rear", "thrust")
VARIABLES = {**{f"hinge_stiffness/{g}": (5e6, 2e8) for g in GROUPS},
             **{f"hinge_loss_factor/{g}": (0.01, 0.2) for g in GROUPS}}
CONSTRAINTS = ("displacement<=0.002", "fatigue>=2")


def main(starts: int = 2, points: int = 13, maxiter: int = 60, workers: int = 1) -> None:
    case = wb.reference_case()
    start = time.perf_counter()
    mount = wb.LinearMount.prepare(band_case(case, BANDS, points))
    prepared = time.perf_counter() - start
    cpu = time.process_time()
    result = wb.optimise(case, VARIABLES, constraints=CONSTRAINTS, starts=starts, mount=mount, bands=BANDS,
                         band_points=points, maxiter=maxiter, workers=workers)
    cpu = time.process_time() - cpu
    table = result.table
    before, after = table.loc[("objective", "worst T (dB)"), ["before", "after"]]
    active = [name for (kind, name), row in table.iterrows() if row["active"] and kind in ("constraint", "variable")]
    bands = ", ".join(f"{name} {low:g}-{high:g} Hz" for name, (low, high) in BANDS.items())
    print(f"reference mount, {len(VARIABLES)} variables, bands {bands} ({points} points each, peaks refined), "
          f"{', '.join(CONSTRAINTS)}, {starts} start(s) of at most {maxiter} SLSQP iterations, {workers} worker(s)")
    print(f"{'quantity':<44}{'value':>14}")
    rows = [("preparation, s", f"{prepared:.1f}"), ("optimisation wall time, s", f"{result.seconds:.1f}"),
            ("optimisation CPU time, s", f"{cpu:.1f}"),
            ("designs with derivatives", f"{result.evaluations}"),
            ("s per design", f"{result.seconds / result.evaluations:.2f}"),
            ("worst T before, dB", f"{before:.2f}"), ("worst T after, dB", f"{after:.2f}"),
            ("gain, dB", f"{before - after:.2f}"),
            ("fast path vs run_case at the optimum", f"{result.fast_difference:.1e}"),
            ("largest violation at the optimum", f"{max(0.0, -min(_slacks(table))):.1e}")]
    for name, value in rows:
        print(f"{name:<44}{value:>14}")
    print("active: " + ("; ".join(active) or "none"))
    for end in result.starts:
        print(f"start {end['start']}: worst T {end['objective']:.3f} dB, {end['iterations']} SLSQP iterations, "
              f"{end['message']}")
    print(table.to_string(float_format=lambda v: f"{v:.5g}"))
    print(f"load: {open('/proc/loadavg').read().split()[0]}")


def _slacks(table) -> list:
    """Normalised slack of each constraint at the optimum (>= 0: met)."""
    slacks = [0.0]
    for _, row in table.xs("constraint").iterrows():
        limit = float(str(row["limit"]).replace("<=", " ").replace(">=", " ").split()[-1])
        sign = -1.0 if "<=" in str(row["limit"]) else 1.0
        slacks.append(sign * (row["after"] - limit) / limit)
    return slacks


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:5]))
