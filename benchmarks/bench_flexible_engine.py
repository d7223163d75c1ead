"""The flexible engine's cost on the reference mount: DOF, casing reduction, run time.

The casing of :func:`workbook.model.reference.reference_casing` at the given
element size is reduced cold (no cache: mesh, assembly, factorisation,
free-free modes, the modes for each rotor) once; then each rotor runs in the
frequency domain (links and casing from the cache), rigid engine against
flexible engine, medians of the repeats. Run::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_flexible_engine.py [--element-size 0.1] [--repeats 3]
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

from flexbodies.casing_reduction import reduce_casing  # noqa: E402
from workbook.model.reference import HP_ROTOR, LP_ROTOR, reference_case, reference_casing  # noqa: E402
from workbook.scene.engine_casing import eye_name  # noqa: E402
from workbook.solve.pipeline import prepare  # noqa: E402


def _run(case, excitation) -> tuple[float, int]:
    """Wall time of one frequency-domain run (s) and the scene's DOF."""
    start = time.perf_counter()
    prepared = prepare(case, excitation)
    with prepared.scene as scene:
        prepared.model.result(excitation, case.analysis.steady_tolerance)
        dof = sum(scene.body_dof().values())
    return time.perf_counter() - start, dof


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--element-size", type=float, default=0.1, help="casing mesh size, m")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rigid = reference_case()
    casing = reference_casing(args.element_size)
    flexible = dataclasses.replace(rigid, engine=dataclasses.replace(rigid.engine, casing=casing))
    model = casing.model(rigid.engine.center_of_mass,
                         [(eye_name(names), point) for point, names in flexible.engine_eyes()])
    print(f"casing element size {args.element_size:g} m; one cold reduction (no cache) for both rotors:")
    print("| rotor | FE DOF | casing DOF | modes | mesh (s) | assembly (s) | factorisation + modes (s) | "
          "free-free (s) |")
    print("|---|---|---|---|---|---|---|---|")
    start = time.perf_counter()
    reduced = reduce_casing(model, casing.modes, [LP_ROTOR.frequency, HP_ROTOR.frequency], use_cache=False)
    total = time.perf_counter() - start
    for excitation, one in zip((LP_ROTOR, HP_ROTOR), reduced, strict=True):
        info = one.info
        print(f"| {excitation.name} | {info['fe_dof']} | {one.dof} | {one.n_fixed_interface} | "
              f"{info['mesh_seconds']:.2f} | {info['assembly_seconds']:.2f} | {info['reduction_seconds']:.2f} | "
              f"{info['frequency_seconds']:.2f} |")
    print(f"total {total:.2f} s")
    print("\nwarm frequency-domain runs (medians):")
    print("| rotor | scene DOF rigid | scene DOF flexible | rigid (s) | flexible (s) | ratio |")
    print("|---|---|---|---|---|---|")
    for excitation in (LP_ROTOR, HP_ROTOR):
        _run(rigid, excitation)
        _run(flexible, excitation)
        rigid_runs = [_run(rigid, excitation) for _ in range(args.repeats)]
        flexible_runs = [_run(flexible, excitation) for _ in range(args.repeats)]
        a = statistics.median(t for t, _ in rigid_runs)
        b = statistics.median(t for t, _ in flexible_runs)
        print(f"| {excitation.name} | {rigid_runs[0][1]} | {flexible_runs[0][1]} | {a:.3f} | {b:.3f} | {b / a:.1f} |")


if __name__ == "__main__":
    main()
