"""The ``mountwb`` command line: the parser, and every error mapped to its exit code once.

One module per command (``workbook.cli.<command>``); each has a function
that adds the command's arguments to its parser and returns the handler.
Exit codes (:mod:`workbook.errors`, ``docs/reliability.md``): 0 done, 1
numerical trouble, 2 bad input (nothing written), 3 a parameter study with
failed rows, 130 interrupted (Ctrl-C), 143 terminated (SIGTERM). An interrupt
or SIGTERM anywhere prints one line, no traceback.

Only an error of the package (:class:`workbook.errors.MountwbError`, whose
class carries its exit code) is reported as the user's input or as
numerical trouble, in one line; so is a file that cannot be read or written
(:class:`OSError`, exit 2). Any other exception is a defect of ``mountwb``:
exit 1, one line saying "internal error", and the traceback in a log file
whose path the line gives.
"""
from __future__ import annotations

import argparse
import importlib
import logging
import os
import signal
import sys
import tempfile
import time
import traceback
from typing import Callable

from threadpoolctl import threadpool_limits

from workbook.answers.saving import recording_writes
from workbook.errors import MountwbError, SimulationError, Terminated, exit_code, interruption

__all__ = ["main", "COMMANDS", "build_parser"]

#: name -> (help, ``module:function`` of :mod:`workbook.cli` adding the command's arguments and returning its
#: handler); a command's module is imported only when that command is run or its parser built.
COMMANDS = {
    "run": ("run a case and print the isolation-efficiency table and the model card", "run:arguments"),
    "links": ("per link: FE size, frequencies free-free and as mounted, modes kept and why, cost, cache hit",
              "links:arguments"),
    "layout": ("draw a case's layout (side, front and top views) as a PNG", "layout:arguments"),
    "check": ("check a case workbook (.xlsx) and list every problem; nothing is run or written",
              "workbooks:check_arguments"),
    "template": ("write the case template workbook (or, with --reference, the reference case)",
                 "workbooks:template_arguments"),
    "study": ("studies of a case: 'accuracy' (accuracy against time) or 'params' (a parameter study)",
              "study:arguments"),
    "rig": ("measured rig records: measured T and eta, the validation table against simulation, "
            "synthetic records", "rig:arguments"),
    "update": ("model updating: fit hinge, transducer and engine parameters to rig records by least squares "
               "(fitted values, standard errors, correlation, error before and after)", "update:arguments"),
    "run-up": ("a rotor imbalance over a speed range (force U w^2): pylon force and T per direction against speed, "
               "the mounted modes marked", "run_up:arguments"),
    "four-pole": ("the mount's four-pole parameters (dynamic stiffness) against frequency", "four_pole:arguments"),
    "campbell": ("the Campbell diagram: mounted modes against rotor speed, gyroscopic whirl, critical speeds",
                 "campbell:arguments"),
    "loads": ("limit load cases: hinge and link forces, engine displacement, link stresses and margins of safety",
              "loads:arguments"),
    "stress": ("link strength: the load cases' static margins, then per rotor excitation the dynamic stress on the "
               "preload and the fatigue factors (Goodman, Gerber); --vtu writes the stress fields",
               "stress:arguments"),
    "optimise": ("optimise the design on the fast linear mount: the worst T (dB) or a weighted mean within static "
                 "displacement and mode-band constraints; before/after table, the optimised case, a Pareto front",
                 "optimise:arguments"),
    "cache": ("the store of reduced bodies: info, verify (keys and checksums), clear", "cache:arguments"),
}


def _configure(name: str) -> Callable[[argparse.ArgumentParser], Callable]:
    """The function of command *name* that adds its arguments to its parser and returns its handler."""
    module, _, function = COMMANDS[name][1].partition(":")
    return getattr(importlib.import_module(f"workbook.cli.{module}"), function)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser of ``mountwb``: every command's, or with *command* only that command's arguments (the
    others are listed with their help, their modules not imported)."""
    parser = argparse.ArgumentParser(prog="mountwb", description="Engine mount vibration isolation workbook")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more log output (-v, -vv)")
    commands = parser.add_subparsers(dest="command", required=True)
    for name, (help_text, _) in COMMANDS.items():
        subparser = commands.add_parser(name, help=help_text, description=help_text)
        if command is None or name == command:
            subparser.set_defaults(handler=_configure(name)(subparser))
    return parser


def _command_of(argv: list[str]) -> str | None:
    """The command *argv* names (its first word that is no option: ``-v`` takes no value), or None."""
    return next((word for word in argv if not word.startswith("-")), None)


def _terminate(signum, frame):
    raise Terminated()


def _interrupted(command: str, interrupt: KeyboardInterrupt, written: list) -> int:
    """Print the one line of an interrupt and return its exit code.

    The line gives the interrupt's own message (a study's rows kept), or the
    files the command wrote before it, or says that no file was changed.
    """
    how = "terminated (SIGTERM)" if isinstance(interrupt, Terminated) else "interrupted (Ctrl-C)"
    if str(interrupt):
        detail = f": {interrupt}"
    elif written:
        files = ", ".join(str(path) for path in dict.fromkeys(written))
        detail = f"; {files} {'was' if len(set(written)) == 1 else 'were'} written before it, no other file was changed"
    else:
        detail = "; no file was changed"
    print(f"mountwb {command}: {how}{detail}", file=sys.stderr)
    return exit_code(interrupt)


def _internal_error(command: str, error: Exception, argv: list[str]) -> int:
    """Report a defect of the package: the traceback to a log file, one line to stderr; exit 1.

    Parameters
    ----------
    command : str
        The command that failed.
    error : Exception
        An exception that is not an error of the package (:class:`workbook.errors.MountwbError`).
    argv : list of str
        The command's arguments, for the log.

    Returns
    -------
    int
        :data:`workbook.errors.EXIT_TROUBLE` (1).
    """
    text = "".join(traceback.format_exception(type(error), error, error.__traceback__))
    try:
        handle, path = tempfile.mkstemp(prefix=f"mountwb-internal-error-{time.strftime('%Y%m%d-%H%M%S')}-",
                                        suffix=".log")
        with os.fdopen(handle, "w", encoding="utf-8") as log:
            log.write(f"mountwb {' '.join(argv)}\nPython {sys.version.split()[0]}\n\n{text}")
        where = f"the traceback is in {path}"
    except OSError:
        print(text, file=sys.stderr, end="")
        where = "the traceback is above"
    first = (str(error).splitlines() or [""])[0]
    print(f"mountwb {command}: internal error (a bug of mountwb, not of your input): "
          f"{type(error).__name__}: {first}; {where}", file=sys.stderr)
    return exit_code(error)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``mountwb`` console script; returns the exit code."""
    # SIGTERM unwinds like Ctrl-C: temporary files are removed, study workers stopped.
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        return _main(argv)
    finally:
        signal.signal(signal.SIGTERM, previous)


#: The environment variables of the BLAS and OpenMP libraries' thread counts.
_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def _one_blas_thread() -> None:
    """Run the BLAS of NumPy and SciPy on one thread: each command's dense solves are small, and more
    threads made a run several times slower on 2 cores.

    A library reads its thread count when it is first loaded, which a command does after this (it
    imports what it needs when it runs): so the variables of :data:`_THREAD_VARIABLES` are set to 1 for
    this process and its workers, and the libraries already loaded are limited too.
    """
    for name in _THREAD_VARIABLES:
        os.environ[name] = "1"
    threadpool_limits(limits=1)


def _main(argv: list[str] | None) -> int:
    _one_blas_thread()
    words = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(_command_of(words)).parse_args(words)
    level = {0: logging.WARNING, 1: logging.INFO}.get(args.verbose, logging.DEBUG)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    with recording_writes() as written:
        try:
            return args.handler(args)
        except BaseException as error:
            interrupt = interruption(error)  # also when Exudyn wrapped it into an error of its own
            if interrupt is not None:
                return _interrupted(args.command, interrupt, written)
            if not isinstance(error, Exception):
                raise
            if not isinstance(error, (MountwbError, OSError)):
                return _internal_error(args.command, error, words)
            trouble = "numerical trouble: " if isinstance(error, SimulationError) else ""
            print(f"mountwb {args.command}: {trouble}{error}", file=sys.stderr)
            return exit_code(error)


if __name__ == "__main__":
    sys.exit(main())
