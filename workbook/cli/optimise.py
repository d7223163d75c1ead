"""``mountwb optimise [CASE] [--vary NAME=LOW:HIGH ...] [--objective worst|weighted] [--constraint C ...]
[--band EXCITATION=LOW:HIGH ...] [--starts N] [--workers N] [--section-step S] [--iterations N] [--pareto [A,B]]
[--output DIR] [--json]``.

Without ``--vary`` the problem is the case workbook's Optimise sheet
(:mod:`workbook.excel.optimise_sheet`), the options' constraints and bands
added to it, their objective and starts replacing its.

Optimises the case's design on the fast linear mount
(:mod:`workbook.design.optimise`): prints the before/after table (the
objective, T per run and direction, every constraint with its value and
whether it is active, each variable), each start's end, and the optimum's
model card; with ``section_scale`` varied, each section scale tried with
its cost (link reductions and preparation); ``--output DIR`` writes the optimised case (``optimum.json``,
which ``mountwb run`` runs, and ``optimum.xlsx`` when a case workbook can
hold it, its Optimise sheet the problem solved, the options it cannot hold
named), the table, the history and the plot.
"""
from __future__ import annotations

import argparse
import json
import os
from typing import TYPE_CHECKING, Callable

from workbook.cli.loading import is_workbook, load_case
from workbook.cli.outputs import output_folder
from workbook.cli.params import at_least_one, parse_ranges
from workbook.design.bands import BAND_POINTS, band_text
from workbook.design.section_search import SECTION, SECTION_STEP
from workbook.errors import UsageError

if TYPE_CHECKING:
    from workbook.excel.optimise_sheet import OptimiseSheet

__all__ = ["arguments"]

#: SLSQP iterations per start at most, by default.
ITERATIONS = 60


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("--run", metavar="R", help="case workbook: take the case of this row of the Runs sheet")
    parser.add_argument("--vary", action="append", default=[], metavar="NAME=LOW:HIGH",
                        help="a design variable and its range, SI units (a study parameter: hinge_stiffness, "
                             "hinge_loss_factor, hinge_damping, per group and direction as "
                             "hinge_stiffness/front/axial; transducer_stiffness; engine_mass; section_scale, the links' "
                             "section, searched over a grid of scales, a new link reduction each); repeatable; "
                             "none: the problem of the case workbook's Optimise sheet")
    parser.add_argument("--objective", choices=("worst", "weighted"),
                        help="worst: the worst T over runs and directions, dB (default); weighted: the mean of T")
    parser.add_argument("--constraint", action="append", default=[], metavar="C",
                        help="displacement<=M, sag<=M (the engine CG's static displacement under the preload), "
                             "rotation<=RAD, modes_outside=LOW:HIGH (Hz), fatigue>=N (every link's lowest "
                             "Goodman factor) or margin>=M (every link's margin of safety under the case's limit "
                             "load cases); repeatable")
    parser.add_argument("--band", action="append", default=[], metavar="EXCITATION=LOW:HIGH",
                        help="a rotor's speed band, Hz (idle to red line): its T judged over the band "
                             "(e.g. 'LP rotor=40:62'); repeatable")
    parser.add_argument("--band-points", type=int, default=BAND_POINTS,
                        help=f"speeds per band, evenly spaced (default {BAND_POINTS}); the peaks between them "
                             "are found as well")
    parser.add_argument("--starts", type=at_least_one, help="SLSQP starts: the case's design, then a Latin "
                        "hypercube (default 3)")
    parser.add_argument("--workers", type=at_least_one, default=os.cpu_count() or 1, metavar="N",
                        help="processes the starts run in (default: every core); the result is the same as with 1")
    parser.add_argument("--section-step", type=float, default=SECTION_STEP, metavar="S",
                        help=f"section_scale: the largest step between the scales tried (default {SECTION_STEP:g})")
    parser.add_argument("--iterations", type=at_least_one, default=ITERATIONS, metavar="N",
                        help=f"SLSQP iterations per start at most (default {ITERATIONS})")
    parser.add_argument("--pareto", nargs="?", const="worst,displacement", metavar="A,B",
                        help="also the NSGA-II front of two objectives (default worst,displacement; each worst, "
                             "worst/EXCITATION, displacement, sag or rotation)")
    parser.add_argument("--population", type=at_least_one, default=50, help="--pareto: designs per generation (default 50)")
    parser.add_argument("--generations", type=at_least_one, default=20, help="--pareto: generations (default 20)")
    parser.add_argument("--output", type=output_folder, metavar="DIR", help="write the optimised case, the table, history and plot here")
    parser.add_argument("--json", action="store_true", help="print the table and the starts as JSON")
    return run


def _sheet(path: str | None) -> "OptimiseSheet":
    """The Optimise sheet of the case workbook *path*.

    Raises
    ------
    UsageError
        *path* is no case workbook, or its Optimise sheet gives no variable.
    """
    from workbook.excel.reader import read_workbook

    if path is None or not is_workbook(path):
        raise UsageError("give the design variables as --vary NAME=LOW:HIGH, or a case workbook whose Optimise "
                         "sheet lists them")
    sheet = read_workbook(path).optimise
    if sheet is None or not sheet.variables:
        raise UsageError(f"{path}: no --vary given and its Optimise sheet lists no variable (a row of kind "
                         "'variable' with a name, low and high)")
    return sheet


def _not_held(args, varied: dict, written: list) -> list[str]:
    """The options given that the written optimum's Optimise sheet cannot hold (none: no optimum.xlsx; with
    bands there is none, so ``--band-points`` never counts)."""
    if not any(path.name == "optimum.xlsx" for path in written):
        return []
    given = (("--section-step", args.section_step if SECTION in varied else SECTION_STEP, SECTION_STEP),
             ("--iterations", args.iterations, ITERATIONS), ("--pareto", args.pareto, None))
    return [f"{option} {value}" for option, value, default in given if value != default]


def run(args) -> int:
    from workbook.design.optimise import optimise
    from workbook.excel.optimise_sheet import OptimiseSheet

    objectives = tuple(args.pareto.split(",")) if args.pareto else None
    if objectives is not None and len(objectives) != 2:
        raise UsageError(f"--pareto {args.pareto!r}: expected two objectives A,B")
    case = load_case(args.case, run=args.run)
    sheet = _sheet(args.case) if not args.vary else OptimiseSheet()
    variables = parse_ranges(args.vary) if args.vary else sheet.variables
    bands = {**sheet.bands, **dict(band_text(text) for text in args.band)}
    objective = args.objective or sheet.objective or "worst"
    result = optimise(case, variables, objective=objective, constraints=[*sheet.constraints, *args.constraint],
                      starts=args.starts or sheet.starts or 3, maxiter=args.iterations, pareto_objectives=objectives,
                      population=args.population, generations=args.generations, bands=bands,
                      band_points=args.band_points, workers=args.workers, section_step=args.section_step)
    written = result.write(args.output) if args.output else []
    not_held = _not_held(args, result.values, written)
    if args.json:
        table = result.table.reset_index()
        print(json.dumps({"case": case.name, "objective": objective, "values": result.values,
                          "table": table.to_dict(orient="records"), "starts": result.starts,
                          "evaluations": result.evaluations, "seconds": result.seconds,
                          "fast_difference": result.fast_difference, "written": [str(p) for p in written],
                          "not_held": not_held,
                          "sections": None if result.sections is None else result.sections.to_dict(orient="records")},
                         indent=1, default=float))
        return 0
    print(f"{case.name}: {len(result.variables)} variable(s), {result.evaluations} designs with derivatives, "
          f"{result.seconds:.1f} s; T of the optimum by the full pipeline (the fast path differs by "
          f"{result.fast_difference:.1e})\n")
    print(result.table.to_string(float_format=lambda v: f"{v:.6g}"))
    print("\nstarts:")
    for end in result.starts:
        print(f"  {end['start']}: objective {end['objective']:.6g}, violation {end['violation']:.1e}, "
              f"{end['iterations']} iterations: {end['message']}")
    if result.sections is not None:
        sections = result.sections
        print(f"\nsection scales tried: {len(sections)} (scale 1: the case's own links), each other "
              f"{sections['distinct link reductions'].max()} distinct link reductions (computed, or loaded from the "
              f"cache): {sections['reduction s'].sum():.1f} s reducing, {sections['preparation s'].sum():.1f} s "
              "preparing in all")
        print(sections.to_string(index=False, float_format=lambda v: f"{v:.6g}"))
    if result.pareto is not None:
        print(f"\nPareto front ({', '.join(result.pareto.objectives)}): {len(result.pareto.designs)} designs, "
              f"{result.pareto.evaluations} evaluations, {result.pareto.seconds:.1f} s")
        print(result.pareto.designs.to_string(float_format=lambda v: f"{v:.5g}"))
    for card in result.result.model_cards.values():
        print("\n" + card.to_text())
    for path in written:
        print(f"written: {path}")
    if not_held:
        print(f"optimum.xlsx's Optimise sheet holds the problem solved but not {', '.join(not_held)}: give "
              "them again to 'mountwb optimise optimum.xlsx'")
    return 0
