"""The truncation-error estimate against the true error of the kept modes, on the reference and hard cases.

For each case and run: the estimated error of T per direction (the model
card's "truncation error", the leading-order effect of the links' omitted
fixed-interface modes), the true error against the same case with 20
fixed-interface modes per link, their ratio, and the share of the run's
wall time the estimate costs. The hard cases are those of docs/hard-cases.md
that concern the kept modes: hinges of 1e10 N/m (the mounted modes at
105-577 Hz, close to the links' own) and a 90 Hz excitation with the thrust
rods forced to static modes (the low-frequency rule broken). Run with
``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_truncation.py``.
"""
import dataclasses

import numpy as np

import workbook as wb
from workbook.model.reference import LP_ROTOR
from workbook.solve.truncation import complete_model


def cases():
    reference = wb.reference_case()
    yield "reference", reference
    stiff = dataclasses.replace(reference, hinges=tuple(
        dataclasses.replace(h, stiffness=1e10, damping=1e-3 * 1e10) for h in reference.hinges))
    yield "hinges 1e10 N/m", stiff
    near = dataclasses.replace(LP_ROTOR, name="90 Hz", frequency_hz=90.0)
    forced = dataclasses.replace(reference, excitations=(near,), links=tuple(
        dataclasses.replace(link, modes="static") if link.name.startswith("thrust") else link
        for link in reference.links))
    yield "90 Hz, thrust rods static", forced


def main() -> None:
    print(f"{'case':<28}{'run':<10}{'dir':>4}{'estimate %':>12}{'true %':>10}{'ratio':>8}{'cost %':>8}")
    for label, case in cases():
        kept, complete = wb.run_case(case), wb.run_case(complete_model(case))
        for run, full in zip(kept.runs, complete.runs, strict=True):
            true = np.abs(run.transmissibility - full.transmissibility) / full.transmissibility
            timings = kept.model_cards[run.name].timings
            cost = timings.get("truncation estimate", np.nan) / sum(timings.values())
            for axis, estimate, error in zip("xyz", run.truncation_error, true, strict=True):
                print(f"{label:<28}{run.name:<10}{axis:>4}{100 * estimate:>12.3g}{100 * error:>10.3g}"
                      f"{estimate / error:>8.2f}{100 * cost:>8.1f}")


if __name__ == "__main__":
    main()
