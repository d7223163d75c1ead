"""Regenerate the reference-mount figure and tables in docs/.

Writes ``docs/reference-mount.png`` (the layout in three views) and replaces
the generated tables in ``docs/reference-mount.md`` (between the
``<!-- generated: ... -->`` markers) with tables made from
``workbook.model.reference.reference_case()``, so the committed docs are what the
code builds. Run from anywhere::

    python docs/make_reference_docs.py
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")

from generated_sections import replace_section  # noqa: E402

from workbook.model.case import AnalysisSettings, Case  # noqa: E402
from workbook.model.drawing import hinge_table, link_table, markdown_table, plot_layout  # noqa: E402
from workbook.model.reference import HINGE_DAMPING_MODELS, reference_case  # noqa: E402
from workbook.scene.build import build_scene, reduce_links  # noqa: E402
from workbook.solve.harmonic import harmonic_model  # noqa: E402
from workbook.solve.modes import modes_of, mounted_modes  # noqa: E402
from workbook.solve.pipeline import run_case  # noqa: E402
from workbook.solve.preload import solve_preload  # noqa: E402

DOCS = Path(__file__).resolve().parent


def main() -> None:
    case = reference_case()
    figure = plot_layout(case)
    figure.savefig(DOCS / "reference-mount.png", dpi=110)

    reduced = reduce_links(case, case.excitations[-1])
    with build_scene(case, reduced=reduced) as scene:
        preload = solve_preload(scene)
        mounted = mounted_modes(modes_of(harmonic_model(scene).linearization))

    modes = "\n".join(["| mode | frequency (Hz) | damping ratio (%) | engine motion |", "|---|---|---|---|"] + [
        f"| {i + 1} | {m.frequency_hz:.2f} | {100 * m.damping_ratio:.2f} | {m.description} |"
        for i, m in enumerate(mounted)])
    forces = "\n".join(["| hinge | Fx (N) | Fy (N) | Fz (N) |", "|---|---|---|---|"] + [
        f"| {name} | {round(f[0])} | {round(f[1])} | {round(f[2])} |" for name, f in preload.hinge_forces.items()] + [
        f"| **pylon sum** | {round(preload.pylon_force[0])} | {round(preload.pylon_force[1])} | "
        f"{round(preload.pylon_force[2])} |"])

    path = DOCS / "reference-mount.md"
    text = path.read_text()
    for name, content in (("links", markdown_table(link_table(case, reduced))),
                          ("hinges", markdown_table(hinge_table(case))),
                          ("modes", modes), ("static forces", forces),
                          ("efficiency", _efficiency_table(case)), ("damping models", _damping_models())):
        text = replace_section(text, name, content, "reference-mount.md")
    path.write_text(text)
    print(f"wrote {DOCS / 'reference-mount.png'} and the tables of {path}")


def _in_frequency_domain(case: Case) -> Case:
    return dataclasses.replace(case, analysis=AnalysisSettings(method="frequency"))


def _efficiency_table(case: Case) -> str:
    """Isolation efficiency of the LP and HP runs, flexible and rigid links (frequency domain)."""
    rows = ["| links | run | f (Hz) | eta x (%) | eta y (%) | eta z (%) |", "|---|---|---|---|---|---|"]
    for label, variant in (("flexible (auto modes)", case), ("rigid (`--rigid`)", case.with_rigid_links())):
        result = run_case(_in_frequency_domain(variant))
        for run in result.runs:
            eta = 100 * (1 - run.transmissibility)
            rows.append(f"| {label} | {run.name} | {run.frequency_hz:g} | {eta[0]:.2f} | {eta[1]:.2f} | {eta[2]:.2f} |")
    return "\n".join(rows)


def _damping_models() -> str:
    """T in dB per direction of the LP and HP runs under each hinge damping model (frequency domain)."""
    rows = ["| hinge damping | run | f (Hz) | T x (dB) | T y (dB) | T z (dB) | mounted-mode zeta (%) |",
            "|---|---|---|---|---|---|---|"]
    results = {}
    for model in HINGE_DAMPING_MODELS[::-1]:
        result = run_case(_in_frequency_domain(reference_case(hinge_damping=model)))
        results[model] = result
        for run in result.runs:
            zeta = [z for _, z, _ in result.model_cards[run.name].mounted_modes]
            db = 20 * np.log10(run.transmissibility)
            rows.append(f"| {model} | {run.name} | {run.frequency_hz:g} | {db[0]:.2f} | {db[1]:.2f} | {db[2]:.2f} | "
                        f"{100 * min(zeta):.2f}-{100 * max(zeta):.2f} |")
    old, new = results["viscous"], results["loss factor"]
    for run in new.runs:
        change = 20 * np.log10(run.transmissibility / old.run(run.name).transmissibility)
        rows.append(f"| change | {run.name} | {run.frequency_hz:g} | {change[0]:+.2f} | {change[1]:+.2f} | "
                    f"{change[2]:+.2f} | |")
    return "\n".join(rows)


if __name__ == "__main__":
    main()
