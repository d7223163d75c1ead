"""Regenerate the load-case, fatigue and Miner tables of docs/stresses.md and the strength table of the README.

The reference mount (default link meshes): its limit load cases
(:func:`workbook.model.load_cases.reference_load_cases`, lowest margins per
load case, :func:`workbook.solve.load_cases.solve_load_cases`); its LP and
HP rotor imbalances in the frequency domain on the preload of its static
loads (1 g and the cruise thrust), per rotor the lowest fatigue factors over
the links; and the Miner sums of its speed spectra
(:func:`workbook.model.spectrum.reference_speed_spectra`), all by
:func:`workbook.solve.fatigue.solve_fatigue`. Replaces the sections between
the ``<!-- generated: ... -->`` markers. Then the bore peaks of its
reference load cases on the two meshes refined at the bores
(:func:`workbook.solve.bore_convergence.bore_convergence`): per distinct link
the peak per net-section stress, per load case the highest bore peak; and the
conservative fatigue factors at the bores of the LP and HP imbalances
(:func:`workbook.solve.bore_fatigue.bore_fatigue`). Run
from anywhere (a few minutes once the links and their refined meshes are
cached)::

    OPENBLAS_NUM_THREADS=1 python docs/make_stress_docs.py
"""
from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

from generated_sections import rewrite_sections

from flexbodies.bore_stress import BORE_DIVISIONS, bore_peaks, convergence_sizes
from workbook.model.load_cases import reference_load_cases
from workbook.model.reference import reference_case
from workbook.model.spectrum import reference_speed_spectra
from workbook.solve.bore_convergence import CONVERGENCE_TOLERANCE, bore_convergence
from workbook.solve.bore_fatigue import bore_fatigue
from workbook.solve.fatigue import solve_fatigue
from workbook.solve.load_cases import solve_load_cases

DOCS = Path(__file__).resolve().parent
DOCUMENT = "stresses.md"
#: The README's generated sections (the rest of the sections are the document's).
README = DOCS.parent / "README.md"
README_SECTIONS = ("strength",)


@functools.lru_cache(maxsize=1)
def _solved():
    case = dataclasses.replace(reference_case(), speed_spectra=reference_speed_spectra())
    return case, solve_load_cases(case, reference_load_cases()), solve_fatigue(case)


def _lowest_margins(results, bores) -> list[str]:
    rows = ["| load case | lowest MS_y | lowest MS_u | link, where | at the bores (pin load, sub-model): "
            "lowest MS_y, MS_u, link |", "|---|---|---|---|---|"]
    for result in results:
        stressed = [s for s in result.links.values() if s.yield_margin is not None]
        worst = min(stressed, key=lambda s: s.ultimate_margin)
        at_bores = [r for r in bores.rows if r.load_case == result.load_case.name and r.ultimate_margin is not None]
        bore = min(at_bores, key=lambda r: r.ultimate_margin)
        rows.append(f"| {result.load_case.name} | {min(s.yield_margin for s in stressed):.3g} "
                    f"| {worst.ultimate_margin:.3g} | {worst.link}, {worst.von_mises_region} "
                    f"| {min(r.yield_margin for r in at_bores):.3g}, {bore.ultimate_margin:.3g}, {bore.link} |")
    return rows


def _load_cases(results, bores) -> str:
    nominal = [abs(s.nominal_stress) for r in results for s in r.links.values() if s.nominal_stress is not None]
    worst = min(results, key=lambda r: min(s.ultimate_margin for s in r.links.values() if s.ultimate_margin is not None))
    worst_nominal = [abs(s.nominal_stress) for s in worst.links.values() if s.nominal_stress is not None]
    return "\n".join(_lowest_margins(results, bores) + [
        "", f"Factor of safety {results[0].load_case.factor_of_safety:g}. The reference links are sized for stiffness, "
        f"not strength: at most {max(nominal) / 1e6:.0f} MPa nominal shank stress in any load case, "
        f"{min(worst_nominal) / 1e6:.0f} to {max(worst_nominal) / 1e6:.0f} MPa in the links of the worst "
        f"({worst.load_case.name})."])


def _fatigue_rows(result, per_rotor: int) -> list[str]:
    rows = ["| rotor | link | peak sigma_a (MPa) | sigma_a, sigma_m at the critical node (MPa) | Goodman | Gerber | where |",
            "|---|---|---|---|---|---|---|"]
    for answer in result.excitations:
        for name, f in sorted(answer.links.items(), key=lambda item: item[1].goodman)[:per_rotor]:
            rows.append(f"| {answer.excitation} ({answer.frequency_hz:g} Hz) | {name} | {f.peak_alternating / 1e6:.4f} "
                        f"| {f.alternating / 1e6:.4f}, {f.mean / 1e6:.2f} | {f.goodman:.1f} | {f.gerber:.1f} "
                        f"| {f.region} |")
    return rows


def _fatigue(case, result) -> str:
    peak = max(f.peak_alternating for answer in result.excitations for f in answer.links.values())
    materials = sorted({link.model.material.name for link in case.links})
    return "\n".join(_fatigue_rows(result, 3) + [
        "", f"The three lowest Goodman factors per rotor ({', '.join(materials)} links). The largest "
        f"alternating stress anywhere is {peak / 1e6:.3f} MPa: the imbalance forces "
        "are small against the links' sizing, and the factors are set by the mean stress of the preload "
        "(about 1/(sigma_m / S_u))."])


def _miner(result) -> str:
    rows = ["| rotor | hours | speeds solved (Hz) | largest sigma_ar (MPa), link, at (Hz) | largest Miner D |",
            "|---|---|---|---|---|"]
    for answer in result.spectra:
        speeds = [f for f, _, _ in answer.speeds]
        worst = max(answer.links.values(), key=lambda d: d.equivalent)
        rows.append(f"| {answer.spectrum.excitation} | {answer.spectrum.hours:g} | {len(speeds)}, "
                    f"{min(speeds):g} to {max(speeds):g} | {worst.equivalent / 1e6:.4f}, {worst.link}, "
                    f"{worst.speed_hz:g} | {max(d.damage for d in answer.links.values()):g} |")
    return "\n".join(rows)


def _readme(case, loads, bores, fatigue) -> str:
    return "\n".join(
        ["Limit load cases (`reference_load_cases()`), lowest margins of safety over the links: of the reduced "
         "links' own peaks (bores tied rigidly) and of the bore peaks under the pins' bearing load "
         "(`docs/stresses.md`):", "",
         *_lowest_margins(loads, bores), "",
         "Fatigue factors on the preload (1 g, cruise thrust) at the LP and HP rotor speeds, the lowest per rotor:",
         "", *_fatigue_rows(fatigue, 1), "",
         "Miner sums over the illustrative speed spectra (`reference_speed_spectra()`, "
         + ", ".join(f"{a.spectrum.excitation} {a.spectrum.hours:g} h" for a in fatigue.spectra) + "): largest D "
         + ", ".join(f"{max(d.damage for d in a.links.values()):g}" for a in fatigue.spectra)
         + " (every stress below the endurance strength)."])


def sections() -> dict[str, str]:
    """The generated sections by name: those of the page and those of the README (:data:`README_SECTIONS`)."""
    case, loads, fatigue = _solved()
    bores = bore_convergence(case, loads)
    return {"load-cases": _load_cases(loads, bores), "fatigue": _fatigue(case, fatigue), "miner": _miner(fatigue),
            "strength": _readme(case, loads, bores, fatigue), "bore-convergence": _bore_section(case, bores),
            "bore-fatigue": _bore_fatigue(bore_fatigue(case, fatigue))}


def _bore_fatigue(rows) -> str:
    table = ["| rotor | link | N_0 (kN) | N^ amplitude (N) | sigma_m, sigma_a at the bore (MPa) | Goodman at the bore "
             "| reduced link's Goodman |", "|---|---|---|---|---|---|---|"]
    for excitation in dict.fromkeys(row.excitation for row in rows):
        ours = sorted((row for row in rows if row.excitation == excitation), key=lambda row: row.goodman)
        for row in ours[:3]:
            table.append(f"| {row.excitation} ({row.frequency_hz:g} Hz) | {row.link} | {row.axial_force / 1e3:.2f} "
                         f"| {row.axial_amplitude:.3g} | {row.mean / 1e6:.2f}, {row.alternating / 1e6:.4f} "
                         f"| {row.goodman:.1f} | {row.reduced_goodman:.1f} |")
    ratio = [row.reduced_goodman / row.goodman for row in rows if row.axial_force > 0.1 * max(r.axial_force for r in rows)]
    below = sorted({row.link for row in rows if row.reduced_goodman < row.goodman})
    return "\n".join(table + [
        "", f"The three lowest bore factors per rotor. Where the link carries a preload (N_0 above a tenth of the "
        f"largest), the bore factor is {min(ratio):.1f} to {max(ratio):.1f} times lower than the reduced link's: "
        "the bore peak per newton against the rigidly tied bore's. "
        + (f"The bore factor leaves out what is not axial: where the link carries little axial preload the reduced "
           f"link's factor is the lower ({', '.join(below)}); take the lower of the two." if below else
           "Take the lower of the two factors.")])


def _bore_section(case, study) -> str:
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
    for load_case in dict.fromkeys(row.load_case for row in study.rows):
        row = max((r for r in study.rows if r.load_case == load_case), key=lambda r: r.peaks[1])
        rows.append(f"| {row.load_case} | {row.link} | {row.axial_force / 1e3:.1f} | {row.reduced_peak / 1e6:.1f} "
                    f"| {row.peaks[0] / 1e6:.1f} / {row.peaks[1] / 1e6:.1f} | {row.change:+.2%} "
                    f"| {'yes' if row.converged else 'no'} |")
    return "\n".join(rows)


def main() -> None:
    generated = sections()
    print(rewrite_sections(DOCS / DOCUMENT, {k: v for k, v in generated.items() if k not in README_SECTIONS}))
    print(rewrite_sections(README, {k: generated[k] for k in README_SECTIONS}))


if __name__ == "__main__":
    main()
