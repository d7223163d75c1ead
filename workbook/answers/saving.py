"""Write a figure, a CSV table or a text file all at once.

Every file the package writes beside a user's work goes through
:func:`flexbodies.atomic.replacing`: a reader (or a crash) sees the old file
or the new one, never half of one, and a replaced file keeps its permissions.
"""
from __future__ import annotations

from pathlib import Path

from flexbodies.atomic import replacing

__all__ = ["save_figure", "save_csv", "save_text"]


def save_figure(figure, path: str | Path, dpi: int = 120) -> Path:
    """Save a matplotlib *figure* as a PNG at *path* (*dpi* dots per inch).

    Returns
    -------
    Path
    """
    path = Path(path)
    with replacing(path, suffix=".png.tmp") as temporary:
        figure.savefig(temporary, dpi=dpi, format="png")
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
    return path
