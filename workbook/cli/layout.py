"""``mountwb layout [CASE] [-o FILE.png]``: draw a case's mount in side, front and top views."""
from __future__ import annotations

import argparse
from typing import Callable

from workbook.cli.loading import load_case

__all__ = ["arguments"]


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("-o", "--output", default="mount-layout.png", help="PNG file to write")
    return layout


def layout(args) -> int:
    import matplotlib

    matplotlib.use("Agg")
    from workbook.answers.saving import save_figure
    from workbook.model.drawing import plot_layout

    figure = plot_layout(load_case(args.case))
    save_figure(figure, args.output, dpi=130)
    print(args.output)
    return 0
