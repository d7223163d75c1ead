"""Regenerate the fatigue table of docs/stresses.md.

The reference mount (default link meshes) under its LP and HP rotor
imbalances in the frequency domain, on the preload of its static loads (1 g
and the cruise thrust): per rotor the lowest fatigue factors over the links
(:func:`workbook.solve.fatigue.solve_fatigue`). Replaces the section between
the ``<!-- generated: fatigue -->`` markers. Run from anywhere (under a
minute once the links are cached)::

    OPENBLAS_NUM_THREADS=1 python docs/make_stress_docs.py
"""
from __future__ import annotations

from pathlib import Path

from generated_sections import rewrite_sections

from workbook.model.reference import reference_case
from workbook.solve.fatigue import solve_fatigue

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
    return {"fatigue": "\n".join(rows)}


def main() -> None:
    print(rewrite_sections(DOCS / DOCUMENT, sections()))


if __name__ == "__main__":
    main()
