"""``mountwb loads [CASE] [--run R] [--load-case NAME] [--rigid] [--json]``.

The case's limit load cases (:mod:`workbook.solve.load_cases`), or, for the
reference mount and a case without any, the documented set of
:func:`workbook.model.load_cases.reference_load_cases`: per load case the
engine's static displacement, then a table per link: axial force, nominal
shank stress, peak von Mises and largest principal stress and where, the
margins of safety against yield (limit load) and ultimate strength
(ultimate load).
"""
from __future__ import annotations

import argparse
import json
from typing import Callable

from workbook.cli.loading import load_case
from workbook.errors import UsageError

__all__ = ["arguments", "add_load_case_arguments", "chosen_load_cases", "print_load_cases"]


def add_load_case_arguments(parser: argparse.ArgumentParser) -> None:
    """The options ``mountwb loads`` and ``mountwb stress`` share: the case, its row, the load cases, JSON."""
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("--run", metavar="R", help="case workbook: take the case of this row of the Runs sheet")
    parser.add_argument("--load-case", dest="load_case", metavar="NAME", action="append",
                        help="solve only this load case (repeatable)")
    parser.add_argument("--json", action="store_true", help="print everything as JSON (SI units) instead of tables")


def arguments(parser: argparse.ArgumentParser) -> Callable:
    add_load_case_arguments(parser)
    parser.add_argument("--rigid", action="store_true", help="make every link rigid (forces only, no stresses)")
    return run


def _mpa(value) -> str:
    return "-" if value is None else f"{value / 1e6:.1f}"


def _triple(values) -> str:
    return "(" + ", ".join(f"{float(v):.4g}" for v in values) + ")"


def _margin(value) -> str:
    return "-" if value is None else f"{value:.2f}"


def chosen_load_cases(case, names) -> tuple:
    """The load cases of *case* (or the reference set when it has none), only those *names* when given.

    Raises
    ------
    UsageError
        A name that is not a load case of the case.
    """
    from workbook.model.load_cases import reference_load_cases

    chosen = case.load_cases or reference_load_cases()
    if names:
        known = {c.name: c for c in chosen}
        missing = [name for name in names if name not in known]
        if missing:
            raise UsageError(f"--load-case {missing[0]!r}: not a load case of {case.name!r} "
                             f"(load cases: {', '.join(known)})")
        chosen = tuple(known[name] for name in names)
    return tuple(chosen)


def run(args) -> int:
    from workbook.solve.load_cases import solve_load_cases

    case = load_case(args.case, run=args.run, rigid=args.rigid)
    results = solve_load_cases(case, chosen_load_cases(case, args.load_case))
    if args.json:
        print(json.dumps({"case": case.name, "load_cases": [r.to_dict() for r in results]}, indent=1))
        return 0
    print_load_cases(case, results)
    return 0


def print_load_cases(case, results) -> None:
    """Print the tables of solved load cases of *case*."""
    source = "the case's" if case.load_cases else "the reference set of"
    print(f"{case.name}: {len(results)} limit load case(s), {source} load cases; margins of safety "
          "MS_y = F_ty / sigma_vM - 1 at limit load, MS_u = F_tu / (FS sigma_vM) - 1 at ultimate load")
    for result in results:
        lc = result.load_case
        d, r = result.engine_displacement * 1e3, result.engine_rotation * 1e3
        print(f"\n{lc.name} (FS {lc.factor_of_safety:g}"
              + (f", fail-safe: {lc.without_link} removed" if lc.without_link else "") + ")"
              + (f": {lc.description}" if lc.description else ""))
        print(f"  applied load {_triple(result.applied_force / 1e3)} kN, pylon force {_triple(result.pylon_force / 1e3)} kN")
        print(f"  engine CG displacement {_triple(d)} mm, rotation {_triple(r)} mrad")
        print(f"  {'link':16s} {'N kN':>9s} {'sigma_nom MPa':>13s} {'vM MPa':>8s} {'at':>6s} "
              f"{'sigma_1 MPa':>11s} {'at':>6s} {'MS_y':>8s} {'MS_u':>8s}")
        for name, s in result.links.items():
            print(f"  {name:16s} {s.axial_force / 1e3:9.2f} {_mpa(s.nominal_stress):>13s} {_mpa(s.von_mises):>8s} "
                  f"{s.von_mises_region or '-':>6s} {_mpa(s.max_principal):>11s} {s.max_principal_region or '-':>6s} "
                  f"{_margin(s.yield_margin):>8s} {_margin(s.ultimate_margin):>8s}")
        print(f"  stress recovery of all links: {result.stress_seconds:.3f} s")
