"""Write run results back into the case workbook, safely.

Result sheets are named ``Result efficiency``, ``Result hinges``, ``Result
sweep``, ``Result model card`` and, for a case with load cases, ``Result
loads`` (:mod:`workbook.excel.loads_sheet`: rewritten whole when the load
cases were solved, kept as it was otherwise), and ``Result fatigue``
(:mod:`workbook.excel.fatigue_sheet`, the same way); each carries, in a hidden cell, a marker
naming the sheet it was written as. A later run rewrites a sheet only when
its name is one of these and its marker names that same sheet, and only the
rows of the runs it computed: the rows of the workbook's other runs stay as
they were, and the sheet's note names them. A copy of a
result sheet (``Result efficiency (2)``) or a renamed one (``Result LP
baseline``) is the user's and is kept, like any sheet of the user's that
happens to share a name. A result sheet written again keeps its place among
the sheets. The input sheets are left as openpyxl read them (values, styles,
drop-downs, comments); formulas keep the values Excel cached, except those
that take a result (directly or through other formulas or defined names):
they are saved without one, for Excel or LibreOffice to calculate anew.

The case workbook is not overwritten (the results go to a separate, new
workbook beside it, and the reason is given) when:

- it is open in Excel or LibreOffice (the lock file ``~$<name>`` or
  ``.~lock.<name>#`` is present);
- it holds content openpyxl would drop (charts, images, pivot tables,
  macros, external links, data-validation extensions, threaded comments,
  dynamic-array formulas, resized or always-shown comment boxes, company
  and manager properties, ...), or the rewritten file would lack any kind
  of part the original has (:func:`~workbook.excel.files.lost_parts`);
- a sheet named like a result sheet exists that is not ours;
- a result sheet it would rewrite was changed since it was written (a note,
  a column or a row added, a text changed: the digest in its marker no
  longer matches; a number changed is not told);
- the user cannot write it (read-only, e.g. mode 444);
- it changed on disk while the runs were computed, or while the new file
  was built (checked again just before the rename; other ``mountwb``
  processes writing it wait for a lock on it meanwhile).

Every save is atomic (temporary file in the same folder, then rename).
"""
from __future__ import annotations

import datetime
import hashlib
import logging
from dataclasses import dataclass
from pathlib import Path

from openpyxl import Workbook
from openpyxl.formula.tokenizer import Token, Tokenizer
from openpyxl.styles import Font, PatternFill
from openpyxl.utils.cell import coordinate_to_tuple, range_boundaries

import workbook.excel.layout as L
from workbook.answers.isolation import efficiency, relative_error
from workbook.answers.results import LONG_COLUMNS, PYLON_SUM, MountResult
from workbook.excel import fatigue_sheet, loads_sheet
from workbook.excel.files import (
    ChangedOnDisk,
    held,
    lock_file,
    lock_message,
    lost_parts,
    name_beside,
    read_only_message,
    restore_formula_values,
    save_atomic,
    unsupported_content,
    workbook_bytes,
    write_atomic,
)
from workbook.excel.runs import RunSpec, TestPoint
from workbook.excel.sheets import CachedValues, open_workbook, peek, stored_cells, stored_values
from workbook.excel.styling import print_setup, write_frame, write_table, write_text_lines
from workbook.model.case import DIRECTIONS

__all__ = ["RunResult", "WriteOutcome", "ResultTable", "result_tables", "write_results", "add_result_sheets", "card_lines",
           "MARKER", "MARKER_CELL"]

log = logging.getLogger(__name__)

#: Text of the hidden marker cell of every result sheet, followed by ": <sheet title>".
MARKER = "mountwb result sheet"
#: Marker cell (its column is hidden).
MARKER_CELL = "Z1"
_HEADER_FILL = PatternFill("solid", fgColor="E2EFDA")


@dataclass
class RunResult:
    """One row of the Runs sheet and its answers.

    Attributes
    ----------
    spec : RunSpec
    result : MountResult
        One excitation result per frequency (several for a sweep).
    """

    spec: RunSpec
    result: MountResult


@dataclass(frozen=True)
class WriteOutcome:
    """Where the results went.

    Attributes
    ----------
    path : Path
        The workbook written.
    reason : str or None
        Why the case workbook was not overwritten (None: it was).
    """

    path: Path
    reason: str | None


def _match_test(tests: list[TestPoint], frequency: float):
    for test in tests:
        if test.frequency is None or abs(test.frequency - frequency) <= 1e-3 * frequency:
            return test
    return None


@dataclass(frozen=True)
class ResultTable:
    """A result table: its column headers and its rows of plain values (None: no value).

    Attributes
    ----------
    columns : tuple of str
    rows : list of tuple
        One value per column each.
    """

    columns: tuple[str, ...]
    rows: list[tuple]

    def records(self) -> list[dict]:
        """The rows as ``{column: value}``."""
        return [dict(zip(self.columns, row, strict=True)) for row in self.rows]


#: Columns of the long table of every answer (a point of a run, its location and direction) with the test
#: comparison; the efficiency table has the pylon sum's rows without location and pylon side.
_LONG_COLUMNS = ("run", "point", *LONG_COLUMNS[1:], "test amplitude N", "error %")
_PYLON_COLUMNS = tuple(column for column in _LONG_COLUMNS if column not in ("location", "pylon side"))


def _long_rows(runs: list[RunResult], tests: tuple) -> list[tuple]:
    """Every answer, one row per run, point, location and direction, with the test comparison (:data:`_LONG_COLUMNS`)."""
    by_key: dict = {}
    for test in tests:
        by_key.setdefault((test.run, test.location, test.direction), []).append(test)
    rows = []
    for run in runs:
        for point, frequency, location, side, direction, amplitude, *answers in run.result.long_rows():
            test = _match_test(by_key.get((run.spec.name, location, direction), []), frequency)
            rows.append((run.spec.name, point, frequency, location, side, direction, amplitude, *answers,
                         None if test is None else test.amplitude,
                         None if test is None else float(relative_error(amplitude, test.amplitude))))
    return rows


def result_tables(runs: list[RunResult], tests: tuple = ()) -> dict[str, ResultTable]:
    """The result tables, by sheet name (without the ``Result`` prefix).

    - ``efficiency``: pylon force per run, point and direction: amplitude,
      T, eta %, dB, the test amplitude and the error (sim - test)/test %;
    - ``hinges``: the same for every hinge;
    - ``sweep``: T and eta per direction against frequency, for sweep runs.
    """
    rows = _long_rows(runs, tests)
    location = _LONG_COLUMNS.index("location")
    kept = [i for i, column in enumerate(_LONG_COLUMNS) if column in _PYLON_COLUMNS]
    tables = {"efficiency": ResultTable(_PYLON_COLUMNS, [tuple(row[i] for i in kept) for row in rows
                                                         if row[location] == PYLON_SUM]),
              "hinges": ResultTable(_LONG_COLUMNS, [row for row in rows if row[location] != PYLON_SUM])}
    sweeps = [run for run in runs if len(run.result.runs) > 1]
    if sweeps:
        sweep = []
        for run in sweeps:
            for point in run.result.runs:
                t = point.transmissibility
                sweep.append((run.spec.name, float(point.frequency_hz), *map(float, t), *map(float, efficiency(t))))
        tables["sweep"] = ResultTable(("run", "frequency Hz", *(f"T {d}" for d in DIRECTIONS),
                                       *(f"eta % {d}" for d in DIRECTIONS)), sweep)
    return tables


def _model_part(card) -> tuple:
    """What a model card says about the model itself (not the solver's steps or the wall time)."""
    return card.bodies, card.effects, card.mounted_modes


def card_lines(runs: list[RunResult]) -> list[str]:
    """The model cards of *runs* as text lines: each run's first card in full; the other points of a sweep
    in one line each (step and wall time) when their model is the same, else in full."""
    lines = []
    for run in runs:
        cards = list(run.result.model_cards.values())
        lines += [f"Run '{run.spec.name}'", *cards[0].to_text().splitlines(), ""]
        same = [card for card in cards[1:] if _model_part(card) == _model_part(cards[0])]
        if same:
            lines.append(f"Other points of run '{run.spec.name}' (the same bodies, effects and mounted modes):")
            lines += [f"  {card.run_name}: time step {card.solver.get('time step', '-')}; wall time "
                      f"{sum(card.timings.values()):.3f} s" for card in same]
            lines.append("")
        for card in cards[1:]:
            if card not in same:
                lines += [*card.to_text().splitlines(), ""]
    return lines


def _sheet_title(name: str) -> str:
    return f"{L.RESULT_PREFIX}{name}"


def _marker(title: str) -> str:
    return f"{MARKER}: {title}"


#: Separates the marker from the digest of the sheet's content that follows it.
_DIGEST = " #"


def _shown(value) -> str:
    """A cell value of a result sheet as :func:`_content_digest` takes it: text as it is, any number or yes/no
    as ``#`` (a save by LibreOffice rounds numbers to 15 digits and saves yes/no as the formulas =TRUE() and
    =FALSE())."""
    return "#" if isinstance(value, (int, float)) or value in ("=TRUE()", "=FALSE()") else str(value)


def _content_digest(ws) -> str:
    """A digest of where *ws* holds values (but its marker) and of its texts (:func:`_shown`): a note, a
    column or a row the user adds, or a text changed, changes it."""
    marker = coordinate_to_tuple(MARKER_CELL)
    text = "\n".join(f"{key} {_shown(cell.value)}" for key, cell in sorted(ws._cells.items())
                     if key != marker and cell.value is not None and cell.value != "")
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _mark(ws) -> None:
    ws[MARKER_CELL] = f"{_marker(ws.title)}{_DIGEST}{_content_digest(ws)}"
    ws.column_dimensions[MARKER_CELL.rstrip("0123456789")].hidden = True


def is_result_sheet(ws) -> bool:
    """True if *ws* is a result sheet this package wrote, under the name it has now.

    A copy or a renamed result sheet keeps the marker of the sheet it came
    from, so its name and marker differ: it is the user's. (Workbooks written
    before the marker named its sheet carry the bare :data:`MARKER`.)
    """
    if ws.title not in RESULT_SHEETS:
        return False
    value = peek(ws, MARKER_CELL)
    return isinstance(value, str) and value.split(_DIGEST)[0] in (_marker(ws.title), MARKER)


def _edited(ws) -> bool:
    """True if the result sheet *ws* was changed since this package wrote it (a note or a column of the
    user's, say), as the digest in its marker tells; a sheet written before the marker held one is not."""
    _, _, digest = str(peek(ws, MARKER_CELL)).partition(_DIGEST)
    return bool(digest) and digest != _content_digest(ws)


def _write_table(ws, table: ResultTable, note: str) -> None:
    ws.cell(1, 1, note).font = Font(italic=True)
    write_table(ws, table.columns, table.rows, top=2, fill=_HEADER_FILL)
    _mark(ws)


_NOTES = {
    "efficiency": "Pylon force (sum of the pylon-side hinges): T = |F_pylon| / |F_exc|, eta = (1 - T) x 100 %, "
                  "dB = 20 log10 T; error = (sim - test) / test x 100 %",
    "hinges": "Hinge forces: T = |F_hinge| / |F_exc| per direction",
    "sweep": "Pylon transmissibility and isolation efficiency against frequency",
}


#: Title of the load cases' result sheet.
LOADS_SHEET = _sheet_title("loads")
#: Title of the links' fatigue result sheet.
FATIGUE_SHEET = _sheet_title("fatigue")
#: Every sheet title a write may create (and so may replace).
RESULT_SHEETS = (*(_sheet_title(name) for name in (*_NOTES, "model card")), LOADS_SHEET, FATIGUE_SHEET)


def result_sheet_names(tables: dict, loads=None, fatigue=None) -> list[str]:
    """Titles of the result sheets a write creates (with *loads* or *fatigue*, a table: its sheet too)."""
    return ([_sheet_title(name) for name in tables] + [_sheet_title("model card")]
            + [title for title, table in ((LOADS_SHEET, loads), (FATIGUE_SHEET, fatigue)) if table is not None])


def _merged(earlier: list[tuple], fresh: list[tuple], computed: set[str]) -> list:
    """Items ``(run, item)`` of an earlier write with those of the runs *computed* replaced by *fresh*.

    The fresh items of a run take the place of its first earlier item; the
    items of runs written for the first time come last.
    """
    by_run: dict[str, list] = {}
    for run, item in fresh:
        by_run.setdefault(run, []).append(item)
    items, placed = [], set()
    for run, item in earlier:
        if run not in computed:
            items.append(item)
        elif run not in placed:
            items += by_run.get(run, [])
            placed.add(run)
    for run, fresh_items in by_run.items():
        if run not in placed:
            items += fresh_items
    return items


def _earlier_rows(ws) -> tuple[list[str], list[tuple[str, dict]]]:
    """The header and the rows ``(run, {header: value})`` of a result table written before."""
    rows = list(stored_values(ws))
    header = [value for value in (rows[1] if len(rows) > 1 else ()) if value]
    return header, [(values[0], dict(zip(header, values, strict=False))) for values in rows[2:]
                    if values and values[0] is not None]


def _earlier_cards(ws) -> list[tuple[str, list[str]]]:
    """The model card of each run, ``(run, lines)``, of a model-card sheet written before."""
    blocks: list[tuple[str, list[str]]] = []
    for values in list(stored_values(ws))[1:]:
        line = "" if values[0] is None else str(values[0])
        if line.startswith("Run '") and line.endswith("'"):
            blocks.append((line[len("Run '"):-1], []))
        if blocks:
            blocks[-1][1].append(line)
    return blocks


def _kept_note(earlier: list[tuple], computed: set[str]) -> str:
    kept = list(dict.fromkeys(run for run, _ in earlier if run not in computed))
    return f"; the results of {', '.join(repr(run) for run in kept)} are from an earlier run" if kept else ""


def add_result_sheets(workbook, runs: list[RunResult], tests: tuple, stamp: str, tables: dict | None = None,
                      loads=None, fatigue=None) -> list[str]:
    """Add the result sheets of *runs* to an openpyxl *workbook*.

    The result sheets a write made before are rewritten: the rows and model
    cards of the runs just computed are replaced, those of every other run
    are kept as they were (the sheet's note names them). *tables* are
    ``result_tables(runs, tests)`` when the caller has them already.
    *loads* (:func:`~workbook.excel.loads_sheet.loads_frame`) replaces the
    loads sheet whole; without it an earlier loads sheet is kept; *fatigue*
    (:func:`~workbook.excel.fatigue_sheet.fatigue_frame`) likewise the fatigue sheet.

    Returns
    -------
    list of str
        The sheet titles written.
    """
    whole = {LOADS_SHEET: (loads, loads_sheet), FATIGUE_SHEET: (fatigue, fatigue_sheet)}
    earlier = {ws.title: ws for ws in workbook.worksheets if is_result_sheet(ws)
               and (ws.title not in whole or whole[ws.title][0] is not None)}
    computed = {run.spec.name for run in runs}
    tables = result_tables(runs, tests) if tables is None else tables
    merged = {}
    for name, note in _NOTES.items():
        title = _sheet_title(name)
        header, rows = _earlier_rows(earlier[title]) if title in earlier else ([], [])
        table = tables.get(name)
        columns = header if table is None else list(table.columns)
        fresh = [] if table is None else [(record["run"], record) for record in table.records()]
        records = _merged(rows, fresh, computed)
        if records:
            # a table without fresh rows keeps the note of the write that made it
            note = f"{note}. {stamp}{_kept_note(rows, computed)}" if fresh else peek(earlier[title], "A1")
            merged[title] = (ResultTable(tuple(columns), [tuple(record.get(column) for column in columns)
                                                          for record in records]), note)
    title = _sheet_title("model card")
    cards = _earlier_cards(earlier[title]) if title in earlier else []
    fresh = [(run.spec.name, card_lines([run])) for run in runs]
    lines = [line for block in _merged(cards, fresh, computed) for line in block]
    order = {title: index for index, title in enumerate(workbook.sheetnames)}
    for ws in earlier.values():
        workbook.remove(ws)
    for title, (table, note) in merged.items():
        _write_table(workbook.create_sheet(title), table, note)
    ws = workbook.create_sheet(_sheet_title("model card"))
    write_text_lines(ws, lines, top=2)
    ws.cell(1, 1, stamp + _kept_note(cards, computed)).font = Font(italic=True)
    print_setup(ws)
    _mark(ws)
    written = [*merged, ws.title]
    for title, (frame, module) in whole.items():
        if frame is not None:
            ws = workbook.create_sheet(title)
            ws.cell(1, 1, f"{module.NOTE}. {stamp}").font = Font(italic=True)
            write_frame(ws, frame, top=2, fill=_HEADER_FILL, quantities=module.QUANTITIES)
            _mark(ws)
            written.append(title)
    # a rewritten sheet takes the place of the one it replaces; new ones go last
    workbook._sheets.sort(key=lambda sheet: order.get(sheet.title, len(order)))
    return written


def _conflicts(workbook, titles: list[str]) -> list[str]:
    return [title for title in titles if title in workbook.sheetnames and not is_result_sheet(workbook[title])]


def _edited_sheets(workbook, titles: list[str]) -> list[str]:
    """The result sheets a write of the sheets *titles* replaces that were changed since they were written
    (the loads and fatigue sheets are replaced only when written again)."""
    return [ws.title for ws in workbook.worksheets if is_result_sheet(ws) and _edited(ws)
            and (ws.title in titles or ws.title not in (LOADS_SHEET, FATIGUE_SHEET))]


def _reason_not_to_overwrite(path: Path, sha256: str, titles: list[str], opened=None):
    """(reason or None, the loaded workbook or None, its cached values (a closed CachedValues) or None).

    *opened* (an :class:`~workbook.excel.sheets.OpenedWorkbook`) gives the workbook as the reader
    loaded it, when the file on disk still has its SHA-256; otherwise the file is loaded here.
    """
    lock = lock_file(path)
    if lock is not None:
        return lock_message(lock), None, None
    refused = read_only_message(path)
    if refused is not None:
        return refused, None, None
    current = hashlib.sha256(path.read_bytes()).hexdigest()
    if current != sha256:
        return "it changed on disk while the runs were computed", None, None
    dropped = unsupported_content(path)
    if dropped:
        return f"it holds content this program cannot keep ({', '.join(dropped)})", None, None
    pair = opened.take(current) if opened is not None else None
    if pair is not None:
        workbook, values = pair
    else:
        workbook, values = open_workbook(path)
        try:
            values.keep_formula_values()
        finally:
            values.close()
    conflicts = _conflicts(workbook, titles)
    if conflicts:
        return (f"it has sheets named {', '.join(repr(c) for c in conflicts)} that were not written by mountwb; "
                "rename them to write the results into the workbook"), None, None
    edited = _edited_sheets(workbook, titles)
    if edited:
        return (f"its result sheets {', '.join(repr(e) for e in edited)} were changed after mountwb wrote them, "
                "and writing the results again would lose the changes; rename those sheets to keep them (or "
                "delete them) to write the results into the workbook"), None, None
    return None, workbook, values


def _reference_boxes(names: dict, ws, text: str) -> list[tuple[str, tuple]]:
    """The cells a formula *text* of sheet *ws* refers to: ``(sheet title in lower case, (min col, min row,
    max col, max row))`` each, a whole column or row open-ended (None); the defined *names* (by lower-case
    name) are followed. References that cannot be placed (other workbooks, tables, 3-D ranges) are left out."""
    local = {name.lower(): defined for name, defined in ws.defined_names.items()}
    boxes: list[tuple[str, tuple]] = []
    try:
        tokens = Tokenizer(text).items
    except Exception:  # openpyxl's tokenizer refuses some formulas Excel takes; the text check still holds
        return boxes
    for token in tokens:
        if token.type != Token.OPERAND or token.subtype != Token.RANGE:
            continue
        sheet, _, ref = token.value.rpartition("!")
        sheet = sheet[1:-1].replace("''", "'") if sheet.startswith("'") else sheet or ws.title
        places = [(sheet, ref)]
        name = local.get(ref.lower()) or names.get(ref.lower())
        if name is not None:
            try:
                places = list(name.destinations)
            except Exception:  # a name openpyxl cannot parse
                places = []
        for target, place in places:
            try:
                boxes.append((target.lower(), range_boundaries(place.replace("$", ""))))
            except ValueError:
                continue
    return boxes


def _inside(box: tuple, col: int, row: int) -> bool:
    low_col, low_row, high_col, high_row = box
    return ((low_col is None or low_col <= col <= high_col) and (low_row is None or low_row <= row <= high_row))


def _result_dependents(workbook, titles) -> set[tuple[str, str]]:
    """The formula cells of *workbook* whose value may come from the sheets *titles*: ``(sheet, coordinate)`` each.

    A formula depends on those sheets when it names one (in a reference or
    in a text, as INDIRECT takes it), or refers to a cell of theirs or to a
    formula cell that depends on them, directly or through a defined name.
    """
    lowered = [title.lower() for title in titles]
    formulas = {(ws.title, cell.row, cell.column): (cell.coordinate, str(cell.value))
                for ws in workbook.worksheets for cell in stored_cells(ws) if cell.data_type == "f"}
    names = {name.lower(): defined for name, defined in workbook.defined_names.items()}
    referring: dict[str, list[tuple[tuple, tuple]]] = {}    # sheet -> (formula cell, box on that sheet)
    tainted = set()
    for key, (_, text) in formulas.items():
        boxes = _reference_boxes(names, workbook[key[0]], text)
        if any(title in text.lower() for title in lowered) or any(sheet in lowered for sheet, _ in boxes):
            tainted.add(key)
        for sheet, box in boxes:
            referring.setdefault(sheet, []).append((key, box))
    waiting = list(tainted)
    while waiting:
        sheet, row, col = waiting.pop()
        for key, box in referring.get(sheet.lower(), ()):
            if key not in tainted and _inside(box, col, row):
                tainted.add(key)
                waiting.append(key)
    return {(sheet, formulas[(sheet, row, col)][0]) for sheet, row, col in tainted}


def _cached_formula_values(workbook, values: CachedValues, results: tuple) -> dict[int, dict[str, object]]:
    """The values Excel cached for the formula cells of *workbook* (as the reader found them in *values*), by
    sheet number; none for a formula that depends on the result sheets *results* (:func:`_result_dependents`):
    its cached value is that of the earlier results, and Excel calculates it anew on opening the file."""
    stale = _result_dependents(workbook, results)
    cached = {number: {cell: value for cell, value in values.formula_values(ws.title).items()
                       if (ws.title, cell) not in stale}
              for number, ws in enumerate(workbook.worksheets, start=1) if ws.title in values.sheetnames}
    return {number: found for number, found in cached.items() if found}


def write_results(path: str | Path, sha256: str, runs: list[RunResult], tests: tuple = (), *,
                  opened=None, loads=None, fatigue=None, tables: dict | None = None) -> WriteOutcome:
    """Write the result sheets into the case workbook at *path*, or beside it.

    Parameters
    ----------
    path : str or Path
        The case workbook that was read.
    sha256 : str
        Its hash when it was read (a changed file is not overwritten).
    runs : list of RunResult
    tests : tuple of TestPoint
    opened : OpenedWorkbook, optional
        The workbook as read (``CaseBook.opened``): its sheets are written into
        without loading the file again, while the file is unchanged.
    loads : pandas.DataFrame, optional
        The solved load cases (:func:`~workbook.excel.loads_sheet.loads_frame`): the loads sheet.
    fatigue : pandas.DataFrame, optional
        The links' fatigue (:func:`~workbook.excel.fatigue_sheet.fatigue_frame`): the fatigue sheet.
    tables : dict of str to ResultTable, optional
        ``result_tables(runs, tests)`` when the caller has them already.

    Returns
    -------
    WriteOutcome
    """
    path = Path(path)
    stamp = f"Written by mountwb on {datetime.datetime.now():%Y-%m-%d %H:%M} from {path.name}"
    tables = result_tables(runs, tests) if tables is None else tables
    titles = result_sheet_names(tables, loads, fatigue)
    with held(path):
        reason, workbook, values = _reason_not_to_overwrite(path, sha256, titles, opened)
        if reason is None:
            log.info("building the new %s with the results", path.name)
            add_result_sheets(workbook, runs, tests, stamp, tables, loads, fatigue)
            data = restore_formula_values(workbook_bytes(workbook, path),
                                          _cached_formula_values(workbook, values, RESULT_SHEETS))
            lost = lost_parts(path.read_bytes(), data)
            reason = f"it holds content this program cannot keep ({', '.join(lost)})" if lost else None
        if reason is None:
            try:
                return WriteOutcome(write_atomic(path, data, unchanged=sha256), None)
            except ChangedOnDisk:
                reason = "it changed on disk while the results were being written (another save landed)"
    separate = Workbook()
    separate.remove(separate.active)
    add_result_sheets(separate, runs, tests, stamp, tables, loads, fatigue)
    target = save_atomic(separate, name_beside(path, "results"))
    log.info("%s not overwritten: %s; results written to %s", path.name, reason, target.name)
    return WriteOutcome(target, reason)
