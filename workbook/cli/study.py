"""``mountwb study accuracy|params|uq [CASE]``: studies of one case.

- ``mountwb study accuracy [CASE] [--run R] [--repeats N] [--output DIR]``:
  runs the case through the accuracy ladder of
  :mod:`workbook.studies.accuracy`, prints the markdown table and writes it,
  the Pareto plot and the sheet into the output folder (new names when files
  of the same name exist).
- ``mountwb study params [CASE] --vary NAME=SPEC ...``: a parameter study
  (:mod:`workbook.cli.params`).
- ``mountwb study uq [CASE] --param NAME=DIST ... --samples N [--sobol]``: the
  uncertainty of T and eta, Monte Carlo and Sobol' indices (:mod:`workbook.cli.uq`).
"""
from __future__ import annotations

import argparse
import sys
from typing import Callable

from workbook.cli import params, uq
from workbook.cli.loading import load_case
from workbook.cli.outputs import output_folder
from workbook.errors import UsageError

__all__ = ["arguments"]


def _case_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", nargs="?", help="case workbook (.xlsx) or JSON case; default: the reference mount")
    parser.add_argument("--run", metavar="R", help="case workbook: study this row of the Runs sheet")
    parser.add_argument("--output", type=output_folder, default=".", metavar="DIR",
                        help="folder for the files written (existing files are kept: new names)")


def arguments(parser: argparse.ArgumentParser) -> Callable:
    kinds = parser.add_subparsers(dest="kind", required=True)
    accuracy = kinds.add_parser("accuracy", help="accuracy against time: a ladder of link fidelities and methods",
                                description="run one case through the ladder of link fidelities and solution "
                                            "methods; DOF, wall time and error of T per rung")
    _case_arguments(accuracy)
    accuracy.add_argument("--repeats", type=int, default=3, help="repeats per rung for the median wall time")
    accuracy.set_defaults(study=run_accuracy)
    study_params = kinds.add_parser("params", help="a parameter study on local processes or a Dask cluster",
                                    description="vary parameters of a case; one table and sensitivity plots")
    _case_arguments(study_params)
    params.add_arguments(study_params)
    study_params.set_defaults(study=params.run_parameter_study)
    study_uq = kinds.add_parser("uq", help="uncertainty of T and eta: Monte Carlo percentiles and Sobol' indices",
                                description="sample parameters from distributions; statistics of T and eta, a "
                                            "histogram/CDF plot and, with --sobol, Sobol' indices (SALib)")
    _case_arguments(study_uq)
    uq.add_arguments(study_uq)
    study_uq.set_defaults(study=uq.run_uq_study)
    return lambda args: args.study(args)


def run_accuracy(args) -> int:
    """Run ``study accuracy``: print the ladder's table and the files written."""
    import matplotlib

    matplotlib.use("Agg")
    from workbook.studies.accuracy import run_study

    if args.repeats < 1:
        raise UsageError(f"--repeats must be at least 1, got {args.repeats}")
    case = load_case(args.case, run=args.run)
    result = run_study(case, repeats=args.repeats,
                       progress=lambda label: print(f"rung: {label}", file=sys.stderr, flush=True))
    print(result.to_markdown())
    for path in result.write(args.output):
        print(path)
    return 0
