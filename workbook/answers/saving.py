"""Write a figure, a CSV table or a text file all at once.

Every file the package writes beside a user's work goes through
:func:`flexbodies.atomic.replacing`: a reader (or a crash) sees the old file
or the new one, never half of one, and a replaced file keeps its permissions.
Each file written is recorded for :func:`recording_writes`: a command
interrupted after writing some of its files names them.
"""
from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

from flexbodies.atomic import replacing

__all__ = ["save_figure", "save_csv", "save_text", "recording_writes", "record_written", "free_stem"]

#: The lists of :func:`recording_writes` blocks open now.
_RECORDERS: list[list[Path]] = []


@contextmanager
def recording_writes():
    """Collect the files written inside the block (by this module and the workbook saves), in order.

    Yields
    ------
    list of Path
        Filled as files are written.
    """
    written: list[Path] = []
    _RECORDERS.append(written)
    try:
        yield written
    finally:
        _RECORDERS.remove(written)


def record_written(path: str | Path) -> None:
    """Note that the file at *path* was just written (see :func:`recording_writes`)."""
    for written in _RECORDERS:
        written.append(Path(path))


def save_figure(figure, path: str | Path, dpi: int = 120) -> Path:
    """Save a matplotlib *figure* as a PNG at *path* (*dpi* dots per inch).

    Returns
    -------
    Path
    """
    path = Path(path)
    with replacing(path, suffix=".png.tmp") as temporary:
        figure.savefig(temporary, dpi=dpi, format="png")
    record_written(path)
    return path


def save_csv(frame, path: str | Path, *, index: bool = True) -> Path:
    """Save a pandas *frame* as CSV at *path* (with its index when *index*).

    Returns
    -------
    Path
    """
    path = Path(path)
    with replacing(path, suffix=".csv.tmp") as temporary:
        frame.to_csv(temporary, index=index)
    record_written(path)
    return path


def save_text(text: str, path: str | Path) -> Path:
    """Save *text* (UTF-8) at *path*.

    Returns
    -------
    Path
    """
    path = Path(path)
    with replacing(path) as temporary:
        temporary.write_text(text, encoding="utf-8")
    record_written(path)
    return path


def free_stem(folder: str | Path, stem: str, suffixes: tuple[str, ...]) -> str:
    """*stem*, or the first of ``stem-2``, ``stem-3``, ... with none of ``<stem><suffix>`` in *folder*.

    A set of files written together (a table, its sheet, its plot) gets new
    names all at once when any of them exists.
    """
    folder = Path(folder)
    name, number = stem, 1
    while any((folder / f"{name}{suffix}").exists() for suffix in suffixes):
        number += 1
        name = f"{stem}-{number}"
    return name
