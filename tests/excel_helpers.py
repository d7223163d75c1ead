"""Helpers of the Excel-layer tests: edit case workbooks cell by header."""
from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

from openpyxl import load_workbook

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "cases" / "reference.xlsx"
TEMPLATE = ROOT / "templates" / "case-template.xlsx"


def column_of(ws, header: str) -> int:
    """Column number of *header* in row 1."""
    for cell in ws[1]:
        if cell.value == header:
            return cell.column
    raise KeyError(header)


def set_cells(path: Path, edits: dict) -> None:
    """Apply ``{(sheet, header, row): value}`` to the workbook at *path*."""
    wb = load_workbook(path)
    for (sheet, header, row), value in edits.items():
        wb[sheet].cell(row, column_of(wb[sheet], header)).value = value
    wb.save(path)


def copy_reference(folder: Path, name: str = "case.xlsx") -> Path:
    target = folder / name
    shutil.copyfile(REFERENCE, target)
    return target


#: Short settings that make a run take about a second (answers within tens of %).
CHEAP_SETTINGS = {"steps per period": 20, "ramp periods": 2, "settle time": 0.05, "measured periods": 4,
                  "steady tolerance": 0.5, "method": "time"}


def make_cheap(path: Path, sweep_points: int = 4) -> None:
    """Short settings, coarse rigid links and a short sweep in the workbook at *path*."""
    wb = load_workbook(path)
    for header, value in CHEAP_SETTINGS.items():
        wb["Case"].cell(3, column_of(wb["Case"], header), value)
    links = wb["Links"]
    for row in range(3, links.max_row + 1):
        links.cell(row, column_of(links, "element size"), 30)
    runs = wb["Runs"]
    for row in range(3, runs.max_row + 1):
        runs.cell(row, column_of(runs, "fidelity"), "rigid")
    excitations = wb["Excitations"]
    for row in range(3, excitations.max_row + 1):
        if excitations.cell(row, column_of(excitations, "sweep points")).value is not None:
            excitations.cell(row, column_of(excitations, "sweep points"), sweep_points)
    wb.save(path)


def sha256(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()
