"""Workbook files on disk: atomic saves and the checks made before overwriting one.

openpyxl rewrites a whole workbook from what it understood; content it does
not understand is dropped silently. :func:`unsupported_content` looks inside
the .xlsx (a zip archive) for such content, so that a run can refuse to
overwrite the file and write its results elsewhere instead.
"""
from __future__ import annotations

import logging
import re
import zipfile
from pathlib import Path
from typing import Callable, Union
from xml.sax.saxutils import escape

from flexbodies.atomic import replacing

__all__ = ["save_atomic", "lock_file", "unsupported_content", "restore_formula_values"]

log = logging.getLogger(__name__)

#: Zip members (by name prefix or exact name) openpyxl drops or may mangle, and what they are.
_MEMBERS = (
    ("xl/charts/", "charts"),
    ("xl/chartsheets/", "chart sheets"),
    ("xl/media/", "images"),
    ("xl/pivotTables/", "pivot tables"),
    ("xl/pivotCache/", "pivot caches"),
    ("xl/vbaProject.bin", "macros (VBA)"),
    ("xl/externalLinks/", "external links"),
    ("xl/slicers/", "slicers"),
    ("xl/slicerCaches/", "slicers"),
    ("xl/timelines/", "timelines"),
    ("xl/ctrlProps/", "form controls"),
    ("xl/activeX/", "ActiveX controls"),
    ("xl/embeddings/", "embedded objects"),
    ("xl/model/", "a data model"),
    ("xl/queryTables/", "queries"),
    ("xl/connections.xml", "data connections"),
    ("customXml/", "custom XML parts"),
)
#: Worksheet extensions (extLst) openpyxl drops.
_EXTENSIONS = (
    (re.compile(rb"<x14:dataValidations?\b"), "data-validation extensions (lists from other sheets)"),
    (re.compile(rb"<x14:conditionalFormattings?\b"), "conditional-formatting extensions"),
    (re.compile(rb"<x14:sparklineGroups?\b"), "sparklines"),
)
_SHEET = re.compile(r"^xl/worksheets/[^/]+\.xml$")
#: Shapes in a drawing (text boxes, arrows) are dropped even when images are kept.
_SHAPE = re.compile(rb"<xdr:sp\b")


def unsupported_content(path: Union[str, Path]) -> list[str]:
    """What in the workbook at *path* openpyxl would drop on saving (empty: nothing).

    Parameters
    ----------
    path : str or Path
        An .xlsx or .xlsm file.

    Returns
    -------
    list of str
        Plain-word descriptions, e.g. ``["charts", "macros (VBA)"]``.
    """
    found = []
    with zipfile.ZipFile(path) as archive:
        names = archive.namelist()
        for prefix, what in _MEMBERS:
            if any(name == prefix or name.startswith(prefix) for name in names) and what not in found:
                found.append(what)
        for name in names:
            if name.startswith("xl/drawings/") and name.endswith(".xml") and "_rels" not in name:
                if _SHAPE.search(archive.read(name)) and "drawn shapes" not in found:
                    found.append("drawn shapes")
            if _SHEET.match(name):
                data = archive.read(name)
                for pattern, what in _EXTENSIONS:
                    if what not in found and pattern.search(data):
                        found.append(what)
    return found


def lock_file(path: Union[str, Path]) -> Union[Path, None]:
    """Excel's lock file ``~$<name>`` beside *path* if present (the workbook is open in Excel)."""
    path = Path(path)
    lock = path.with_name("~$" + path.name)
    return lock if lock.exists() else None


def _cached(value) -> Union[tuple[str, str], None]:
    """(type attribute, text) of a cached formula value; None for a type not restored."""
    if isinstance(value, bool):
        return ' t="b"', "1" if value else "0"
    if isinstance(value, (int, float)):
        return "", repr(float(value)) if isinstance(value, float) else str(value)
    if isinstance(value, str):
        return ' t="str"', escape(value)
    return None


def restore_formula_values(path: Union[str, Path], cached: dict[int, dict[str, object]]) -> None:
    """Put the cached values of formula cells back into an .xlsx openpyxl wrote.

    openpyxl keeps formulas but writes them without the value Excel last
    calculated; a reader of the saved file (this package's included) would
    find none until Excel opened and saved it again.

    Parameters
    ----------
    path : str or Path
        The .xlsx written by openpyxl (rewritten in place).
    cached : dict of int to dict of str to value
        Per sheet number (1-based position in the workbook), cell -> value.
    """
    with zipfile.ZipFile(path) as archive:
        members = [(info, archive.read(info.filename)) for info in archive.infolist()]
    changed = False
    for i, (info, data) in enumerate(members):
        match = re.match(r"^xl/worksheets/sheet(\d+)\.xml$", info.filename)
        if not match or int(match.group(1)) not in cached:
            continue
        xml = data.decode("utf-8")
        for cell, value in cached[int(match.group(1))].items():
            typed = _cached(value)
            if typed is None:
                continue
            pattern = re.compile(rf'<c r="{cell}"([^>]*)>(<f\b[^>]*/>|<f\b[^>]*>.*?</f>)<v\s*/>(</c>)', re.S)
            xml = pattern.sub(lambda m: f'<c r="{cell}"{m.group(1)}{typed[0]}>{m.group(2)}<v>{typed[1]}</v></c>', xml)
        members[i] = (info, xml.encode("utf-8"))
        changed = True
    if changed:
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
            for info, data in members:
                archive.writestr(info, data)


def save_atomic(workbook, path: Union[str, Path], finish: Union[Callable[[Path], None], None] = None) -> Path:
    """Save an openpyxl workbook to *path* atomically.

    The workbook is written to a temporary file in the same folder and then
    renamed over *path*, so *path* is never half-written; it keeps the
    permissions of the workbook it replaces.

    Parameters
    ----------
    workbook : openpyxl.Workbook
    path : str or Path
    finish : callable, optional
        Called with the temporary file's path before the rename (to post-process it).

    Returns
    -------
    Path
    """
    path = Path(path)
    with replacing(path, suffix=".xlsx.tmp") as temporary:
        workbook.save(temporary)
        if finish is not None:
            finish(temporary)
    log.info("saved %s", path)
    return path
