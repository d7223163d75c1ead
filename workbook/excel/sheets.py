"""Read the input tables of a workbook: cells parsed by column kind, units converted, problems collected.

Every problem names the file, sheet, cell (or row and column header), the
value found and what was expected (:class:`Problem`). Formula cells are read
as the values Excel cached when it last saved the file.
"""
from __future__ import annotations

import math
import re
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Union

from openpyxl.utils import get_column_letter
from openpyxl.utils.cell import coordinate_to_tuple

import workbook.excel.layout as L
from workbook.errors import Problem, UnitProblem, WorkbookError
from workbook.excel.runs import FIDELITY_RIGID
from workbook.model.units import si_factor

__all__ = ["Record", "SheetReader", "open_workbook", "peek", "stored_cells"]


def peek(ws, coordinate: str) -> Any:
    """The value of cell *coordinate* of *ws*, without creating the cell (None if it is not stored).

    ``ws[coordinate]`` and ``ws.cell()`` add an empty cell to the sheet,
    which a later save would write.
    """
    cell = ws._cells.get(coordinate_to_tuple(coordinate))
    return None if cell is None else cell.value


def stored_cells(ws) -> list:
    """The cells stored in *ws* (those in the file), by row then column; no empty cell is created."""
    return [ws._cells[key] for key in sorted(ws._cells)]


@dataclass
class Record:
    """One data row of a table: values in SI units and the cell of each value."""

    table: L.Table
    row: int
    values: dict
    cells: dict
    raw: dict
    ok: bool

    def get(self, key: str, default: Any = None) -> Any:
        value = self.values.get(key)
        return default if value is None else value

    def vector(self, key: str, default: Any = None) -> Any:
        keys = self.table.vector_keys(key)
        values = [self.values.get(k) for k in keys]
        return default if all(v is None for v in values) else tuple(values)

    def typed(self, keys: tuple, default: Any) -> Any:
        """The cells' values as the user typed them (one value, or a tuple for several cells)."""
        raw = [self.raw.get(k) for k in keys if k in self.raw]
        if not raw:
            return default
        return raw[0] if len(raw) == 1 else tuple(raw)

    def where(self, *keys: str) -> str:
        """Cell (or range) of the columns *keys* in this row."""
        cells = [self.cells[k] for k in keys if k in self.cells]
        if not cells:
            return f"row {self.row}"
        return cells[0] if len(cells) == 1 else f"{cells[0]}:{cells[-1]}"


class SheetReader:
    """Reads one workbook, collecting problems."""

    def __init__(self, path: Path, formulas, values):
        self.path, self.formulas, self.values = path, formulas, values
        self.problems: list[Problem] = []

    def problem(self, sheet, cell, column, value, expected) -> None:
        problem = Problem(self.path.name, sheet, cell, column, value, expected)
        if problem not in self.problems:
            self.problems.append(problem)

    def record_problem(self, record: Record, keys: tuple, value: Any, expected: str) -> None:
        keys = tuple(k for k in keys if k in record.cells) or ()
        header = record.table.column(keys[0]).header if keys else None
        if len(keys) == 3 and keys == record.table.vector_keys(keys[0][:-2]):
            header = header[:-2]
        elif len(keys) > 1:
            header = f"{header} to {record.table.column(keys[-1]).header}"
        self.problem(record.table.sheet, record.where(*keys) if keys else f"row {record.row}", header, value,
                     expected)

    # -- tables -------------------------------------------------------------------------------------------

    def table(self, table: L.Table) -> list[Record]:
        """The data rows of *table* (empty if the sheet is unusable)."""
        if table.sheet not in self.values.sheetnames:
            if not table.optional:
                self.problem(table.sheet, None, None, None,
                             f"a sheet named '{table.sheet}' (sheets: {', '.join(self.values.sheetnames)})")
            return []
        ws_values, ws_formulas = self.values[table.sheet], self.formulas[table.sheet]
        positions = self._headers(table, ws_values)
        if positions is None:
            return []
        factors = self._units(table, ws_values, positions)
        records = []
        for row in range(L.FIRST_DATA_ROW, ws_values.max_row + 1):
            raw = {}
            for key, col in positions.items():
                raw[key] = self._cell(ws_values, ws_formulas, row, col, table)
            if all(v is None for v in raw.values()):
                continue
            records.append(self._record(table, row, raw, positions, factors))
        if table.single_row:
            if not records and not table.optional:
                self.problem(table.sheet, f"row {L.FIRST_DATA_ROW}", None, None, "one row of data")
            for extra in records[1:]:
                self.problem(table.sheet, f"row {extra.row}", None, "a second row", "exactly one row of data")
            records = records[:1]
        return records

    def _headers(self, table: L.Table, ws) -> Union[dict, None]:
        by_header = {c.header.lower(): c for c in table.columns}
        positions: dict[str, int] = {}
        for col in range(1, ws.max_column + 1):
            text = ws.cell(L.HEADER_ROW, col).value
            if text is None or (isinstance(text, str) and (not text.strip() or text.strip().startswith("#"))):
                continue
            cell = f"{get_column_letter(col)}{L.HEADER_ROW}"
            column = by_header.get(str(text).strip().lower())
            if column is None:
                self.problem(table.sheet, cell, None, text,
                             "a known column header (notes: start the header with '#')")
            elif column.key in positions:
                self.problem(table.sheet, cell, column.header, text, "each column once")
            else:
                positions[column.key] = col
        missing = [c for c in table.columns if c.key not in positions]
        for column in missing:
            if column.required:
                self.problem(table.sheet, f"row {L.HEADER_ROW}", column.header, None,
                             f"a column headed '{column.header}'")
        return None if any(c.required for c in missing) else positions

    def _units(self, table: L.Table, ws, positions: dict) -> dict:
        """Factor to SI of each number column (None where the unit cell is bad)."""
        factors = {}
        for key, col in positions.items():
            column = table.column(key)
            if not column.has_unit:
                continue
            text = ws.cell(L.UNIT_ROW, col).value
            try:
                factors[key] = si_factor("" if text is None else str(text), column.si_unit)
            except UnitProblem as exc:
                factors[key] = None
                self.problem(table.sheet, f"{get_column_letter(col)}{L.UNIT_ROW}", f"{column.header} (unit)",
                             text, exc.expected)
        return factors

    def _cell(self, ws_values, ws_formulas, row: int, col: int, table: L.Table) -> Any:
        value = ws_values.cell(row, col).value
        if value is None and ws_formulas.cell(row, col).data_type == "f":
            self.problem(table.sheet, f"{get_column_letter(col)}{row}", ws_values.cell(L.HEADER_ROW, col).value,
                         ws_formulas.cell(row, col).value,
                         "a formula with a calculated value (the file was saved without one: open it in "
                         "Excel or LibreOffice, recalculate and save)")
            return _FORMULA_WITHOUT_VALUE
        if isinstance(value, str) and not value.strip():
            return None
        return value

    def _record(self, table: L.Table, row: int, raw: dict, positions: dict, factors: dict) -> Record:
        values, cells, known, usable = {}, {}, len(self.problems), True
        for key, col in positions.items():
            cells[key] = f"{get_column_letter(col)}{row}"
            column = table.column(key)
            value = raw[key]
            if value is _FORMULA_WITHOUT_VALUE:
                usable = False    # reported already
                continue
            if value is None:
                if column.required:
                    self.problem(table.sheet, cells[key], column.header, None, "a value (required)")
                continue
            try:
                converted = _PARSERS[column.kind](value, column)
            except _Bad as exc:
                self.problem(table.sheet, cells[key], column.header, value, exc.expected)
                continue
            if column.has_unit:
                if factors.get(key) is None:
                    usable = False    # the unit cell is reported
                    continue
                converted = converted * factors[key] if column.kind == "number" else converted
            values[key] = converted
        raw = {key: value for key, value in raw.items() if value is not _FORMULA_WITHOUT_VALUE}
        return Record(table, row, values, cells, raw, usable and len(self.problems) == known)


_FORMULA_WITHOUT_VALUE = object()


class _Bad(ValueError):
    def __init__(self, expected: str):
        self.expected = expected
        super().__init__(expected)


def _as_number(value: Any, column: L.Column) -> float:
    if isinstance(value, bool):
        raise _Bad("a number")
    number = float(value) if isinstance(value, (int, float)) else _text_number(str(value))
    if not math.isfinite(number):
        raise _Bad("a finite number")
    return number


#: Digits grouped in threes by a separator: 1,234 or 12.345.678.
_GROUPED = re.compile(r"^[+-]?[1-9]\d{0,2}(?:(?P<sep>[,.])\d{3})+$")
_PLAIN = re.compile(r"^[+-]?(\d+([.,]\d*)?|[.,]\d+)([eE][+-]?\d+)?$")


def _text_number(text: str) -> float:
    """A number typed as text, read only when its separators leave one reading.

    ``3,5`` is 3.5, ``1.234,5`` and ``1,234.5`` are 1234.5, ``1,234,567`` is
    1234567; but ``3,568`` (or ``3.568``) may be 3568 (a thousands
    separator) or 3.568 (a decimal separator) and is refused with both
    readings. A number entered as a number is never ambiguous.
    """
    compact = text.strip().replace("\u00a0", "").replace("\u202f", "").replace(" ", "")
    grouped = _GROUPED.match(compact)
    separator = grouped.group("sep") if grouped else None
    if grouped and compact.count(separator) == 1:
        thousands, decimal = compact.replace(separator, ""), compact.replace(separator, ".")
        raise _Bad(f"a number whose separators can be read one way only: {text.strip()!r} reads as "
                   f"{thousands} ({separator!r} separating thousands) or as {decimal} ({separator!r} as the "
                   f"decimal separator); type {thousands} or {decimal}, or enter the cell as a number")
    if grouped:
        return float(compact.replace(grouped.group("sep"), ""))
    if "," in compact and "." in compact:
        decimal = "," if compact.rindex(",") > compact.rindex(".") else "."
        whole, _, fraction = compact.rpartition(decimal)
        if _GROUPED.match(whole) and _GROUPED.match(whole).group("sep") != decimal and fraction.isdigit():
            return float(whole.replace("," if decimal == "." else ".", "") + "." + fraction)
        raise _Bad("a number")
    if not _PLAIN.match(compact) and compact.lower().lstrip("+-") not in ("inf", "infinity", "nan"):
        raise _Bad("a number")
    return float(compact.replace(",", "."))


def _as_integer(value: Any, column: L.Column) -> int:
    number = _as_number(value, column)
    if number != int(number):
        raise _Bad("a whole number")
    return int(number)


def _as_text(value: Any, column: L.Column) -> str:
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    return str(value).strip()


def _as_choice(value: Any, column: L.Column) -> str:
    text = _as_text(value, column)
    for choice in column.choices:
        if text.lower() == choice.lower():
            return choice
    raise _Bad("one of " + ", ".join(column.choices))


def _as_yesno(value: Any, column: L.Column) -> bool:
    if isinstance(value, bool):
        return value
    text = _as_text(value, column).lower()
    if text in ("yes", "y", "true", "1"):
        return True
    if text in ("no", "n", "false", "0"):
        return False
    raise _Bad("yes or no")


_CUTOFF = re.compile(r"^\s*([0-9.eE+-]+)\s*([A-Za-z/ ]+)\s*$")


def _as_modes(value: Any, column: L.Column) -> Union[str, int, float]:
    """auto, static, a whole number (mode count) or a frequency with its unit (cut-off, Hz)."""
    expected = "auto, static, a mode count or a cut-off frequency such as '2000 Hz'"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        if value < 0 or value != int(value):
            raise _Bad(expected)
        return int(value)
    text = _as_text(value, column).lower()
    if text in ("auto", "static"):
        return text
    if text.isdigit():
        return int(text)
    match = _CUTOFF.match(text)
    if match:
        try:
            cutoff = float(match.group(1)) * si_factor(match.group(2), "Hz")
        except (ValueError, UnitProblem):
            raise _Bad(expected) from None
        if cutoff > 0 and math.isfinite(cutoff):
            return cutoff
    raise _Bad(expected)


def _as_fidelity(value: Any, column: L.Column) -> Union[str, int, float]:
    if isinstance(value, str) and value.strip().lower() == FIDELITY_RIGID:
        return FIDELITY_RIGID
    try:
        return _as_modes(value, column)
    except _Bad:
        raise _Bad("rigid, static, auto, a mode count or a cut-off frequency such as '2000 Hz'") from None


def _as_length_unit(value: Any, column: L.Column) -> float:
    try:
        return si_factor(_as_text(value, column), "m")
    except UnitProblem:
        raise _Bad("a length unit such as mm or m") from None


_PARSERS: dict[str, Callable] = {"number": _as_number, "integer": _as_integer, "text": _as_text,
                                 "choice": _as_choice, "yesno": _as_yesno, "modes": _as_modes,
                                 "fidelity": _as_fidelity, "unit": _as_length_unit}


def open_workbook(path: Union[str, Path]):
    """Open a workbook twice: with formulas and with the cached values.

    Returns
    -------
    (formulas, values) : two openpyxl Workbooks

    Raises
    ------
    WorkbookError
        The file is missing, not an .xlsx workbook or corrupt.
    """
    from openpyxl import load_workbook

    path = Path(path)
    if not path.is_file():
        raise WorkbookError([Problem(path.name, None, None, None, str(path), "an existing workbook file")])
    if not zipfile.is_zipfile(path):
        raise WorkbookError([Problem(path.name, None, None, None, f"{path.stat().st_size} bytes that are not "
                                     "a zip archive", "an Excel .xlsx workbook")])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return (load_workbook(path, data_only=False), load_workbook(path, data_only=True))
    except Exception as exc:  # openpyxl raises many kinds for a damaged file
        raise WorkbookError([Problem(path.name, None, None, None, f"{type(exc).__name__}: {exc}",
                                     "a readable Excel .xlsx workbook")]) from None
