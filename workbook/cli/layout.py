"""``mountwb layout [CASE] [-o FILE.png]``: draw a case's mount in side, front and top views."""
from __future__ import annotations

import argparse
from typing import Callable

from workbook.cli.loading import load_case
from workbook.cli.outputs import check_output, write_output

__all__ = ["arguments"]


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("-o", "--output", default="mount-layout.png", help="PNG file to write (an existing file is kept: a new name)")
    return layout


def layout(args) -> int:
    import matplotlib

    matplotlib.use("Agg")
    from workbook.answers.saving import save_figure
    from workbook.model.drawing import plot_layout

    check_output("--output", args.output, (".png",), [args.case])
    figure = plot_layout(load_case(args.case))
    write_output(args.output, "layout", "layout", lambda target: save_figure(figure, target, dpi=130))
    return 0
