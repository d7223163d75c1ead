"""Read the input tables of a workbook: cells parsed by column kind, units converted, problems collected.

Every problem names the file, sheet, cell (or row and column header), the
value found and what was expected (:class:`Problem`). Formula cells are read
as the values Excel cached when it last saved the file.
"""
from __future__ import annotations

import datetime
import difflib
import math
import re
import unicodedata
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator

from openpyxl.cell.read_only import EmptyCell
from openpyxl.utils import get_column_letter
from openpyxl.utils.cell import coordinate_to_tuple
from openpyxl.utils.datetime import to_excel
from openpyxl.worksheet.worksheet import Worksheet

import workbook.excel.layout as L
from workbook.errors import Problem, UnitProblem, WorkbookError
from workbook.excel.runs import FIDELITY_RIGID
from workbook.model.case import ModeCutoff
from workbook.model.units import DIMENSIONLESS, si_factor

__all__ = ["Record", "SheetReader", "CachedValues", "OpenedWorkbook", "open_workbook", "peek", "stored_cells",
           "stored_values", "value_rows", "matching_sheets", "MAX_DATA_ROWS",
           "MAX_FILE_BYTES", "MAX_UNPACKED_BYTES", "FORMULA_ERRORS"]


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


def value_rows(values: dict) -> Iterator[tuple]:
    """The *values* by ``(row, column)`` row by row from row 1, each row as wide as the widest.

    As openpyxl's ``iter_rows(values_only=True)`` gives a sheet's values
    (:func:`stored_values`), without creating a cell for every empty place.
    """
    last_row = max((row for row, _ in values), default=1)
    last_col = max((col for _, col in values), default=1)
    for row in range(1, last_row + 1):
        yield tuple(values.get((row, col)) for col in range(1, last_col + 1))


def stored_values(ws) -> Iterator[tuple]:
    """The values of the openpyxl worksheet *ws* row by row from row 1 (:func:`value_rows`); no cell is created."""
    return value_rows({key: cell.value for key, cell in ws._cells.items()})


def _sheet_key(name: str) -> str:
    """A sheet name without letter case and spaces: 'Test Rig', 'test rig' and 'Rotors ' read as 'Test rig', 'Rotors'."""
    return "".join(name.split()).casefold()


def matching_sheets(titles, name: str) -> list[str]:
    """The sheet *titles* that are *name* up to letter case and spaces, in workbook order."""
    return [title for title in titles if _sheet_key(title) == _sheet_key(name)]


#: The name Excel and LibreOffice give a copy of a sheet: 'Runs (2)'.
_COPY = re.compile(r"^(.*?)\s*\(\d+\)$")
#: How alike (difflib ratio, letters and digits only) a sheet name must be to a name read to be reported as a
#: likely misspelling of it.
_CLOSE_NAME = 0.8

#: Data rows read per table at most.
MAX_DATA_ROWS = 10_000


class _Cells:
    """The stored cells of one sheet (values as cached, and formulas), looked up without creating cells."""

    def __init__(self, values: dict, ws_formulas):
        self._values = {key: cell.value for key, cell in values.items()}
        #: Cells holding a number shown as a percentage (5 % is stored as 0.05).
        self.percent = {key for key, cell in values.items()
                        if isinstance(cell.value, (int, float)) and not isinstance(cell.value, bool)
                        and _percent_format(cell.number_format)}
        self._formulas = {(c.row, c.column): c.value for c in stored_cells(ws_formulas) if c.data_type == "f"}
        self.merged = list(ws_formulas.merged_cells.ranges)

    def value(self, row: int, col: int) -> Any:
        return self._values.get((row, col))

    def formula(self, row: int, col: int) -> Any:
        return self._formulas.get((row, col))

    def has(self, row: int, col: int) -> bool:
        return self._values.get((row, col)) is not None or (row, col) in self._formulas

    def columns(self, row: int) -> list[int]:
        """Columns of the stored cells of *row*."""
        return sorted(c for r, c in self._values if r == row)

    def data_cells(self) -> list[tuple[int, int]]:
        """``(row, column)`` of each data-row cell showing a value (not blank text), by row then column."""
        return sorted(key for key, value in self._values.items() if key[0] >= L.FIRST_DATA_ROW and value is not None
                      and not (isinstance(value, str) and not value.strip()))

    def rows(self, columns: set) -> list[int]:
        """Data rows with a value or a formula in one of *columns*, in order."""
        found = {r for r, c in (*self._values, *self._formulas) if c in columns and self.has(r, c)}
        return sorted(r for r in found if r >= L.FIRST_DATA_ROW)


def _percent_format(number_format: str | None) -> bool:
    """True if *number_format* shows its number as a percentage (a ``%`` outside quotes and escapes)."""
    if not number_format:
        return False
    return "%" in re.sub(r'"[^"]*"|\\.|\[[^]]*\]', "", number_format)


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
        #: True once merged cells were found in a table (its rows are incomplete: the case is not built).
        self.merged_found = False

    def problem(self, sheet, cell, column, value, expected) -> None:
        problem = Problem(self.path.name, sheet, cell, column, value, expected)
        if problem not in self.problems:
            self.problems.append(problem)

    def record_problem(self, record: Record, keys: tuple, value: Any, expected: str) -> None:
        keys = tuple(k for k in keys if k in record.cells) or ()
        header = record.table.column(keys[0]).header if keys else None
        if len(keys) == 3 and keys == record.table.vector_keys(keys[0][:-2]):
            header = record.table.column(keys[0]).header[:-2]
        elif len(keys) > 1:
            header = f"{header} to {record.table.column(keys[-1]).header}"
        self.problem(record.table.sheet, record.where(*keys) if keys else f"row {record.row}", header, value,
                     expected)

    # -- sheets -------------------------------------------------------------------------------------------

    def sheet_title(self, name: str) -> str | None:
        """The title of the workbook's sheet *name*, matched up to letter case and spaces.

        Returns None when no sheet matches, and when several do (reported,
        naming them: which one holds the data cannot be told).
        """
        titles = matching_sheets(self.values.sheetnames, name)
        if len(titles) > 1:
            self.problem(None, None, None, ", ".join(f"sheet '{title}'" for title in titles),
                         f"one sheet named '{name}' (these names read as the same one, letter case and spaces "
                         "aside: rename or delete all but one)")
            return None
        if titles and not isinstance(self.formulas[titles[0]], Worksheet):
            self.problem(titles[0], None, None, "a chart sheet",
                         f"a sheet of cells named '{name}' (a chart sheet holds no table: rename the chart sheet)")
            return None
        return titles[0] if titles else None

    def misspelt_sheets(self, read: tuple, known: tuple) -> None:
        """Report each sheet whose name is close to a sheet read but is none of *read* or *known*.

        Such a sheet ('Rotor', 'Test-rig', 'Engine_casing') would be ignored:
        an optional sheet would silently be missing. A copy of a sheet read
        beside it ('Runs (2)' with 'Runs') is the user's and not reported.

        Parameters
        ----------
        read : tuple of str
            Names of the sheets the package reads.
        known : tuple of str
            Names of other sheets the package knows (not reported).
        """
        squashed = {re.sub(r"[\W_]", "", _sheet_key(name)): name for name in read}
        for title in self.values.sheetnames:
            if any(matching_sheets((title,), name) for name in (*read, *known)):
                continue
            copy = _COPY.match(title)
            if copy and any(matching_sheets(self.values.sheetnames, name) for name in read
                            if matching_sheets((copy.group(1),), name)):
                continue    # 'Runs (2)' beside 'Runs': a copy the user made, not a misspelling
            close = difflib.get_close_matches(re.sub(r"[\W_]", "", _sheet_key(title)), squashed, n=1,
                                              cutoff=_CLOSE_NAME)
            if close:
                self.problem(title, None, None, title,
                             f"a sheet name the package reads (did you mean '{squashed[close[0]]}'? a sheet under "
                             f"another name is ignored; the names read: {', '.join(read)}; a sheet of notes: "
                             "a name unlike these)")

    # -- tables -------------------------------------------------------------------------------------------

    def table(self, table: L.Table) -> list[Record]:
        """The data rows of *table* (empty if the sheet is unusable).

        The sheet is found up to letter case and spaces (:meth:`sheet_title`).
        Only the cells stored in the file are looked at (a stray cell in the
        last row of the sheet costs nothing), and only the first
        :data:`MAX_DATA_ROWS` data rows are read: a value below them is a
        problem.
        """
        title = self.sheet_title(table.sheet)
        if title is None:
            if not table.optional and not matching_sheets(self.values.sheetnames, table.sheet):
                self.problem(table.sheet, None, None, None,
                             f"a sheet named '{table.sheet}' (sheets: {', '.join(self.values.sheetnames)})")
            return []
        sheet = _Cells(self.values.cells(title), self.formulas[title])
        positions = self._headers(table, sheet)
        self._headless(table, sheet)
        if positions is None:
            return []
        merged = self._merged(table, sheet, positions)
        factors = self._units(table, sheet, positions)
        records = []
        for row in sheet.rows(set(positions.values())):
            if row in merged:
                continue
            if row >= L.FIRST_DATA_ROW + MAX_DATA_ROWS:
                col = min(c for c in positions.values() if sheet.has(row, c))
                self.problem(table.sheet, f"{get_column_letter(col)}{row}", sheet.value(L.HEADER_ROW, col),
                             sheet.value(row, col), f"data in rows {L.FIRST_DATA_ROW} to "
                             f"{L.FIRST_DATA_ROW + MAX_DATA_ROWS - 1} (at most {MAX_DATA_ROWS} rows are read; "
                             "delete the stray cell or move the data up)")
                break
            raw = {key: self._cell(sheet, row, col, table) for key, col in positions.items()}
            if all(v is None for v in raw.values()):
                continue
            percent = {key for key, col in positions.items() if (row, col) in sheet.percent}
            records.append(self._record(table, row, raw, positions, factors, percent))
        if table.single_row:
            if not records and not table.optional:
                self.problem(table.sheet, f"row {L.FIRST_DATA_ROW}", None, None, "one row of data")
            for extra in records[1:]:
                self.problem(table.sheet, f"row {extra.row}", None, "a second row", "exactly one row of data")
            records = records[:1]
        return records

    def _merged(self, table: L.Table, sheet: "_Cells", positions: dict) -> set:
        """Report merged cells over the columns read; the data rows they cover (not read further)."""
        columns, rows = set(positions.values()), set[int]()
        for merged in sheet.merged:
            if not any(merged.min_col <= col <= merged.max_col for col in columns):
                continue
            self.problem(table.sheet, merged.coord, sheet.value(L.HEADER_ROW, merged.min_col),
                         sheet.value(merged.min_row, merged.min_col),
                         "cells that are not merged (merged cells hold one value for all of them: unmerge them "
                         "and give every cell its own value)")
            rows.update(range(merged.min_row, merged.max_row + 1))
            self.merged_found = True
        return rows

    def _headers(self, table: L.Table, sheet: "_Cells") -> dict | None:
        by_header = {c.header.lower(): c for c in table.columns}
        positions: dict[str, int] = {}
        for col in sheet.columns(L.HEADER_ROW):
            text = sheet.value(L.HEADER_ROW, col)
            if text is None or (isinstance(text, str) and (not text.strip() or text.strip().startswith("#"))):
                continue
            cell = f"{get_column_letter(col)}{L.HEADER_ROW}"
            column = by_header.get(_visible(str(text)).lower())
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

    def _headless(self, table: L.Table, sheet: "_Cells") -> None:
        """Report each column holding data below an empty header cell: its values would be ignored.

        A header cleared by mistake would drop the column's values silently (an
        optional column is then read as empty); a column of notes is headed
        with '#'.
        """
        cells: dict[int, list[int]] = {}
        for row, col in sheet.data_cells():
            header = sheet.value(L.HEADER_ROW, col)
            if header is None or (isinstance(header, str) and not header.strip()):
                cells.setdefault(col, []).append(row)
        for col, rows in sorted(cells.items()):
            more = f"; {len(rows) - 1} more cell{'s' if len(rows) > 2 else ''} below it" if len(rows) > 1 else ""
            self.problem(table.sheet, f"{get_column_letter(col)}{rows[0]}", None, sheet.value(rows[0], col),
                         f"a column header in cell {get_column_letter(col)}{L.HEADER_ROW} above data (it is empty, "
                         f"so the column's values would be ignored{more}: give the column its header, or a header "
                         "starting with '#' for notes)")

    def _units(self, table: L.Table, sheet: "_Cells", positions: dict) -> dict:
        """Factor to SI of each number column (None where the unit cell is bad)."""
        factors: dict[str, float | None] = {}
        for key, col in positions.items():
            column = table.column(key)
            if not column.has_unit:
                continue
            text = sheet.value(L.UNIT_ROW, col)
            try:
                factors[key] = si_factor("" if text is None else str(text), column.si_unit)
                if column.kind != "number" and factors[key] != 1.0:
                    raise UnitProblem("'-' (the column counts: a count has no unit)")
            except UnitProblem as exc:
                factors[key] = None
                self.problem(table.sheet, f"{get_column_letter(col)}{L.UNIT_ROW}", f"{column.header} (unit)",
                             text, exc.expected + _unit_suggestion(text, column.si_unit or ""))
        return factors

    def _cell(self, sheet: "_Cells", row: int, col: int, table: L.Table) -> Any:
        value = sheet.value(row, col)
        formula = sheet.formula(row, col)
        if value is None and formula is not None:
            self.problem(table.sheet, f"{get_column_letter(col)}{row}", sheet.value(L.HEADER_ROW, col), formula,
                         "a formula with a calculated value (the file was saved without one: open it in "
                         "Excel or LibreOffice, recalculate and save)")
            return _FORMULA_WITHOUT_VALUE
        if isinstance(value, str) and not value.strip():
            return None
        return value

    def _record(self, table: L.Table, row: int, raw: dict, positions: dict, factors: dict,
                percent: set) -> Record:
        """One data row read: each cell parsed by its column's kind and converted to SI.

        A number shown as a percentage (keys in *percent*) is read as shown:
        a cell showing 5 % holds 0.05, which is 5 % whatever the column's unit
        cell (``%``, ``-`` or empty); such a cell in a column with a dimension
        or of counts is refused. The text ``5 %`` in a column without
        dimension is 5 % too.
        """
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
            typed_percent = (isinstance(value, str) and value.strip().endswith("%") and column.kind == "number"
                             and column.si_unit == DIMENSIONLESS)
            try:
                # '5 %' typed as text is 5 %, as a cell formatted as a percentage shows it
                converted = (_as_number(value.strip()[:-1], column) / 100 if typed_percent
                             else _PARSERS[column.kind](value, column))
            except _Bad as exc:
                self.problem(table.sheet, cells[key], column.header, exc.shown or value, exc.expected)
                continue
            if typed_percent:
                values[key] = converted
                continue
            if key in percent:
                if column.kind != "number" or column.si_unit != DIMENSIONLESS:
                    self.problem(table.sheet, cells[key], column.header, _shown_percent(value),
                                 f"a number not formatted as a percentage (the cell holds {value:g}; a percentage "
                                 "is read only in a column without dimension: format the cell as a number)")
                    continue
                values[key] = converted    # the stored fraction is the value shown in %
                continue
            if column.has_unit:
                if factors.get(key) is None:
                    usable = False    # the unit cell is reported
                    continue
                converted = converted * factors[key] if column.kind == "number" else converted
                limit = L.MAGNITUDE_LIMITS.get(column.si_unit or "")
                if column.kind == "number" and limit is not None and abs(converted) > limit:
                    self.problem(table.sheet, cells[key], column.header, value,
                                 f"a magnitude of at most {limit:g} {column.si_unit} (found {converted:g} "
                                 f"{column.si_unit}: check the number and the unit in row {L.UNIT_ROW})")
                    continue
            values[key] = converted
        raw = {key: value for key, value in raw.items() if value is not _FORMULA_WITHOUT_VALUE}
        return Record(table, row, values, cells, raw, usable and len(self.problems) == known)


_FORMULA_WITHOUT_VALUE = object()


def _shown_percent(value: float) -> str:
    """A number as a percent-formatted cell shows it: 0.05 -> '5 %'."""
    return f"{value * 100:.10g} %"


class _Bad(ValueError):
    """A cell that cannot be read: what was expected, and the value as the user sees it (if not the cell's)."""

    def __init__(self, expected: str, shown: Any = None):
        self.expected, self.shown = expected, shown
        super().__init__(expected)


#: What a formula shows when it fails.
FORMULA_ERRORS = ("#NULL!", "#DIV/0!", "#VALUE!", "#REF!", "#NAME?", "#NUM!", "#N/A", "#SPILL!", "#CALC!",
                  "#GETTING_DATA")


#: Column kinds whose cells hold words (a name, a choice, yes or no, a unit), not numbers.
_WORD_KINDS = ("text", "choice", "yesno", "unit")


def _not_a_value(value: Any, column: L.Column) -> None:
    """Refuse a formula error or a date where a number or text is read."""
    if isinstance(value, str) and value.strip().upper() in FORMULA_ERRORS:
        raise _Bad(f"a value (the cell shows the formula error {value.strip()}: correct the formula or the cells "
                   "it uses)")
    if isinstance(value, (datetime.datetime, datetime.date, datetime.time)):
        number = float(to_excel(value))
        if column.kind in _WORD_KINDS:
            raise _Bad("text, not a date (Excel and LibreOffice turn text such as 1-2, 3/4 or 10:30 into a date as "
                       "it is typed: format the cell as Text and type it again)", f"the date {_shown_date(value)}")
        raise _Bad(f"a number, not a date (the cell is formatted as a date: format it as a number; it holds "
                   f"{number:.10g})", f"{number:.10g} formatted as the date {_shown_date(value)}")


def _shown_date(value) -> str:
    """A date as ISO text, without a midnight time."""
    if isinstance(value, datetime.datetime) and value.time() == datetime.time():
        value = value.date()
    return value.isoformat()


def _unit_suggestion(text: Any, si_unit: str) -> str:
    """'; did you mean ...?' for a unit cell spelt unlike the accepted spelling ('RPM', 'U/min', 'Ns/m'), or ''."""
    if text is None:
        return ""
    text = str(text).strip()
    for spelling in _UNIT_SPELLINGS:
        candidate = spelling(text)
        if candidate == text:
            continue
        try:
            si_factor(candidate, si_unit)
        except UnitProblem:
            continue
        return f"; did you mean '{candidate}'?"
    return ""


#: Rewrites of common unit spellings into the accepted one, tried in turn.
_UNIT_SPELLINGS = (
    lambda t: "rpm" if t.lower().replace(" ", "") in ("rpm", "u/min", "upm", "r/min", "rev/min") else t,
    str.lower,
    lambda t: re.sub(r"(?<=N)(?=[sm])", "*", t),
    lambda t: re.sub(r"(?<=N)(?=[sm])", "*", t.replace("KN", "kN")),
)


def _as_number(value: Any, column: L.Column) -> float:
    _not_a_value(value, column)
    if isinstance(value, bool):
        raise _Bad("a number")
    number = float(value) if isinstance(value, (int, float)) else _text_number(str(value), column.si_unit)
    if not math.isfinite(number):
        raise _Bad("a finite number")
    return number


#: Digits grouped in threes by a separator: 1,234 or 12.345.678.
_GROUPED = re.compile(r"^[+-]?[1-9]\d{0,2}(?:(?P<sep>[,.])\d{3})+$", re.ASCII)
_PLAIN = re.compile(r"^[+-]?(\d+([.,]\d*)?|[.,]\d+)([eE][+-]?\d+)?$", re.ASCII)


def _text_number(text: str, si_unit: str | None = None) -> float:
    """A number typed as text, read only when its separators leave one reading.

    ``3,5`` is 3.5, ``1.234,5`` and ``1,234.5`` are 1234.5, ``1,234,567`` is
    1234567; but ``3,568`` (or ``3.568``) may be 3568 (a thousands
    separator) or 3.568 (a decimal separator) and is refused with both
    readings. A number entered as a number is never ambiguous. A number
    followed by a unit of the quantity of *si_unit* (``20 kN/mm``) is refused
    saying that the unit goes in the unit row.
    """
    compact = _visible(text).replace("\u00a0", "").replace("\u202f", "").replace(" ", "")
    grouped = _GROUPED.match(compact)
    separator = grouped.group("sep") if grouped else ""
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
        whole_grouped = _GROUPED.match(whole)
        if whole_grouped and whole_grouped.group("sep") != decimal and fraction.isdigit():
            return float(whole.replace("," if decimal == "." else ".", "") + "." + fraction)
        raise _Bad("a number")
    if not _PLAIN.match(compact) and compact.lower().lstrip("+-") not in ("inf", "infinity", "nan"):
        with_unit = _WITH_UNIT.match(_visible(text))
        if with_unit and si_unit and _is_unit(with_unit.group(2), si_unit):
            raise _Bad(f"a number without its unit (a cell takes the number, {with_unit.group(1)}; the unit, "
                       f"{with_unit.group(2)}, goes in the column's unit cell, row {L.UNIT_ROW}, for the whole "
                       "column)")
        raise _Bad("a number")
    return float(compact.replace(",", "."))


def _is_unit(text: str, si_unit: str) -> bool:
    """True if *text* is a unit of the quantity of *si_unit*."""
    try:
        si_factor(text, si_unit)
    except UnitProblem:
        return False
    return True


#: A number followed by a unit, typed into one cell: '20 kN/mm'.
_WITH_UNIT = re.compile(r"^([+-]?[\d.,]*\d(?:[eE][+-]?\d+)?)\s*([^\W\d_].*)$")


def _as_integer(value: Any, column: L.Column) -> int:
    number = _as_number(value, column)
    if number != int(number):
        raise _Bad("a whole number")
    return int(number)


def _as_text(value: Any, column: L.Column) -> str:
    _not_a_value(value, column)
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    return _visible(str(value))


def _visible(text: str) -> str:
    """*text* as a cell shows it: without spaces at its ends and without invisible format characters (zero-width
    space, byte-order mark, soft hyphen, direction marks: text pasted from web pages and PDFs brings them), which
    would make two names that look the same differ."""
    return "".join(char for char in text if unicodedata.category(char) != "Cf").strip()


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


def _as_modes(value: Any, column: L.Column) -> str | int | ModeCutoff:
    """auto, static, a whole number (mode count) or a frequency with its unit (cut-off, Hz)."""
    expected = "auto, static, a mode count or a cut-off frequency such as '2000 Hz'"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        if value < 0 or value != int(value):
            raise _Bad(expected)
        return int(value)
    raw = _as_text(value, column)
    text = raw.lower()
    if text in ("auto", "static"):
        return text
    if text.isascii() and text.isdigit():      # not '²' or other digits int() refuses
        return int(text)
    match = _CUTOFF.match(raw)             # units are case-sensitive: mHz is not MHz
    if match:
        try:
            cutoff = float(match.group(1)) * si_factor(match.group(2), "Hz")
        except (ValueError, UnitProblem):
            raise _Bad(expected) from None
        if cutoff > 0 and math.isfinite(cutoff):
            return ModeCutoff(cutoff)
    raise _Bad(expected)


def _as_fidelity(value: Any, column: L.Column) -> str | int | ModeCutoff:
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


#: Largest workbook file read, bytes, and the most its parts may unpack to (a case workbook is ~50 kB).
MAX_FILE_BYTES, MAX_UNPACKED_BYTES = 50_000_000, 250_000_000
_OLE = bytes.fromhex("d0cf11e0a1b11ae1")


def _not_a_workbook(path: Path) -> Problem:
    """What a file that is not a zip archive is, in words a user recognises."""
    with open(path, "rb") as stream:
        head = stream.read(min(MAX_FILE_BYTES, 4_000_000))
    size = path.stat().st_size
    if head.startswith(_OLE):
        if "EncryptedPackage".encode("utf-16-le") in head:
            return Problem(path.name, None, None, None, "a workbook encrypted with a password",
                           "a workbook without a password (save a copy without one: in Excel File > Info > "
                           "Protect Workbook > Encrypt with Password, clear the password)")
        return Problem(path.name, None, None, None, "an Excel 97-2003 workbook (.xls)",
                       "an Excel .xlsx workbook (save it as Excel Workbook .xlsx)")
    if size == 0:
        return Problem(path.name, None, None, None, "an empty file (0 bytes)", "an Excel .xlsx workbook")
    if head.startswith(b"PK"):
        return Problem(path.name, None, None, None, f"{size} bytes of an incomplete zip archive (the file was cut "
                       "short: copied, downloaded or saved only in part)",
                       "a complete Excel .xlsx workbook (copy or save it again)")
    if b"\0" not in head[:65536]:
        return Problem(path.name, None, None, None, f"{size} bytes of text that are not a zip archive (a CSV or "
                       "text file named .xlsx?)", "an Excel .xlsx workbook (open the file in Excel or LibreOffice "
                       "and save it as an .xlsx workbook)")
    return Problem(path.name, None, None, None, f"{size} bytes that are not a zip archive", "an Excel .xlsx workbook")


#: The media type an OpenDocument spreadsheet (.ods) names in its 'mimetype' part.
_ODS_MIMETYPE = b"application/vnd.oasis.opendocument.spreadsheet"


def _not_excel(path: Path) -> Problem | None:
    """A problem if the zip archive at *path* is not an Excel workbook (it has no content types), naming an
    OpenDocument spreadsheet as such; None if it is."""
    try:
        with zipfile.ZipFile(path) as archive:
            names = archive.namelist()
            if "[Content_Types].xml" in names:
                return None
            mimetype = archive.read("mimetype").strip() if "mimetype" in names else b""
    except Exception:  # a damaged archive: reported as unreadable when it is opened
        return None
    if mimetype.startswith(_ODS_MIMETYPE):
        return Problem(path.name, None, None, None, "an OpenDocument spreadsheet (.ods)",
                       "an Excel .xlsx workbook (in LibreOffice: File > Save As, file type Excel 2007-365 .xlsx)")
    return Problem(path.name, None, None, None, "a zip archive without the parts of an Excel workbook",
                   "a readable Excel .xlsx workbook")


def _too_large(path: Path) -> Problem | None:
    """A problem if the file, or what its parts unpack to, exceeds the limits read."""
    size = path.stat().st_size
    if size > MAX_FILE_BYTES:
        return Problem(path.name, None, None, None, f"a file of {size:,} bytes",
                       f"a case workbook of at most {MAX_FILE_BYTES:,} bytes (the limit read)")
    try:
        with zipfile.ZipFile(path) as archive:
            unpacked = sum(info.file_size for info in archive.infolist())
    except zipfile.BadZipFile:
        return None    # reported by the reader below
    if unpacked > MAX_UNPACKED_BYTES:
        return Problem(path.name, None, None, None, f"parts that unpack to {unpacked:,} bytes",
                       f"a case workbook whose parts unpack to at most {MAX_UNPACKED_BYTES:,} bytes (the limit "
                       "read; a sheet filled to its last row or column is the usual cause)")
    return None


class CachedValues:
    """The values Excel cached in a workbook's cells, each sheet parsed the first time it is asked for.

    Holds the workbook loaded ``read_only=True, data_only=True``: only the
    sheets read are parsed (not, say, the result sheets of an earlier run).
    :meth:`keep_formula_values` keeps the cached values of the formula
    cells, which the writer puts back (:meth:`formula_values`), before
    :meth:`close`.

    Parameters
    ----------
    values : openpyxl.Workbook
        Loaded read-only with the cached values.
    formulas : openpyxl.Workbook
        The same file loaded with its formulas.
    name : str
        The file's name, for messages.
    """

    def __init__(self, values, formulas, name: str):
        self._workbook, self._formulas, self._name = values, formulas, name
        self._sheets: dict[str, dict] = {}
        self._formula_values: dict[str, dict[str, Any]] = {}
        self.sheetnames: list[str] = list(values.sheetnames)

    def cells(self, title: str) -> dict:
        """The stored cells of sheet *title* by ``(row, column)``, each with its ``value`` and ``number_format``.

        Raises
        ------
        WorkbookError
            The sheet cannot be read (a cached value that is no number in a number cell, say).
        """
        if title not in self._sheets:
            ws = self._workbook[title]
            ws.reset_dimensions()    # every stored cell, whatever size the file says the sheet has
            try:
                self._sheets[title] = {(cell.row, cell.column): cell for row in ws.iter_rows() for cell in row
                                       if not isinstance(cell, EmptyCell)}
            except Exception as exc:  # openpyxl raises many kinds for a damaged file
                raise _unreadable(self._name, exc) from None
        return self._sheets[title]

    def rows(self, title: str) -> Iterator[tuple]:
        """The values of sheet *title* row by row from row 1, each row as wide as the sheet (as openpyxl's
        ``iter_rows(values_only=True)`` of a loaded sheet)."""
        return value_rows({key: cell.value for key, cell in self.cells(title).items()})

    def keep_formula_values(self) -> None:
        """Parse the sheets holding formulas and keep the cached values of their formula cells (:meth:`formula_values`).

        Raises
        ------
        WorkbookError
            Such a sheet cannot be read.
        """
        for ws in self._formulas.worksheets:
            formulas = [cell for cell in stored_cells(ws) if cell.data_type == "f"]
            if formulas and ws.title in self.sheetnames:
                cells = self.cells(ws.title)
                found = {cell.coordinate: cells.get((cell.row, cell.column)) for cell in formulas}
                self._formula_values[ws.title] = {coordinate: cell.value for coordinate, cell in found.items()
                                                  if cell is not None and cell.value is not None}

    def formula_values(self, title: str) -> dict[str, Any]:
        """The cached value of each formula cell of sheet *title* that has one, by coordinate
        (:meth:`keep_formula_values` first)."""
        return self._formula_values.get(title, {})

    def close(self) -> None:
        """Close the workbook (the sheets parsed stay readable)."""
        self._workbook.close()


class OpenedWorkbook:
    """A case workbook as the reader opened it, handed on once to the writer of its results.

    The writer adds its sheets to the workbook the reader opened instead of
    opening the file again; it takes the pair only while the file's SHA-256
    is the one read (:meth:`take`), and only once (it changes the workbook).

    Parameters
    ----------
    sha256 : str
        SHA-256 of the bytes both workbooks were loaded from.
    formulas : openpyxl.Workbook
        Loaded with formulas (and rich text).
    values : CachedValues
        The cached values, those of the formula cells kept, closed.
    """

    def __init__(self, sha256: str, formulas, values):
        self.sha256 = sha256
        self._pair: tuple | None = (formulas, values)

    def take(self, sha256: str) -> tuple | None:
        """``(formulas, values)`` if they were loaded from bytes of this *sha256* and not taken yet, else None."""
        if self._pair is None or sha256 != self.sha256:
            return None
        pair, self._pair = self._pair, None
        return pair


def read_workbook_bytes(path: Path) -> bytes:
    """The bytes of a case workbook, checked before openpyxl sees them.

    Raises
    ------
    WorkbookError
        The file is missing, not an .xlsx workbook, or too large (see :func:`open_workbook`).
    """
    if not path.is_file():
        raise WorkbookError([Problem(path.name, None, None, None, str(path), "an existing workbook file")])
    if not zipfile.is_zipfile(path):
        raise WorkbookError([_not_a_workbook(path)])
    problem = _too_large(path) or _not_excel(path)
    if problem is not None:
        raise WorkbookError([problem])
    return path.read_bytes()


def open_workbook(path: str | Path, data: bytes | None = None) -> tuple[Any, CachedValues]:
    """Open a workbook with its formulas (and rich text, kept for the writer) and with its cached values.

    Parameters
    ----------
    path : str or Path
    data : bytes, optional
        The file's bytes, read by :func:`read_workbook_bytes` (default: read here); both
        workbooks are loaded from them, so that the file is read once.

    Returns
    -------
    (formulas, values) : openpyxl.Workbook and CachedValues
        *values* to be closed by the caller (:meth:`CachedValues.close`).

    Raises
    ------
    WorkbookError
        The file is missing, not an .xlsx workbook (an .xls or a
        password-protected one, named as such), corrupt, or larger than
        :data:`MAX_FILE_BYTES` (:data:`MAX_UNPACKED_BYTES` unpacked).
    """
    import io

    from openpyxl import load_workbook

    path = Path(path)
    if data is None:
        data = read_workbook_bytes(path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            # rich text changes no formula, the only cells the reader takes from this one (the writer keeps it)
            formulas = load_workbook(io.BytesIO(data), data_only=False, rich_text=True)
            values = load_workbook(io.BytesIO(data), data_only=True, read_only=True)
    except Exception as exc:  # openpyxl raises many kinds for a damaged file
        raise _unreadable(path.name, exc) from None
    return formulas, CachedValues(values, formulas, path.name)


def _unreadable(name: str, error: Exception) -> WorkbookError:
    """The problem of a workbook *name* openpyxl cannot read (*error*: what it raised)."""
    return WorkbookError([Problem(name, None, None, None, f"{type(error).__name__}: {error}",
                                  "a readable Excel .xlsx workbook")])
