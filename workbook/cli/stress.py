"""``mountwb stress [CASE] [--run R] [--load-case NAME] [--vtu DIR] [--png DIR] [--json]``.

Everything the package says of the links' strength: the static margins of
the limit load cases (the tables of ``mountwb loads``,
:mod:`workbook.solve.load_cases`), then per rotor excitation and link the
dynamic stress on the preload and the fatigue safety factors by Goodman and
Gerber, and Haigh for a material with a Haigh curve (:mod:`workbook.solve.fatigue`). ``--vtu DIR`` writes each flexible
link's surface with its preload stress, the dynamic stress amplitude of each
excitation and its first mode shapes, one VTU file per link (ParaView);
``--png DIR`` draws the same stress fields on each link's shape, one PNG per
link.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path
from typing import Callable

from workbook.cli.loading import load_case
from workbook.cli.outputs import output_folder

__all__ = ["arguments", "print_bore_convergence", "print_bore_fatigue", "print_fatigue_factors"]

#: Mode shapes written with each link's VTU file.
VTU_MODES = 6


def arguments(parser: argparse.ArgumentParser) -> Callable:
    from workbook.cli.loads import add_load_case_arguments

    add_load_case_arguments(parser)
    parser.add_argument("--vtu", type=output_folder, metavar="DIR", help="write each link's mesh with its stress fields as DIR/<link>.vtu")
    parser.add_argument("--png", type=output_folder, metavar="DIR", help="draw each link's stress fields on its shape as DIR/<link>.png")
    return run


def run(args) -> int:
    from workbook.cli.loads import chosen_load_cases, print_load_cases
    from workbook.solve.bore_convergence import bore_convergence
    from workbook.solve.bore_fatigue import bore_fatigue
    from workbook.solve.fatigue import solve_fatigue
    from workbook.solve.load_cases import solve_load_cases

    case = load_case(args.case, run=args.run)
    chosen = chosen_load_cases(case, args.load_case)
    fatigue = solve_fatigue(case)
    results = solve_load_cases(case, chosen) if chosen else []
    bores = bore_convergence(case, results)
    at_bores = bore_fatigue(case, fatigue)
    if args.vtu:
        write_fields(Path(args.vtu), fatigue)
    if args.png:
        draw_fields(Path(args.png), fatigue)
    if args.json:
        print(json.dumps({"case": case.name, "load_cases": [r.to_dict() for r in results],
                          "bore_convergence": bores.to_dict(), "fatigue": fatigue.to_dict(),
                          "bore_fatigue": [dataclasses.asdict(row) for row in at_bores]}, indent=1))
        return 0
    print_load_cases(case, results)
    print_bore_convergence(bores)
    print_fatigue_factors(fatigue)
    print_bore_fatigue(at_bores)
    print_miner_sums(fatigue)
    print(f"\nstress recovery and fatigue factors, all links and excitations: {fatigue.stress_seconds:.3f} s")
    if args.vtu:
        print(f"VTU files: {args.vtu}/<link>.vtu")
    if args.png:
        print(f"PNG files: {args.png}/<link>.png")
    return 0


def print_fatigue_factors(fatigue) -> None:
    """Per excitation and link of a :class:`~workbook.solve.fatigue.FatigueResult` its stresses and fatigue
    factors (the Haigh column when a link's material has a Haigh curve)."""
    print("\nfatigue on the preload (the case's static loads): alternating stress sigma_a = largest von Mises "
          "over the cycle, mean sigma_m = von Mises of the preload stress signed by its hydrostatic part; "
          "Goodman 1/n = sigma_a/S_e + sigma_m/S_u, Gerber n sigma_a/S_e + (n sigma_m/S_u)^2 = 1")
    haigh = any(f.haigh is not None for answer in fatigue.excitations for f in answer.links.values())
    if haigh:
        print("Haigh: (n sigma_m, n sigma_a) on the material's Haigh curve (the proportional load line; '-' a "
              "material without one); Gerber and Haigh the lowest over the link's nodes, at its worst node for each")
    haigh_header = f" {'Haigh':>9s}" if haigh else ""
    for answer in fatigue.excitations:
        print(f"\n{answer.excitation} ({answer.frequency_hz:g} Hz)")
        print(f"  {'link':16s} {'peak sigma_a MPa':>16s} {'sigma_a MPa':>11s} {'sigma_m MPa':>11s} "
              f"{'Goodman':>9s} {'Gerber':>9s}{haigh_header} {'at':>6s}")
        for name, f in answer.links.items():
            column = "" if not haigh else f" {'-':>9s}" if f.haigh is None else f" {f.haigh:9.3g}"
            print(f"  {name:16s} {f.peak_alternating / 1e6:16.4f} {f.alternating / 1e6:11.4f} {f.mean / 1e6:11.2f} "
                  f"{f.goodman:9.3g} {f.gerber:9.3g}{column} {f.region:>6s}")


def print_bore_fatigue(rows) -> None:
    """The bore fatigue factors (:func:`~workbook.solve.bore_fatigue.bore_fatigue`) beside the reduced links'."""
    if not rows:
        return
    print("\nfatigue at the bores (the bore sub-model under the pins' bearing load, a two-force link): "
          "sigma_m = k(sign N_0) |N_0|, sigma_a = max(k_t, k_c) |N^|, k the sub-model's peak per newton; "
          "conservative: both peaks at one point, no credit for a compressive preload")
    print(f"  {'excitation':20s} {'link':16s} {'N_0 kN':>8s} {'|N^| N':>9s} {'sigma_m MPa':>11s} "
          f"{'sigma_a MPa':>11s} {'Goodman':>9s} {'reduced link':>12s}")
    for row in rows:
        print(f"  {row.excitation:20s} {row.link:16s} {row.axial_force / 1e3:8.2f} {row.axial_amplitude:9.3g} "
              f"{row.mean / 1e6:11.2f} {row.alternating / 1e6:11.4f} {row.goodman:9.3g} {row.reduced_goodman:12.3g}")


def print_miner_sums(fatigue) -> None:
    """The Miner sums of a :class:`~workbook.solve.fatigue.FatigueResult`'s speed spectra and each link's life."""
    if not fatigue.spectra:
        return
    life = fatigue.life_hours()
    for answer in fatigue.spectra:
        print(f"\nMiner sum over the speed spectrum of {answer.spectrum.excitation} ({answer.spectrum.hours:g} h, "
              f"{len(answer.speeds)} speeds; Goodman-equivalent stress sigma_ar, none below the endurance strength)")
        print(f"  {'link':16s} {'damage D':>10s} {'life h':>10s} {'sigma_ar MPa':>12s} {'at Hz':>8s} {'where':>6s}")
        for name, d in answer.links.items():
            print(f"  {name:16s} {d.damage:10.3g} {d.life_hours:10.3g} {d.equivalent / 1e6:12.4f} {d.speed_hz:8.4g} "
                  f"{d.region:>6s}")
    print("  life under all spectra: " + ", ".join(f"{name} {hours:.3g} h" for name, hours in life.items()))


def draw_fields(directory: Path, fatigue) -> list[Path]:
    """Draw ``directory/<link>.png`` for each flexible link (:meth:`~workbook.solve.fatigue.FatigueResult.plot`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from workbook.answers.saving import save_figure

    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for name in fatigue.reduced:
        figure = fatigue.plot(name)
        written.append(save_figure(figure, directory / f"{name}.png"))
        plt.close(figure)
    return written


def print_bore_convergence(study) -> None:
    """The bore peaks of a :class:`~workbook.solve.bore_convergence.BoreStudy` on its two meshes, and their cost."""
    from flexbodies.bore_stress import BORE_DIVISIONS
    from workbook.solve.bore_convergence import CONVERGENCE_TOLERANCE

    if not study.rows:
        return
    coarse, fine = BORE_DIVISIONS
    print(f"\nbore peak von Mises under the pin's bearing load (cosine pressure), on meshes of {coarse} and {fine} "
          f"elements around the bore; the reduced link ties its bores rigidly, its own peak beside; margins of "
          f"safety of the {fine}/bore peak")
    print(f"  {'load case':30s} {'link':14s} {'N kN':>8s} {'reduced MPa':>11s} {f'{coarse}/bore MPa':>12s} "
          f"{f'{fine}/bore MPa':>12s} {'change':>7s} {'MS_y':>6s} {'MS_u':>6s}  converged")
    for row in study.rows:
        reduced = "-" if row.reduced_peak is None else f"{row.reduced_peak / 1e6:.1f}"
        state = "yes" if row.converged else f"NO: change above {CONVERGENCE_TOLERANCE:.0%}"
        margins = " ".join("     -" if m is None else f"{m:6.2f}" for m in (row.yield_margin, row.ultimate_margin))
        print(f"  {row.load_case:30s} {row.link:14s} {row.axial_force / 1e3:8.1f} {reduced:>11s} "
              f"{row.peaks[0] / 1e6:12.1f} {row.peaks[1] / 1e6:12.1f} {row.change:7.1%} {margins}  {state}")
    bad = [row for row in study.rows if not row.converged]
    if bad:
        print(f"  warning: {len(bad)} bore peak(s) changed by more than {CONVERGENCE_TOLERANCE:.0%} between the two "
              "meshes: not converged, do not use them as they are")
    nodes = max(max(pair) for pair in study.meshes.values())
    seconds = sum(sum(pair) for pair in study.seconds.values())
    print(f"  cost: {2 * len(study.meshes)} refined sub-models of {len(study.meshes)} distinct links (up to {nodes} "
          f"FE nodes), {seconds:.0f} s to mesh, assemble and solve when first asked; their peaks are kept in the "
          "link cache and loaded since")
    if study.skipped:
        print(f"  not refined (links from mesh files): {', '.join(study.skipped)}")


def write_fields(directory: Path, fatigue) -> list[Path]:
    """Write ``directory/<link>.vtu`` for each flexible link of a :class:`~workbook.solve.fatigue.FatigueResult`.

    Point data: ``preload stress`` (Voigt xx, yy, zz, yz, xz, xy, Pa, link
    frame) and its ``preload von Mises``; per excitation its ``alternating
    von Mises`` and the real and imaginary parts of its stress amplitude
    (Pa); the first :data:`VTU_MODES` mode shapes.
    """
    from flexbodies.stress import alternating_von_mises, von_mises, write_vtu

    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for name, link in fatigue.reduced.items():
        mean = fatigue.mean_stress[name]
        fields = {"preload stress": mean, "preload von Mises": von_mises(mean)}
        for answer in fatigue.excitations:
            amplitude = answer.amplitudes[name]
            fields[f"{answer.excitation} alternating von Mises"] = alternating_von_mises(amplitude)
            fields[f"{answer.excitation} amplitude (real)"] = amplitude.real
            fields[f"{answer.excitation} amplitude (imaginary)"] = amplitude.imag
        path = directory / f"{name}.vtu"
        write_vtu(path, link, fields, modes=VTU_MODES)
        written.append(path)
    return written
