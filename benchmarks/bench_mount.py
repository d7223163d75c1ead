"""Timings of the reference mount: scene build, static preload, time domain.

For rigid and flexible links and both rotor cases, each stage is repeated and
the median wall time printed (link reductions come from the disk cache, so the
first, uncached reduction is timed once, separately). Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_mount.py [--repeats 3]
"""
from __future__ import annotations

import argparse
import statistics
import time

from workbook.model.reference import reference_case
from workbook.scene.build import build_scene, reduce_links
from workbook.solve.modes import linearize, modes_of, mounted_modes
from workbook.solve.preload import solve_preload
from workbook.solve.time_domain import extract, integrate, plan_run


def _time(function):
    start = time.perf_counter()
    value = function()
    return time.perf_counter() - start, value


def bench(case, excitation, repeats: int) -> dict[str, float]:
    """Median seconds per stage of one run."""
    samples = {stage: [] for stage in ("reduce (cached)", "build scene", "static preload", "mounted modes",
                                       "time integration", "extraction")}
    for _ in range(repeats):
        seconds, reduced = _time(lambda: reduce_links(case, excitation))
        samples["reduce (cached)"].append(seconds)
        seconds, scene = _time(lambda reduced=reduced: build_scene(case, excitation, reduced=reduced))
        samples["build scene"].append(seconds)
        seconds, _ = _time(lambda scene=scene: solve_preload(scene))
        samples["static preload"].append(seconds)
        seconds, mounted = _time(lambda scene=scene: mounted_modes(modes_of(linearize(scene))))
        samples["mounted modes"].append(seconds)
        plan = plan_run(case.analysis, scene.excitation.signal, mounted)
        seconds, histories = _time(lambda scene=scene, plan=plan: integrate(scene, plan))
        samples["time integration"].append(seconds)
        seconds, _ = _time(lambda scene=scene, plan=plan, histories=histories: extract(scene, plan, histories))
        samples["extraction"].append(seconds)
    medians = {stage: statistics.median(values) for stage, values in samples.items()}
    medians["steps"] = plan.steps
    medians["DOF"] = sum(scene.body_dof().values())
    return medians


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()

    case = reference_case()
    first, _ = _time(lambda: [reduce_links(case, e) for e in case.excitations])
    print(f"link reductions, all excitations (cold cache fills it; warm cache loads it): {first:.2f} s\n")
    rows = []
    for label, variant in (("rigid", case.with_rigid_links()), ("flexible", case)):
        for excitation in variant.excitations:
            rows.append((label, excitation.name, bench(variant, excitation, args.repeats)))
    stages = [key for key in rows[0][2] if key not in ("steps", "DOF")]
    header = f"{'links':9}{'run':10}{'DOF':>5}{'steps':>7}" + "".join(f"{s:>18}" for s in stages)
    print(f"median of {args.repeats} repeats, seconds")
    print(header)
    for label, name, medians in rows:
        print(f"{label:9}{name:10}{medians['DOF']:5d}{medians['steps']:7d}"
              + "".join(f"{medians[s]:18.4f}" for s in stages))
    for label, name, medians in rows:
        print(f"{label} {name}: {1e6 * medians['time integration'] / medians['steps']:.1f} us per step")


if __name__ == "__main__":
    main()
