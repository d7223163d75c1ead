"""``mountwb links [CASE] [--export FOLDER]``: the links as reduced for a case.

Per link: FE DOF, first frequencies free-free and as mounted, the
fixed-interface modes kept and why, the reduction time and the cache hit;
``--export`` writes each link in Exudyn's own reduced-body format.
"""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Callable

from workbook.cli.loading import load_case
from workbook.cli.outputs import write_output

__all__ = ["arguments"]


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("--export", metavar="FOLDER",
                        help="also write each reduced link in Exudyn's own format (FOLDER/<link>.npz; an existing "
                             "file is kept: a new name)")
    return links


def _exporter(link) -> Callable[[Path], Path]:
    """The writer of *link*'s file in Exudyn's own reduced-body format."""
    from flexbodies import export_exudyn_file

    def write(target: Path) -> Path:
        return export_exudyn_file(link, target)

    return write


def links(args) -> int:
    from workbook.answers.link_table import link_table
    from workbook.scene.build import reduce_links

    case = load_case(args.case)
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
            write_output(str(Path(args.export) / f"{name}.npz"), f"link {name}", "export", _exporter(link))
    return 0
