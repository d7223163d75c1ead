"""``mountwb study uq [CASE] --param NAME=DIST ... --samples N [--sobol]``: uncertainty of T and eta.

Each ``--param`` names a numeric study parameter (``mountwb study params``'
names, a hinge parameter also per group and direction) and its distribution
(:mod:`workbook.studies.uncertainty`): ``normal:MEAN:STD``,
``uniform:LOW:HIGH``, ``lognormal:MEDIAN:SIGMA`` (SIGMA of ln) or
``tol:NOMINAL:TOL[:K]`` (NOMINAL ± TOL, TOL absolute or ``N%``, holding K
standard deviations, default 3), SI units. ``--samples N`` random rows, or
with ``--sobol`` N base samples (a power of two) of a Saltelli design,
N (d + 2) rows, for first-order and total Sobol' indices. The rows run as
the parameter study's do (local processes or ``--dask``, the linear mount in
NumPy where it follows them). Printed: the statistics (mean, std, P5, P50,
P95 of T and eta per run and direction), the Sobol' indices, the files
written (``uncertainty.csv``/``.xlsx``/``.png``, or ``uncertainty-2.*``...
beside earlier ones); with ``--json`` one JSON document instead.
Distributions are not read from a case workbook (command line only).
"""
from __future__ import annotations

import argparse
import json
import sys

from workbook.cli.loading import load_case
from workbook.cli.params import add_run_arguments, run_table
from workbook.errors import EXIT_FAILED_ROWS, EXIT_OK, InputError, UsageError

__all__ = ["add_arguments", "parse_params", "run_uq_study"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``study uq`` to its parser."""
    from workbook.studies.uncertainty import DISTRIBUTIONS

    parser.add_argument("--param", action="append", default=[], metavar="NAME=DIST",
                        help=f"uncertain parameter and its distribution: {'; '.join(DISTRIBUTIONS.values())}; SI units "
                             "(e.g. hinge_stiffness=lognormal:2e7:0.1, hinge_stiffness/front=tol:2e7:10%%:3)")
    parser.add_argument("--samples", type=int, default=1000,
                        help="Monte Carlo rows (1000); with --sobol base samples N, a power of two: N (d + 2) rows")
    parser.add_argument("--sobol", action="store_true", help="a Saltelli design and first-order and total Sobol' indices")
    parser.add_argument("--json", action="store_true", help="print one JSON document (statistics, indices, files)")
    add_run_arguments(parser, "sampling seed (0)")


def parse_params(specs: list[str]) -> dict:
    """The distributions of the ``--param NAME=DIST`` options.

    Raises
    ------
    UsageError
        A malformed option, an unknown parameter or distribution, naming the option.
    """
    from workbook.studies.parametric import parameter
    from workbook.studies.uncertainty import parse_distribution

    if not specs:
        raise UsageError("an uncertainty study needs at least one --param NAME=DIST")
    distributions = {}
    for spec in specs:
        name, sep, text = spec.partition("=")
        try:
            if not sep:
                raise InputError("expected NAME=DIST")
            parameter(name.strip())
            distributions[name.strip()] = parse_distribution(text)
        except InputError as error:
            raise UsageError(f"--param {spec!r}: {error}") from None
    return distributions


def run_uq_study(args) -> int:
    """Run ``study uq``; print the statistics, the Sobol' indices and the files written (or JSON).

    Returns
    -------
    int
        0, or :data:`workbook.errors.EXIT_FAILED_ROWS` when some rows failed (no Sobol' indices then).
    """
    import matplotlib

    matplotlib.use("Agg")

    from workbook.studies.parametric import check_parameters
    from workbook.studies.sensitivity import StudyTable, new_study_table
    from workbook.studies.uncertainty import UQ_STEM, UncertaintyResult, sample_rows

    distributions = parse_params(args.param)
    try:
        rows = sample_rows(distributions, args.samples, sobol=args.sobol, seed=args.seed)
    except InputError as error:
        raise UsageError(f"--samples {args.samples}: {error}") from None
    case = load_case(args.case, run=args.run, rigid=args.rigid)
    check_parameters(case, distributions)
    table = StudyTable(new_study_table(args.output, args.format, UQ_STEM), rows)
    where = f"Dask scheduler {args.dask}" if args.dask else f"{args.workers} local process(es)"
    print(f"{case.name}: {len(rows)} uncertainty rows on {where}", file=sys.stderr)
    outcomes = run_table(args, case, table, "the statistics need a new run")
    result = UncertaintyResult.from_outcomes(distributions, rows, outcomes, sobol=args.sobol, seed=args.seed)
    files = result.write(args.output, args.format, table=table.path)
    statistics = result.to_pandas()
    if args.json:
        print(json.dumps({"case": case.name, "rows": len(rows), "failed": result.failed,
                          "distributions": {name: str(d) for name, d in distributions.items()},
                          "statistics": statistics.to_dict("records"),
                          "sobol": None if result.sobol is None else result.sobol.to_dict("records"),
                          "files": [str(path) for path in files]}, indent=1))
    else:
        if statistics.empty:           # every row failed: the first one's error says why
            first = next(outcome for outcome in outcomes if outcome.status != "ok")
            print(f"no statistics: every row failed (row {first.index}: {first.error})")
        else:
            print(statistics.to_string(index=False, float_format=lambda v: f"{v:.5g}"))
        if result.sobol is not None:
            print(result.sobol.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
        for path in files:
            print(path)
        if result.failed:
            print(f"{result.failed} of {len(rows)} rows failed (their errors in {files[0]})"
                  + ("; Sobol' indices need every row" if args.sobol else ""))
    return EXIT_FAILED_ROWS if result.failed else EXIT_OK
