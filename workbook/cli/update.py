"""``mountwb update [CASE] --record FILE[:SIGMA] ... --vary NAME=low:high ... [--output DIR] [--json]``.

Model updating (:mod:`workbook.rig.updating`): the values of the parameters
``--vary`` (the names of ``study params --vary``: hinge stiffness, damping
and loss factor, also per hinge group and direction, transducer stiffness,
engine mass, a flexible casing's modulus) within their bounds that make the case's T agree with the rig
records' measured T, by weighted least squares on the fast linear model.
A record may state its measurement uncertainty after a colon, one standard
deviation of its T, relative (``lp-1.csv:0.5%``) or absolute (``lp-1.csv:0.0004``):
the records are then weighted by it and the standard errors come from it
(every record states one, or none does: unweighted, the standard errors
from the residual).
Prints the fitted values with their standard errors, the correlation
matrix, the error before and after per run and direction, and a warning
for each parameter the data do not determine. ``--output DIR`` writes the
updated case (``updated-case.json``, and ``updated-case.xlsx`` when the case
has parametric links), both tables as CSV and the plot ``update.png``.
``--json`` prints the fit as JSON. A bad record, an unknown parameter or a
record of a run the case lacks exits with 2.
"""
from __future__ import annotations

import argparse
import json
import re
from pathlib import Path
from typing import Callable

from workbook.cli.loading import load_case
from workbook.cli.outputs import output_folder
from workbook.cli.params import at_least_one, parse_ranges
from workbook.errors import UnwritableCase

__all__ = ["arguments"]


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("--record", action="append", required=True, metavar="FILE[:SIGMA]",
                        help="rig record of a run of the case: CSV or UFF 58 (repeatable), with its measurement "
                             "uncertainty of T after a colon: relative (lp.csv:0.5%%) or absolute (lp.csv:0.0004)")
    parser.add_argument("--map", metavar="MAP.json", help="channel map of the records if they are a lab's CSV")
    parser.add_argument("--vary", action="append", required=True, metavar="NAME=low:high",
                        help="a parameter to fit within bounds (SI units; repeatable), e.g. "
                             "hinge_stiffness/front=1e7:5e7 or transducer_stiffness=1e7:1e9")
    parser.add_argument("--rigid", action="store_true", help="make every link rigid")
    parser.add_argument("--periods", type=at_least_one, default=None,
                        help="whole rotor periods per measured window (default: the case's)")
    parser.add_argument("--output", type=output_folder, metavar="DIR", help="write the updated case, the tables and the plot in DIR")
    parser.add_argument("--json", action="store_true", help="print the fit as JSON (SI units) instead of tables")
    return run


def run(args) -> int:
    import pandas as pd

    from workbook.cli.rig import read_any_record
    from workbook.rig.updating import update_model

    bounds = parse_ranges(args.vary)
    specs = [_record_option(text) for text in args.record]
    case = load_case(args.case, rigid=args.rigid)
    records = [read_any_record(path, args.map) for path, _ in specs]
    result = update_model(case, records, bounds, uncertainty=[sigma for _, sigma in specs], periods=args.periods)
    if args.output:
        _write(Path(args.output), result)
    if args.json:
        print(json.dumps({"case": case.name, **result.to_dict()}, indent=1))
        return 0
    with pd.option_context("display.width", 200, "display.max_columns", 20):
        spread = "reduced chi-square" if result.uncertainty is not None else "relative residual s ="
        value = result.residual_std ** 2 if result.uncertainty is not None else result.residual_std
        print(f"model updating of {case.name!r}: {len(records)} records, {len(bounds)} parameters, "
              f"{result.evaluations} evaluations in {result.seconds:.1f} s; {spread} {value:.3g}; standard errors "
              f"from {'the stated uncertainties' if result.uncertainty is not None else 'the residual'}\n")
        print(result.to_pandas().to_string(float_format=lambda v: f"{v:.5g}"))
        print("\ncorrelation")
        print(pd.DataFrame(result.correlation, index=result.parameters, columns=result.parameters)
              .to_string(float_format=lambda v: f"{v:+.3f}"))
        print(f"condition number of J^T J (columns scaled): {result.condition:.3g}\n")
        print(result.error_frame().to_string(float_format=lambda v: f"{v:.5g}"))
    for warning in result.warnings:
        print(f"warning: {warning}")
    return 0


def _record_option(text: str) -> tuple:
    """``(path, Uncertainty or None)`` of a ``--record FILE[:SIGMA]`` option: a tail after the last colon
    that reads as a number (or a percentage) is the uncertainty; otherwise it is all the path.

    Raises
    ------
    UsageError
        A tail that starts like a number but is not a positive one.
    """
    from workbook.rig.updating import Uncertainty

    path, colon, tail = text.rpartition(":")
    if not colon or not path or not re.fullmatch(r"\s*[+\-]?[0-9.][0-9.eE+\-\s]*%?\s*", tail):
        return text, None
    return path, Uncertainty.parse(tail)


def _write(folder: Path, result) -> None:
    """The updated case (JSON; a workbook when it can be written), both tables and the plot in *folder*."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from workbook.answers.saving import save_csv, save_figure, save_text
    from workbook.cli.outputs import write_output
    from workbook.model.codec import to_json

    folder.mkdir(parents=True, exist_ok=True)
    write_output(str(folder / "updated-case.json"), "updated case", "update",
                 lambda target: save_text(to_json(result.case, indent=1), target))
    try:
        from workbook.excel.runs import RunSpec
        from workbook.excel.template import case_workbook, write_workbook

        book = case_workbook(result.case, [RunSpec(e.name, e.name) for e in result.case.excitations])
        write_output(str(folder / "updated-case.xlsx"), "updated case workbook", "update",
                     lambda target: write_workbook(book, target)[0])
    except UnwritableCase as error:
        print(f"no case workbook written: {error}")
    write_output(str(folder / "update-parameters.csv"), "fitted values", "update",
                 lambda target: save_csv(result.to_pandas(), target))
    write_output(str(folder / "update-errors.csv"), "error before and after", "update",
                 lambda target: save_csv(result.error_frame(), target))
    figure = result.plot()
    write_output(str(folder / "update.png"), "plot", "update", lambda target: save_figure(figure, target))
    plt.close(figure)
