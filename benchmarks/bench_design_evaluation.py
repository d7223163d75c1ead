"""Design evaluation in NumPy (workbook.design) against the Exudyn pipeline, on the reference mount.

Prints, for hinge designs with every hinge's stiffness scaled per direction
(random factors 1 to 4), the median wall time of one design (both rotors)
by each path and the largest normwise difference of T and of the hinge
forces; the difference of T for designs far from the prepared one (every
hinge's stiffness scaled by :data:`FAR_FACTORS`) with the engine's static
sag there; then the median time of the derivatives of T and the hinge forces
with respect to five parameters by the direct method and by central
differences of whole evaluations, and their largest difference. Last, the
time per design of :data:`BATCH` designs answered together
(``LinearMount.evaluate_many``, in the parameter studies' batches of
``BATCH_ROWS``) against the same designs one at a time, in :data:`REPEATS`
alternating rounds, and the largest difference between them; and beside
them the floor of this way of evaluating: the LAPACK solves alone that a
design needs together with others (per rotor, the chord's solve of the size
of its channels' coordinates; the solves of its bodies' held dynamic
stiffness, bodies of one width together, for their loads and their points
on channels between moving bodies; the Woodbury solve of those channels,
three unknowns per channel), timed on matrices of those sizes. Run with
``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_design_evaluation.py [designs]``.
"""
import dataclasses
import statistics
import sys
import time

import numpy as np

import workbook as wb
from workbook.design.sensitivity import difference_sensitivity
from workbook.studies.parallel import BATCH_ROWS

#: Scale factors of every hinge's stiffness for the designs far from the prepared one.
FAR_FACTORS = (0.25, 0.5, 2.0, 20.0, 80.0)
#: Designs answered together, and rounds of the batch against one at a time.
BATCH = 128
REPEATS = 3
PARAMETERS = ("hinge_stiffness/front", "hinge_stiffness/rear/axial", "hinge_loss_factor/thrust", "engine_mass",
              "hinge_damping/all")


def main(count: int = 5) -> None:
    case = wb.reference_case()
    case = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, equilibrium_tolerance=1e-10))
    start = time.perf_counter()
    mount = wb.LinearMount.prepare(case)
    prepare_seconds = time.perf_counter() - start
    rng = np.random.default_rng(1)
    fast_times, exact_times, t_errors, hinge_errors = [], [], [], []
    for _ in range(count):
        design = dataclasses.replace(case, hinges=tuple(
            dataclasses.replace(h, stiffness=tuple(h.values("stiffness") * rng.uniform(1.0, 4.0, 3)))
            for h in case.hinges))
        start = time.perf_counter()
        fast = mount.evaluate(design).result
        fast_times.append(time.perf_counter() - start)
        start = time.perf_counter()
        exact = wb.run_case(design)
        exact_times.append(time.perf_counter() - start)
        for f, e in zip(fast.runs, exact.runs, strict=True):
            t_errors.append(np.abs(f.transmissibility - e.transmissibility).max() / e.transmissibility.max())
            hinge_errors.append(max(np.abs(f.hinge_amplitudes[n] - e.hinge_amplitudes[n]).max()
                                    / e.hinge_amplitudes[n].max() for n in e.hinge_amplitudes))
    direct_times, difference_times, gradient_errors = [], [], []
    for _ in range(count):
        values = {"hinge_stiffness/front": rng.uniform(2e7, 8e7), "hinge_stiffness/rear/axial": rng.uniform(2e7, 8e7),
                  "hinge_loss_factor/thrust": rng.uniform(0.02, 0.1), "engine_mass": rng.uniform(2000, 2600),
                  "hinge_damping/all": rng.uniform(100, 500)}
        direct = wb.design_sensitivity(mount, values)
        differences = difference_sensitivity(mount, values)
        direct_times.append(direct.seconds)
        difference_times.append(differences.seconds)
        scale = np.abs(differences.gradient).max(axis=(0, 1))
        gradient_errors.append(float((np.abs(direct.gradient - differences.gradient).max(axis=(0, 1)) / scale).max()))
    fast_median, exact_median = statistics.median(fast_times), statistics.median(exact_times)
    print(f"reference mount, {count} hinge designs, both rotors (preparation {prepare_seconds:.2f} s)")
    print(f"{'path':<24}{'median s/design':>16}{'designs/s':>11}")
    print(f"{'NumPy (LinearMount)':<24}{fast_median:>16.4f}{1 / fast_median:>11.1f}")
    print(f"{'Exudyn (run_case)':<24}{exact_median:>16.4f}{1 / exact_median:>11.1f}")
    print(f"speed-up {exact_median / fast_median:.1f}x; largest difference: T {max(t_errors):.1e}, "
          f"hinge forces {max(hinge_errors):.1e} (normwise)")
    print(f"\nderivatives of T and hinge forces with respect to {len(PARAMETERS)} parameters "
          f"({', '.join(PARAMETERS)}), {count} designs")
    print(f"{'method':<24}{'median s/design':>16}")
    print(f"{'direct (design_sensitivity)':<24}{statistics.median(direct_times):>16.4f}")
    print(f"{'central differences':<24}{statistics.median(difference_times):>16.4f}")
    print(f"largest difference of dT/dp, relative to each parameter's largest: {max(gradient_errors):.1e}")
    print("\nevery hinge's stiffness scaled, far from the prepared design")
    print(f"{'factor':>8}{'engine sag, mm':>16}{'T difference':>14}")
    for factor in FAR_FACTORS:
        design = dataclasses.replace(case, hinges=tuple(
            dataclasses.replace(h, stiffness=tuple(h.values("stiffness") * factor)) for h in case.hinges))
        answer = mount.evaluate(design)
        exact = wb.run_case(design)
        sag = max(abs(float(engine[2])) for engine in answer.engine_static.values())
        difference = max(np.abs(f.transmissibility - e.transmissibility).max() / e.transmissibility.max()
                         for f, e in zip(answer.result.runs, exact.runs, strict=True))
        print(f"{factor:>8g}{1e3 * sag:>16.2f}{difference:>14.1e}")
    _batch(case, mount, rng)


def _batch(case, mount, rng) -> None:
    """Designs answered together against one at a time: median time per design, and their largest difference."""
    designs = [dataclasses.replace(case, hinges=tuple(
        dataclasses.replace(h, stiffness=tuple(h.values("stiffness") * rng.uniform(1.0, 4.0, 3)),
                            loss_factor=float(rng.uniform(0.02, 0.1))) for h in case.hinges))
        for _ in range(BATCH)]
    alone_times, together_times, difference = [], [], 0.0
    for _ in range(REPEATS):
        start = time.perf_counter()
        alone = [mount.evaluate(design) for design in designs]
        alone_times.append((time.perf_counter() - start) / BATCH)
        start = time.perf_counter()
        together = [answer for k in range(0, BATCH, BATCH_ROWS) for answer in mount.evaluate_many(designs[k:k + BATCH_ROWS])]
        together_times.append((time.perf_counter() - start) / BATCH)
        for one, many in zip(alone, together, strict=True):
            for a, b in zip(one.result.runs, many.result.runs, strict=True):
                difference = max(difference, np.abs(a.transmissibility - b.transmissibility).max()
                                 / a.transmissibility.max())
    one, many = statistics.median(alone_times), statistics.median(together_times)
    floor = _solves_alone(mount)
    print(f"\n{BATCH} hinge designs (stiffness and loss factor), both rotors, {REPEATS} rounds; together: "
          f"{BATCH_ROWS} at a time")
    print(f"{'evaluation':<24}{'median s/design':>16}{'designs/s':>11}")
    print(f"{'one at a time':<24}{one:>16.4f}{1 / one:>11.1f}")
    print(f"{'together':<24}{many:>16.4f}{1 / many:>11.1f}")
    print(f"{'its LAPACK solves alone':<24}{floor:>16.4f}{1 / floor:>11.1f}")
    for name, item in mount.items.items():
        layout = item.expansion.layout
        widths = ", ".join(f"{len(g.blocks)} of {g.width}" for g in item.expansion.coupling.groups)
        print(f"{name}: {layout.count} independent coordinates in {len(layout.coordinates)} bodies ({widths}); "
              f"{3 * len(item.expansion.coupling.coupled) // 2} Woodbury unknowns")
    print(f"speed-up {one / many:.1f}x; largest difference of T {difference:.1e}")


def _solves_alone(mount) -> float:
    """Median time per design of the LAPACK solves of :data:`BATCH_ROWS` designs together, s."""
    rng = np.random.default_rng(2)
    times = []
    for _ in range(REPEATS):
        total = 0.0
        for item in mount.items.values():
            unknowns = 3 * len(item.expansion.coupling.coupled) // 2
            channels = 3 * len(mount.channels)
            chord = rng.standard_normal((BATCH_ROWS, channels, channels)) + channels * np.eye(channels)
            bodies = []
            for group in item.expansion.coupling.groups:
                shape = (BATCH_ROWS, len(group.blocks), group.width, group.width)
                matrices = rng.standard_normal(shape) + group.width * np.eye(group.width) + 1j * rng.standard_normal(shape)
                bodies.append((matrices, matrices[..., :1 + 3 * group.points.shape[1]]))
            woodbury = rng.standard_normal((BATCH_ROWS, unknowns, unknowns)) + unknowns * np.eye(unknowns) + 0j
            start = time.perf_counter()
            np.linalg.solve(chord, chord)
            for matrices, right in bodies:
                np.linalg.solve(matrices, right)
            np.linalg.solve(woodbury, woodbury[..., :1])
            total += time.perf_counter() - start
        times.append(total / BATCH_ROWS)
    return statistics.median(times)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
