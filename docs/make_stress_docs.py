"""Regenerate the fatigue and bore-peak tables of docs/stresses.md.

The reference mount (default link meshes) under its LP and HP rotor
imbalances in the frequency domain, on the preload of its static loads (1 g
and the cruise thrust): per rotor the lowest fatigue factors over the links
(:func:`workbook.solve.fatigue.solve_fatigue`). Then the bore peaks of its
reference load cases on the two meshes refined at the bores
(:func:`workbook.solve.bore_convergence.bore_convergence`): per distinct link
the peak per net-section stress, per load case the highest bore peak.
Replaces the sections between the ``<!-- generated: fatigue -->`` and
``<!-- generated: bore-convergence -->`` markers. Run from anywhere (under a
minute once the links and their refined meshes are cached)::

    OPENBLAS_NUM_THREADS=1 python docs/make_stress_docs.py
"""
from __future__ import annotations

from pathlib import Path

from generated_sections import rewrite_sections

from flexbodies.bore_stress import BORE_DIVISIONS, bore_peaks, convergence_sizes
from workbook.model.load_cases import reference_load_cases
from workbook.model.reference import reference_case
from workbook.solve.bore_convergence import CONVERGENCE_TOLERANCE, bore_convergence
from workbook.solve.fatigue import solve_fatigue
from workbook.solve.load_cases import solve_load_cases

DOCS = Path(__file__).resolve().parent
DOCUMENT = "stresses.md"


def sections() -> dict[str, str]:
    """The generated sections of the page by name."""
    case = reference_case()
    result = solve_fatigue(case)
    rows = ["| rotor | link | peak sigma_a (MPa) | sigma_a, sigma_m at the critical node (MPa) | Goodman | Gerber | where |",
            "|---|---|---|---|---|---|---|"]
    for answer in result.excitations:
        for name, f in sorted(answer.links.items(), key=lambda item: item[1].goodman)[:3]:
            rows.append(f"| {answer.excitation} ({answer.frequency_hz:g} Hz) | {name} | {f.peak_alternating / 1e6:.4f} "
                        f"| {f.alternating / 1e6:.4f}, {f.mean / 1e6:.2f} | {f.goodman:.1f} | {f.gerber:.1f} "
                        f"| {f.region} |")
    peak = max(f.peak_alternating for answer in result.excitations for f in answer.links.values())
    materials = sorted({link.model.material.name for link in case.links})
    rows.append("")
    rows.append(f"The three lowest Goodman factors per rotor ({', '.join(materials)} links). The largest "
                f"alternating stress anywhere is {peak / 1e6:.3f} MPa: the imbalance forces "
                "are small against the links' sizing, and the factors are set by the mean stress of the preload "
                "(about 1/(sigma_m / S_u)).")
    return {"fatigue": "\n".join(rows), "bore-convergence": _bore_section(case)}


def _bore_section(case) -> str:
    coarse, fine = BORE_DIVISIONS
    rows = [f"| links | d/H | FE nodes ({coarse}, {fine} per bore) | K_tn tension, {coarse} / {fine} | change "
            f"| K_tn compression, {coarse} / {fine} | change |", "|---|---|---|---|---|---|---|"]
    models: dict = {}
    for link in case.links:
        models.setdefault(link.model.key(), (link.model, []))[1].append(link.name)
    for model, names in models.values():
        g = model.geometry
        net = 2 * (g.eye_outer_radius - g.bore_radius) * g.thickness
        pair = [bore_peaks(model, size) for size in convergence_sizes(model)]
        tension = [max(p.tension) * net for p in pair]
        compression = [max(p.compression) * net for p in pair]
        rows.append(f"| {', '.join(names)} | {g.bore_radius / g.eye_outer_radius:.2f} "
                    f"| {pair[0].nodes}, {pair[1].nodes} | {tension[0]:.3f} / {tension[1]:.3f} "
                    f"| {tension[1] / tension[0] - 1:+.2%} | {compression[0]:.3f} / {compression[1]:.3f} "
                    f"| {compression[1] / compression[0] - 1:+.2%} |")
    rows += ["", "The highest bore peak of each reference load case:", "",
             "| load case | link | N (kN) | reduced link's peak (MPa) | bore peak, "
             f"{coarse} / {fine} per bore (MPa) | change | converged (<= {CONVERGENCE_TOLERANCE:.0%}) |",
             "|---|---|---|---|---|---|---|"]
    study = bore_convergence(case, solve_load_cases(case, reference_load_cases()))
    for load_case in dict.fromkeys(row.load_case for row in study.rows):
        row = max((r for r in study.rows if r.load_case == load_case), key=lambda r: r.peaks[1])
        rows.append(f"| {row.load_case} | {row.link} | {row.axial_force / 1e3:.1f} | {row.reduced_peak / 1e6:.1f} "
                    f"| {row.peaks[0] / 1e6:.1f} / {row.peaks[1] / 1e6:.1f} | {row.change:+.2%} "
                    f"| {'yes' if row.converged else 'no'} |")
    return "\n".join(rows)


def main() -> None:
    print(rewrite_sections(DOCS / DOCUMENT, sections()))


if __name__ == "__main__":
    main()
