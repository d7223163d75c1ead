"""The ``mountwb`` command line.

Subcommands:

- ``mountwb run [CASE.json] [--json] [--rigid]``: run a case (default: the
  reference mount, LP and HP rotors); print the three-way isolation-efficiency
  table and the model card of each run, or the answers as JSON.
- ``mountwb layout [CASE.json] [-o FILE.png]``: draw a case's layout.
- ``mountwb study accuracy [CASE] [--run R] [--repeats N] [--output DIR]``:
  the accuracy-against-time ladder (:mod:`workbook.study_cli`).
- ``mountwb study params [CASE] --vary NAME=SPEC ... [--lhs N] [--workers N |
  --dask ADDRESS]``: a parameter study (:mod:`workbook.parametric_cli`).
- ``mountwb rig measure|compare|synthesize ...``: rig records against
  simulation (:mod:`workbook.rig_cli`).
- ``mountwb run CASE.xlsx [--run NAME] [--report OUT.xlsx]``, ``mountwb check
  CASE.xlsx``, ``mountwb template OUT.xlsx [--reference]``: case workbooks
  (:mod:`workbook.excel.commands`).

A subcommand is a function that adds its arguments to a parser and returns
its handler; add it to :data:`SUBCOMMANDS`.
"""
from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path
from typing import Callable

from .excel import commands as excel_commands
from .rig_cli import rig_arguments
from .study_cli import study_arguments

__all__ = ["main", "SUBCOMMANDS"]

log = logging.getLogger(__name__)


def _load_case(path: str | None, rigid: bool = False, time_budget: float | None = None):
    import dataclasses

    from .codec import from_json
    from .reference import reference_case

    case = reference_case() if path is None else from_json(Path(path).read_text())
    if time_budget is not None:
        case = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, time_budget=time_budget))
    return case.with_rigid_links() if rigid else case


def _progress_factory():
    """Progress bars on stderr (tqdm hides them when stderr is not a terminal)."""
    from tqdm import tqdm

    def factory(description: str, total: float):
        bar = tqdm(total=total, desc=description, file=sys.stderr, disable=None, leave=False,
                   bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}<{remaining}")

        def update(done: float):
            bar.update(done - bar.n)

        return update, bar.close

    return factory


def _run_arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("--json", action="store_true", help="print the answers as JSON")
    parser.add_argument("--rigid", action="store_true", help="make every link rigid")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    parser.add_argument("--time-budget", type=float, metavar="SECONDS",
                        help="wall time one run may take before it stops with an estimate of the time it needs")
    excel_commands.add_run_arguments(parser)

    def run(args) -> int:
        from .runner import run_case

        if excel_commands.is_workbook(args.case):
            return excel_commands.run_workbook(args)

        case = _load_case(args.case, args.rigid, args.time_budget)
        result = run_case(case, progress=None if args.no_progress else _progress_factory())
        if args.json:
            print(result.to_json(indent=2))
            return 0
        table = result.table("efficiency")
        levels = result.table("db")
        print(f"{case.name}: pylon isolation efficiency eta = (1 - T) x 100 % (T: pylon force / excitation)\n")
        print(table.to_string(float_format=lambda v: f"{v:8.2f}"))
        print("\n20 log10 T (dB):")
        print(levels.drop(columns="frequency Hz").to_string(float_format=lambda v: f"{v:8.2f}"))
        for run_result in result.runs:
            for warning in run_result.warnings:
                print(f"\nWARNING {run_result.name}: {warning}")
        for card in result.model_cards.values():
            print("\n" + card.to_text())
        return 0

    return run


def _links_arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON); default: the reference mount")
    parser.add_argument("--export", metavar="FOLDER",
                        help="also write each reduced link in Exudyn's own format (FOLDER/<link>.npz)")

    def links(args) -> int:
        from flexbodies import export_exudyn_file

        from .link_table import link_table
        from .scene import reduce_links

        case = _load_case(args.case)
        reduced = reduce_links(case)
        table = link_table(case, reduced)
        print(f"{case.name}: links as reduced for the highest excitation of the case\n")
        formats = {"f1 free-free [Hz]": "{:.0f}", "f1 mounted [Hz]": "{:.0f}", "f_exc/f1": "{:.3f}",
                   "reduction [s]": "{:.2f}"}
        print(table.drop(columns="why").to_string(formatters={k: f.format for k, f in formats.items()}))
        print()
        for name, reason in table["why"].items():
            print(f"{name}: {reason}")
        if args.export:
            for name, link in reduced.items():
                print(export_exudyn_file(link, Path(args.export) / name))
        return 0

    return links


def _layout_arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON); default: the reference mount")
    parser.add_argument("-o", "--output", default="mount-layout.png", help="PNG file to write")

    def layout(args) -> int:
        import matplotlib

        matplotlib.use("Agg")
        from .layout import plot_layout

        figure = plot_layout(_load_case(args.case))
        figure.savefig(args.output, dpi=130)
        print(args.output)
        return 0

    return layout


#: name -> (help, function adding the arguments and returning the handler)
SUBCOMMANDS = {
    "run": ("run a case and print the isolation-efficiency table and the model card", _run_arguments),
    "links": ("per link: FE size, frequencies free-free and as mounted, modes kept and why, cost, cache hit",
              _links_arguments),
    "layout": ("draw a case's layout (side, front and top views) as a PNG", _layout_arguments),
    "check": ("check a case workbook (.xlsx) and list every problem; nothing is run or written",
              excel_commands.check_arguments),
    "template": ("write the case template workbook (or, with --reference, the reference case)",
                 excel_commands.template_arguments),
    "study": ("accuracy against time: run a case through the ladder of link fidelities and methods; "
              "or a parameter study (params)",
              study_arguments),
    "rig": ("measured rig records: measured T and eta, the validation table against simulation, "
            "synthetic records", rig_arguments),
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="mountwb", description="Engine mount vibration isolation workbook")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more log output (-v, -vv)")
    commands = parser.add_subparsers(dest="command", required=True)
    for name, (help_text, configure) in SUBCOMMANDS.items():
        command = commands.add_parser(name, help=help_text, description=help_text)
        command.set_defaults(handler=configure(command))
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``mountwb`` console script."""
    from .case import CaseError
    from .guards import SimulationError

    from threadpoolctl import threadpool_limits

    # Multithreaded BLAS made the small dense solves of a run many times slower on 2 cores.
    threadpool_limits(limits=1)
    args = build_parser().parse_args(argv)
    level = {0: logging.WARNING, 1: logging.INFO}.get(args.verbose, logging.DEBUG)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.handler(args)
    except SimulationError as error:
        print(f"mountwb {args.command}: numerical trouble: {error}", file=sys.stderr)
        return 1
    except (CaseError, ValueError, OSError) as error:
        print(f"mountwb {args.command}: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
