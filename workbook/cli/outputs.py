"""The files a command writes: the paths it accepts, and where each file goes.

- An output path must end as its option says (``--csv OUT.csv``,
  ``--report OUT.xlsx``, ...) and may not be an input of the command (the
  case file, a rig record): :func:`check_output` refuses it before anything
  is computed (exit 2, nothing written).
- An output folder (``--output DIR``, ``--export FOLDER``) may be new or an
  existing folder, not a file: :func:`output_folder` refuses a file as
  the command line is read.
- An existing file is replaced only when this program wrote it and nobody
  changed it since (a signed workbook, :func:`~workbook.excel.files.untouched`);
  any other file of that name is kept and the new file goes to a new name
  beside it (:func:`~workbook.excel.files.new_file_target`), which the
  command prints with the reason.
"""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Callable

from workbook.errors import UsageError

__all__ = ["check_output", "output_folder", "print_written", "write_output"]


def check_output(option: str, path: str | None, suffixes: tuple[str, ...], inputs=()) -> None:
    """Refuse an output path with another ending than *suffixes*, or one that names an input.

    Parameters
    ----------
    option : str
        The option (or argument) that gave *path*, for the message.
    path : str or None
        The output path (None: not asked for; nothing to check).
    suffixes : tuple of str
        Accepted endings, lower case with the dot (``(".csv",)``).
    inputs : iterable of str or None
        The files the command reads.

    Raises
    ------
    UsageError
        Naming the option, the path, what was found and what was expected.
    """
    if path is None:
        return
    found = Path(path).suffix
    if found.lower() not in suffixes:
        raise UsageError(f"{option} {path}: expected a file ending in {' or '.join(suffixes)}, found "
                         f"{repr(found) if found else 'no ending'}; this option writes {suffixes[0][1:].upper()}")
    for source in inputs:
        if source is not None and Path(source).exists() and Path(path).exists() and Path(path).samefile(source):
            raise UsageError(f"{option} {path}: that is an input of this command ({source}); give a new file name")


def output_folder(text: str) -> str:
    """An option's output folder, new or existing, or argparse's usage error when a file has that name."""
    if Path(text).exists() and not Path(text).is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a file; expected a folder for the files written (a new "
                                         "name makes one)")
    return text


def print_written(named, what: str, target, reason: str | None) -> None:
    """Print where a file went: the file named, or beside it with the reason."""
    if reason is None:
        print(f"{what} written to {target}")
    else:
        print(f"{named} was not overwritten: {reason}.\n{what} written to {target}")


def write_output(path: str, what: str, label: str, write: Callable[[Path], Path],
                 replaceable: Callable[[Path], bool] | None = None) -> Path:
    """Write one output file of a command at *path*, or beside an existing file there, and say where.

    Parameters
    ----------
    path : str
        The path the user gave (checked by :func:`check_output`).
    what : str
        What the file holds, for the message (``"table"``).
    label : str
        Part of the new name beside an existing file (``<stem>-<label>-<date-time><ending>``).
    write : callable
        Writes the file at the path it is given, all at once; returns that path.
    replaceable : callable, optional
        True for an existing file that may be replaced (None: no file may be).

    Returns
    -------
    Path
        The file written.
    """
    from workbook.excel.files import new_file_target

    target, reason = new_file_target(path, label, replaceable)
    written = write(target)
    print_written(path, what, written, reason)
    return written
