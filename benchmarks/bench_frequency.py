"""Time domain against frequency domain on the reference mount: medians of repeats.

Per rotor case (flexible links as the case asks, reductions from the disk
cache, filled once before timing): scene build, static solve, time-domain
run (linearisation, mounted modes, the steady start, integration, amplitude
extraction; the scene built with the excitation in full from the first
step, as for a steady start), frequency-domain run
(linearisation, input and outputs by central differences, one harmonic
solve) and a 1000-point sweep on that linearisation (2 to 300 Hz). Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_frequency.py [--repeats 3]
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from workbook.model.reference import reference_case  # noqa: E402
from workbook.scene.build import build_scene, reduce_links  # noqa: E402
from workbook.solve.harmonic import excitation_phasor, harmonic_model  # noqa: E402
from workbook.solve.modes import modes_of, mounted_modes  # noqa: E402
from workbook.solve.preload import solve_preload  # noqa: E402
from workbook.solve.steady_start import STEADY, steady_start  # noqa: E402
from workbook.solve.time_domain import extract, integrate, plan_run  # noqa: E402

SWEEP_POINTS = 1000


def _time(function):
    start = time.perf_counter()
    value = function()
    return time.perf_counter() - start, value


def bench(case, excitation, reduced, repeats: int) -> dict:
    """Median seconds per stage for one excitation."""
    stages = ("build", "static solve", "time-domain run", "frequency-domain run", f"{SWEEP_POINTS}-point sweep")
    samples = {stage: [] for stage in stages}
    frequencies = np.geomspace(2.0, 300.0, SWEEP_POINTS)
    force = excitation_phasor(excitation)
    for _ in range(repeats):
        seconds, scene = _time(lambda: build_scene(case, excitation, reduced=reduced))
        samples["build"].append(seconds)
        seconds, _ = _time(lambda scene=scene: solve_preload(scene))
        samples["static solve"].append(seconds)

        def frequency_run(scene=scene):
            model = harmonic_model(scene)
            return model, model.respond(excitation.frequency, force, excitation.point)

        seconds, (model, response) = _time(frequency_run)
        samples["frequency-domain run"].append(seconds)
        seconds, _ = _time(lambda model=model: [model.respond(f, force, excitation.point) for f in frequencies])
        samples[f"{SWEEP_POINTS}-point sweep"].append(seconds)

        def time_run(scene=scene):
            linear = harmonic_model(scene)
            plan = plan_run(case.analysis, scene.excitation.signal, mounted_modes(modes_of(linear.linearization)),
                            start=STEADY)
            steady_start(linear, excitation).apply(scene)
            histories = integrate(scene, plan, steady=lambda h: extract(scene, plan, h).steady)
            return plan, extract(scene, plan, histories)

        seconds, (plan, result) = _time(time_run)
        samples["time-domain run"].append(seconds)
    medians = {stage: statistics.median(values) for stage, values in samples.items()}
    medians.update(DOF=sum(scene.body_dof().values()), coordinates=model.dof, steps=plan.steps,
                   difference=np.abs(np.abs(response.pylon_force) / excitation.force_amplitude
                                     / result.transmissibility - 1).max())
    return medians


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    case = reference_case()
    case = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, ramp_periods=0.0))
    rows = []
    for excitation in case.excitations:
        reduced = reduce_links(case, excitation)
        rows.append((excitation.name, bench(case, excitation, reduced, args.repeats)))
    stages = [key for key in rows[0][1] if key not in ("DOF", "coordinates", "steps", "difference")]
    print(f"reference mount, median of {args.repeats} repeats, seconds")
    print(f"{'run':10}{'DOF':>5}{'steps':>7}" + "".join(f"{s:>22}" for s in stages) + f"{'max |T_FD/T_TD - 1|':>22}")
    for name, medians in rows:
        print(f"{name:10}{medians['DOF']:5d}{medians['steps']:7d}" + "".join(f"{medians[s]:22.4f}" for s in stages)
              + f"{100 * medians['difference']:21.3f}%")


if __name__ == "__main__":
    main()
