"""``mountwb study params [CASE] --vary NAME=SPEC ... [--lhs N] [--workers N | --dask ADDRESS]``.

A parameter study of a case (:mod:`workbook.studies.parametric`): ``--vary`` names a
parameter and its values, as a list ``a,b,c`` (numbers in SI units, or
text for ``material`` and ``removed_link``) or a range ``low:high:points``;
the rows are every combination. With ``--lhs N`` every ``--vary`` gives
bounds ``low:high`` and the rows are N samples of a Latin hypercube. Runs go
to local processes (``--workers``, default: every core) or to the Dask
scheduler at ``--dask ADDRESS``; the table (CSV or Parquet, and a sheet) and
the sensitivity plot go to ``--output`` (``parameter-study.*``, or
``parameter-study-2.*``... beside an earlier study's files, which are kept;
``--resume`` continues ``parameter-study.*``). A progress line on stderr every
:data:`workbook.studies.progress.PROGRESS_INTERVAL` s gives the rows done,
rows per second and the time left.

Rows that change only what a design evaluation follows (hinge springs and
loss factors, transducer springs, engine mass properties, excitation
amplitudes) are answered by the case's linear mount, prepared once
(:class:`workbook.LinearMount`), in NumPy; the others, and every row with
``--exudyn``, by the Exudyn pipeline (local processes and Dask workers alike). The table's ``path``
column says which.

The table file is kept up to date as rows finish, so an interrupted study
keeps every finished row; ``--resume`` runs only the rows the table does not
hold. A study whose rows all ran but some failed exits with
:data:`workbook.errors.EXIT_FAILED_ROWS` after a summary line.
"""
from __future__ import annotations

import argparse
import math
import os
import sys

from workbook.cli.loading import load_case
from workbook.errors import EXIT_FAILED_ROWS, EXIT_OK, InputError, UsageError

__all__ = ["add_arguments", "add_run_arguments", "run_parameter_study", "parse_vary", "parse_ranges",
           "linear_mount_for"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``study params`` to its parser."""
    from workbook.studies.parametric import PARAMETERS

    parser.add_argument("--vary", action="append", default=[], metavar="NAME=SPEC",
                       help=f"parameter ({', '.join(PARAMETERS)}; a hinge parameter also as NAME/GROUP[/DIRECTION], "
                            "e.g. hinge_stiffness/front/axial) and its values: a,b,c or low:high:points "
                            "(with --lhs: low:high); SI units")
    parser.add_argument("--lhs", type=int, metavar="N", help="N Latin-hypercube samples over the --vary bounds")
    add_run_arguments(parser, "Latin-hypercube seed (0)")
    parser.add_argument("--resume", action="store_true",
                        help="keep the rows the table in --output already holds and run only the missing ones")


def at_least_one(text: str) -> int:
    """An option's whole number >= 1 (processes, starts), or argparse's usage error naming what was found."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, found {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, found {value}")
    return value


def positive(text: str) -> float:
    """An option's number > 0 (a length of time, a rate), or argparse's usage error naming what was found."""
    return _bounded(text, strict=True)


def not_negative(text: str) -> float:
    """An option's number >= 0 (a noise level), or argparse's usage error naming what was found."""
    return _bounded(text, strict=False)


def _bounded(text: str, strict: bool) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value < 0 or (strict and value == 0):
        raise argparse.ArgumentTypeError(f"expected a number {'>' if strict else '>='} 0, found {text!r}")
    return value


def add_run_arguments(parser: argparse.ArgumentParser, seed_help: str) -> None:
    """Add the options of a study's rows (seed, workers, Dask, table format, rigid links, Exudyn) to *parser*."""
    from workbook.studies.sensitivity import TABLE_FORMATS

    parser.add_argument("--seed", type=int, default=0, help=seed_help)
    parser.add_argument("--workers", type=at_least_one, default=os.cpu_count() or 1,
                       help="local processes (default: every core; 1: serial)")
    parser.add_argument("--dask", metavar="ADDRESS", help="run on the Dask scheduler at ADDRESS instead")
    parser.add_argument("--format", choices=TABLE_FORMATS, default="csv", help="table file format (csv)")
    parser.add_argument("--rigid", action="store_true", help="make every link rigid")
    parser.add_argument("--exudyn", action="store_true",
                        help="answer every row through Exudyn (default: the rows that change only hinge and "
                             "transducer springs, engine mass properties or excitation amplitudes are answered "
                             "by the case's linear mount in NumPy, equal to 1e-6)")


def _number(spec: str, text: str) -> float:
    """A number of the ``--vary`` option *spec*, or the usage error naming what was found."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise UsageError(f"--vary {spec!r}: found {text.strip()!r}, expected a finite number")
    return value


def parse_vary(specs: list[str], lhs: int | None, seed: int = 0) -> tuple[dict, ...]:
    """The study rows of the ``--vary`` options.

    Raises
    ------
    UsageError
        A malformed option, naming it.
    """
    from workbook.studies.parametric import grid, latin_hypercube, linear_range, parameter

    if not specs:
        raise UsageError("a parameter study needs at least one --vary NAME=SPEC")
    values: dict[str, list] = {}
    bounds: dict[str, tuple[float, float]] = {}
    for spec in specs:
        name, sep, text = spec.partition("=")
        name = name.strip()
        if not sep:
            raise UsageError(f"--vary {spec!r}: expected NAME=SPEC")
        try:
            numeric = parameter(name).numeric
        except InputError as error:
            raise UsageError(f"--vary {spec!r}: {error}") from None
        parts = text.split(":")
        if lhs is not None:
            if len(parts) != 2:
                raise UsageError(f"--vary {spec!r}: with --lhs give bounds low:high")
            bounds[name] = (_number(spec, parts[0]), _number(spec, parts[1]))
        elif len(parts) == 3 and numeric:
            points = _number(spec, parts[2])
            if not points.is_integer():
                raise UsageError(f"--vary {spec!r}: found {parts[2].strip()!r} points, expected a whole number")
            low, high = _number(spec, parts[0]), _number(spec, parts[1])
            try:
                values[name] = linear_range(low, high, int(points))
            except InputError as error:
                raise UsageError(f"--vary {spec!r}: {error}") from None
        elif len(parts) == 1:
            values[name] = [_number(spec, v) if numeric else v.strip() for v in text.split(",")]
        else:
            raise UsageError(f"--vary {spec!r}: expected a,b,c or low:high:points")
    return latin_hypercube(bounds, lhs, seed) if lhs is not None else grid(values)


def linear_mount_for(case, cases):
    """The linear mount of *case* when it follows a row's case (said on stderr), else None."""
    import time

    from workbook.model.case import Case
    from workbook.studies.parallel import prepare_design_model

    start = time.perf_counter()
    model = prepare_design_model(case)
    if isinstance(model, str):
        print(f"every row through Exudyn: {model}", file=sys.stderr)
        return None
    # the first row it follows is enough to use it (each row is checked again where it runs)
    if not any(isinstance(row, Case) and model.follows(row) for row in cases):
        print(f"every row through Exudyn: the linear mount of {case.name!r} follows none of the rows",
              file=sys.stderr)
        return None
    print(f"linear mount prepared in {time.perf_counter() - start:.1f} s: the rows it follows are answered by it "
          "in NumPy, the others by Exudyn (the table's path column)", file=sys.stderr)
    return model


def parse_ranges(specs: list[str]) -> dict:
    """``{name: (low, high)}`` of the ``--vary NAME=low:high`` options.

    Raises
    ------
    UsageError
        A malformed option or an unknown parameter, naming it.
    """
    from workbook.studies.parametric import parameter

    if not specs:
        raise UsageError("give at least one --vary NAME=low:high")
    bounds = {}
    for spec in specs:
        name, sep, text = spec.partition("=")
        name = name.strip()
        try:
            parameter(name)
        except InputError as error:
            raise UsageError(f"--vary {spec!r}: {error}") from None
        parts = text.split(":")
        try:
            low, high = (float(p) for p in parts) if sep and len(parts) == 2 else (None, None)
        except ValueError:
            low = high = None
        if low is None or high is None or not low < high:
            raise UsageError(f"--vary {spec!r}: expected NAME=low:high with numbers low < high")
        bounds[name] = (low, high)
    return bounds


def run_table(args, case, table, resume: str) -> list:
    """Run the rows of *table* (a :class:`workbook.studies.sensitivity.StudyTable`) as *args* ask, the file
    kept up to date, a progress line on stderr; *resume*: how to go on after an interrupt.

    Returns
    -------
    list of RowOutcome

    Raises
    ------
    KeyboardInterrupt
        Ctrl-C or SIGTERM, with the number of finished rows kept in the table and *resume* as its message.
    OSError
        A file that could not be written (the table's disk full), with the same words after its own.
    """
    from workbook.studies.parallel import check_scheduler, run_rows
    from workbook.studies.parametric import study_cases
    from workbook.studies.progress import StudyProgress

    if args.dask:
        check_scheduler(args.dask)
    rows = table.rows
    cases = study_cases(case, rows)
    design_model = None if args.exudyn else linear_mount_for(case, cases)
    try:
        with StudyProgress(len(rows), table.kept, stream=sys.stderr) as progress:
            outcomes = run_rows(cases, workers=args.workers, dask=args.dask, finished=table.outcomes,
                                record=table.add, progress=progress.update, design_model=design_model)
            table.flush()
    except KeyboardInterrupt as interrupt:
        table.flush()
        raise type(interrupt)(f"{table.kept} of {len(rows)} rows finished and kept in {table.path}; {resume}") from None
    except OSError as error:           # the table's disk full, its folder gone...: the rows of its last write are kept
        raise OSError(error.errno, f"{error.strerror or error}; {table.kept} of {len(rows)} rows finished and kept "
                                   f"in {table.path}; {resume}") from None
    return outcomes


#: Most table rows printed; a longer table prints its first and last halves of them (the file has every row).
PRINTED_ROWS = 60


def run_parameter_study(args) -> int:
    """Run ``study params``; print the table, a summary line and the files written.

    Returns
    -------
    int
        0, or :data:`workbook.errors.EXIT_FAILED_ROWS` when some rows failed.

    Raises
    ------
    KeyboardInterrupt
        Ctrl-C or SIGTERM, with the number of finished rows kept in the table as its message.
    """
    import matplotlib

    matplotlib.use("Agg")

    from workbook.studies.parallel import NUMPY_PATH
    from workbook.studies.parametric import check_parameters
    from workbook.studies.sensitivity import StudyTable, new_study_table, read_finished, table_path, write_study

    rows = parse_vary(args.vary, args.lhs, args.seed)
    case = load_case(args.case, run=args.run, rigid=args.rigid)
    check_parameters(case, rows[0])
    path = table_path(args.output, args.format) if args.resume else new_study_table(args.output, args.format)
    finished = read_finished(path, rows) if args.resume else {}
    table = StudyTable(path, rows, finished)
    where = f"Dask scheduler {args.dask}" if args.dask else f"{args.workers} local process(es)"
    kept = f" ({len(finished)} already in {path})" if args.resume else ""
    print(f"{case.name}: {len(rows)} study rows{kept} on {where}", file=sys.stderr)
    outcomes = run_table(args, case, table, "--resume runs the rest")
    frame = table.to_pandas()
    print(frame.drop(columns="error").to_string(index=False, float_format=lambda v: f"{v:.5g}",
                                                max_rows=PRINTED_ROWS))
    if len(frame) > PRINTED_ROWS:
        print(f"(the first and last {PRINTED_ROWS // 2} of {len(frame)} table rows; all of them in {path})")
    failed = [outcome for outcome in outcomes if outcome.status != "ok"]
    for outcome in failed:
        print(f"row {outcome.index} failed: {outcome.error}")
    for written in write_study(frame, list(rows[0]) if rows else [], path, table_written=True):
        print(written)
    fast = sum(outcome.path == NUMPY_PATH for outcome in outcomes)
    if fast:
        print(f"{fast} of {len(rows)} rows answered by the prepared linear mount in NumPy (column 'path'), "
              f"the others by Exudyn")
    print(f"{len(rows) - len(failed)} of {len(rows)} rows ok, {len(failed)} failed"
          + (f" (rows {', '.join(str(o.index) for o in failed)}; exit code {EXIT_FAILED_ROWS})" if failed else ""))
    return EXIT_FAILED_ROWS if failed else EXIT_OK
