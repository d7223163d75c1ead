"""The report workbook of a run: a summary, native charts, plots, warnings, model cards, provenance.

Sheets, each printed landscape and one page wide, headers frozen and
repeated on every printed page, every number formatted by its quantity
(:data:`~workbook.excel.styling.FORMATS`) and every header with its unit:

- ``Summary`` (one printed page): pylon isolation efficiency eta,
  transmissibility T and level 20 log10 T per run and direction at the
  single frequencies, the sweeps, the number of warnings, a native bar chart;
- ``Validation`` (with test data): pylon T and eta simulated and measured
  per run and direction, error = (sim - test) / test x 100 %;
- ``Transmissibility``: pylon T (and dB, eta) per direction against
  frequency, with a native log-log scatter chart (one curve per sweep run
  and direction; the single-frequency runs as points);
- ``Modes``: the mounted modes of each run (frequency, damping ratio,
  motion) with a native bar chart;
- ``Warnings``: every warning of the runs (e.g. a response not steady);
- ``Plots``: one picture per run (force histories, or T against frequency);
- ``Model card``: the model card of every run;
- ``Loads`` (a case with load cases): per load case and link the axial
  force, stresses and margins of safety (:mod:`workbook.excel.loads_sheet`);
- ``Fatigue`` (a case asking for the links' strength): per excitation and
  link the alternating and mean stress, Goodman and Gerber factors, and per
  speed spectrum the Miner sum and life (:mod:`workbook.excel.fatigue_sheet`);
- ``Metadata``: the input file and its SHA-256 as read, the files written
  and their SHA-256 as they are on disk after the write, versions, date.
"""
from __future__ import annotations

import datetime
import hashlib
import io
import platform
from importlib import metadata
from pathlib import Path

from openpyxl import Workbook
from openpyxl.chart import BarChart, Reference, ScatterChart, Series
from openpyxl.drawing.image import Image
from openpyxl.styles import Alignment, Font, PatternFill
from openpyxl.utils import get_column_letter

from workbook.answers.isolation import efficiency, level_db
from workbook.excel import fatigue_sheet, loads_sheet
from workbook.excel.files import new_file_target, save_atomic, signed, untouched
from workbook.excel.pictures import draw_pictures
from workbook.excel.reader import CaseBook
from workbook.excel.styling import FORMATS, print_setup, style_series, write_frame, write_text_lines
from workbook.excel.writer import RunResult, WriteOutcome, card_lines, result_tables
from workbook.model.case import DIRECTIONS

__all__ = ["write_report", "is_report", "four_pole_sheet", "FOUR_POLE_SHEET", "PACKAGES", "REPORT_KEYWORDS"]

#: Document keywords of a report workbook.
REPORT_KEYWORDS = "mountwb report"
#: The report's sheet of the mount's four-pole parameters (asked for with ``mountwb run --four-pole``).
FOUR_POLE_SHEET = "Four-pole"

#: Distributions whose versions the metadata sheet records.
PACKAGES = ("engine-mount-workbook", "exudyn", "scikit-fem", "numpy", "scipy", "pandas", "openpyxl", "pint",
            "matplotlib")

_HEADER_FILL = PatternFill("solid", fgColor="DDEBF7")
#: Row of the caption of the first table below a sheet's chart (the chart fills the rows above).
_TABLE_TOP = 29
#: Printed characters per unit of column width, and the widest column, characters.
_MAX_WIDTH = 60


def _value(value):
    return value.item() if hasattr(value, "item") else value


def _table(ws, top: int, columns: list[tuple[str, str]], rows: list, left: int = 1) -> int:
    """Write a table at row *top*: a bold header row, then *rows*, each column formatted by its quantity.

    Parameters
    ----------
    columns : list of (header, quantity)
        Header text (with its unit) and a key of :data:`FORMATS`.

    Returns
    -------
    int
        The last row written.
    """
    for col, (header, _) in enumerate(columns, start=left):
        cell = ws.cell(top, col, header)
        cell.font, cell.fill = Font(bold=True), _HEADER_FILL
        cell.alignment = Alignment(horizontal="center", vertical="center", wrap_text=True)
    for r, values in enumerate(rows, start=top + 1):
        for col, (value, (_, quantity)) in enumerate(zip(values, columns, strict=True), start=left):
            cell = ws.cell(r, col, _value(value))
            if quantity in FORMATS:
                cell.number_format = FORMATS[quantity]
    for col, (header, quantity) in enumerate(columns, start=left):
        texts = [str(_value(v[col - left])) for v in rows if v[col - left] is not None] if quantity == "text" else []
        width = max([len(w) for w in header.split()] + [len(t) for t in texts] + [9 if quantity != "text" else 6])
        letter = get_column_letter(col)
        ws.column_dimensions[letter].width = max(ws.column_dimensions[letter].width or 0, min(width + 2, _MAX_WIDTH))
    return top + len(rows)


def _title(ws, text: str, note: str | None = None) -> None:
    ws["A1"] = text
    ws["A1"].font = Font(bold=True, size=13)
    if note:
        ws["A2"] = note
        ws["A2"].font = Font(italic=True)


def _show_axes(chart) -> None:
    """Write the axes as shown: Excel hides an axis whose ``delete`` flag openpyxl leaves out."""
    chart.x_axis.delete = False
    chart.y_axis.delete = False


def _directions(label: str, quantity: str) -> list[tuple[str, str]]:
    return [(f"{label} {d}", quantity) for d in DIRECTIONS]


def _singles(runs: list[RunResult]) -> list:
    return [(run, point) for run in runs if len(run.result.runs) == 1 for point in run.result.runs]


def _summary(ws, book: CaseBook, runs: list[RunResult]) -> None:
    _title(ws, f"{book.case.name}: pylon isolation", "eta = (1 - T) x 100 %; T = |F_pylon| / |F_exc|; "
           "level = 20 log10 T (negative: isolation)")
    columns = [("run", "text"), ("frequency (Hz)", "Hz"), *_directions("eta (%)", "eta"),
               *_directions("T (-)", "T"), *_directions("level (dB)", "dB")]
    rows = [[run.spec.name, point.frequency_hz, *point.efficiency, *point.transmissibility,
             *level_db(point.transmissibility)] for run, point in _singles(runs)]
    top = 4
    last = _table(ws, top, columns, rows)
    sweeps = [run for run in runs if len(run.result.runs) > 1]
    row = last + 2
    if sweeps:
        sweep_columns = [("sweep run", "text"), ("from (Hz)", "Hz"), ("to (Hz)", "Hz"),
                         *_directions("max T (-)", "T"), *_directions("at (Hz)", "Hz")]
        sweep_rows = []
        for run in sweeps:
            points = run.result.runs
            peaks = [max(points, key=lambda p, i=i: p.transmissibility[i]) for i in range(len(DIRECTIONS))]  # type: ignore[misc]
            sweep_rows.append([run.spec.name, points[0].frequency_hz, points[-1].frequency_hz,
                               *(p.transmissibility[i] for i, p in enumerate(peaks)), *(p.frequency_hz for p in peaks)])
        row = _table(ws, row, sweep_columns, sweep_rows) + 2
    warnings = sum(len(point.warnings) for run in runs for point in run.result.runs)
    ws.cell(row, 1, f"{warnings} warning{'s' if warnings != 1 else ''} (sheet Warnings); curves: sheet "
                    "Transmissibility; mounted modes: sheet Modes; model cards and provenance: sheets Model card "
                    "and Metadata").font = Font(italic=True)
    if rows:
        chart = BarChart()
        chart.title, chart.y_axis.title, chart.x_axis.title = "Pylon isolation efficiency", "eta (%)", "run"
        chart.add_data(Reference(ws, min_col=3, max_col=5, min_row=top, max_row=top + len(rows)),
                       titles_from_data=True)
        chart.set_categories(Reference(ws, min_col=1, min_row=top + 1, max_row=top + len(rows)))
        chart.width, chart.height = 16, 7.5
        _show_axes(chart)
        ws.add_chart(chart, f"A{row + 2}")
    print_setup(ws, one_page=True)


def _validation(ws, runs: list[RunResult], tests: tuple) -> None:
    _title(ws, "Validation: pylon transmissibility, simulation against test",
           "error = (sim - test) / test x 100 %")
    rows = []
    for row in result_tables(runs, tests)["efficiency"].records():
        if row["test amplitude N"] is not None:
            t = row["T"] * row["test amplitude N"] / row["amplitude N"]
            rows.append([row["run"], row["frequency Hz"], row["direction"], row["T"], t, row["error %"], row["eta %"],
                         efficiency(t), row["dB"], float(level_db(t))])
    _table(ws, 3, [("run", "text"), ("frequency (Hz)", "Hz"), ("direction", "text"), ("T sim (-)", "T"),
                   ("T test (-)", "T"), ("error (%)", "error"), ("eta sim (%)", "eta"), ("eta test (%)", "eta"),
                   ("level sim (dB)", "dB"), ("level test (dB)", "dB")], rows)
    print_setup(ws, header_rows=3)


def _log_log_chart(title: str, y_title: str) -> ScatterChart:
    """An empty log-log scatter chart against frequency (Hz), 24 x 12 cm."""
    chart = ScatterChart()
    chart.title, chart.x_axis.title, chart.y_axis.title = title, "frequency (Hz)", y_title
    chart.x_axis.scaling.logBase = 10
    chart.y_axis.scaling.logBase = 10
    chart.scatterStyle = "lineMarker"             # straight lines between the points, not splines
    chart.width, chart.height = 24, 12
    return chart


def _transmissibility(ws, runs: list[RunResult]) -> None:
    _title(ws, "Pylon transmissibility T = |F_pylon| / |F_exc| against frequency",
           "level = 20 log10 T; eta = (1 - T) x 100 %")
    groups = [(run.spec.name, run.result.runs) for run in runs if len(run.result.runs) > 1]
    singles = sorted((p for _, p in _singles(runs)), key=lambda p: p.frequency_hz)
    if singles:
        groups.append(("single-frequency runs", singles))
    chart = _log_log_chart("Pylon transmissibility", "T (-)")
    ws.add_chart(chart, "A4")
    row = _TABLE_TOP + 1
    for group, (name, points) in enumerate(groups):
        ws.cell(row - 1, 1, name).font = Font(bold=True)
        columns = [("frequency (Hz)", "Hz"), *_directions("T (-)", "T"), *_directions("level (dB)", "dB"),
                   *_directions("eta (%)", "eta")]
        _table(ws, row, columns, [[p.frequency_hz, *p.transmissibility, *level_db(p.transmissibility),
                                   *p.efficiency] for p in points])
        x = Reference(ws, min_col=1, min_row=row + 1, max_row=row + len(points))
        for i, d in enumerate(DIRECTIONS):
            series = Series(Reference(ws, min_col=2 + i, min_row=row + 1, max_row=row + len(points)), x,
                            title=f"{name}: {d}")
            style_series(series, d, group, markers=name == "single-frequency runs")
            chart.series.append(series)
        row += len(points) + 3
    _show_axes(chart)
    print_setup(ws, table_below=_TABLE_TOP)


def _modes(ws, runs: list[RunResult]) -> None:
    _title(ws, "Mounted modes: the engine on its mount", "linearised about the static preload; "
           "zeta = damping ratio")
    rows = []
    for run in runs:
        card = next(iter(run.result.model_cards.values()))    # the points of a sweep share the model
        rows += [[run.spec.name, number, frequency, 100 * zeta, description]
                 for number, (frequency, zeta, description) in enumerate(card.mounted_modes, start=1)]
    last = _table(ws, 3, [("run", "text"), ("mode", "text"), ("frequency (Hz)", "Hz"), ("zeta (%)", "zeta"),
                          ("engine motion", "text")], rows)
    ws.column_dimensions["E"].width = max([len(row[4]) + 2 for row in rows] + [20])    # one line each, printed in full
    first = runs[0].spec.name if runs else None
    count = sum(row[0] == first for row in rows)
    if count:
        chart = BarChart()
        chart.type = "bar"
        chart.title, chart.y_axis.title, chart.x_axis.title = f"Mounted modes ({first})", "frequency (Hz)", "mode"
        chart.add_data(Reference(ws, min_col=3, min_row=3, max_row=3 + count), titles_from_data=True)
        chart.set_categories(Reference(ws, min_col=2, min_row=4, max_row=3 + count))
        chart.width, chart.height, chart.legend = 16, 7.5, None
        _show_axes(chart)
        ws.add_chart(chart, f"A{last + 3}")               # below the table: the page is as wide as the table
    print_setup(ws, header_rows=3)


def _warnings(ws, runs: list[RunResult]) -> None:
    _title(ws, "Warnings of the runs", "a warning names a result to read with care; none: nothing to report")
    rows = [[run.spec.name, point.name, warning] for run in runs for point in run.result.runs
            for warning in point.warnings]
    _table(ws, 3, [("run", "text"), ("point", "text"), ("warning", "text")],
           rows or [["(none)", "", "no run gave a warning"]])
    ws.column_dimensions["C"].width = 110
    for row in ws.iter_rows(min_row=4, min_col=3, max_col=3):
        row[0].alignment = Alignment(wrap_text=True, vertical="top")
    print_setup(ws, header_rows=3)


def _plots(ws, runs: list[RunResult], pictures: list[bytes]) -> None:
    """The pictures of *runs* (PNG, one per run, :mod:`workbook.excel.pictures`), two side by side."""
    row, height = 1, 0
    for number, (run, png) in enumerate(zip(runs, pictures, strict=True)):
        column = 1 if number % 2 == 0 else 12      # two pictures side by side (10 default columns each)
        ws.cell(row, column, f"Run '{run.spec.name}'").font = Font(bold=True)
        image = Image(io.BytesIO(png))
        ws.add_image(image, f"{get_column_letter(column)}{row + 1}")
        height = max(height, int(image.height / 20) + 3)
        if number % 2 == 1:
            row, height = row + height, 0
    print_setup(ws)


def _model_cards(ws, runs: list[RunResult]) -> None:
    write_text_lines(ws, card_lines(runs))
    print_setup(ws)


def four_pole_sheet(ws, pole) -> None:
    """Fill *ws* with the mount's four-pole parameters (a
    :class:`~workbook.solve.four_pole.FourPole`): magnitude (N/m) and
    phase (deg) of K11, K21 and K22 per direction against frequency, and a
    native log-log chart of the magnitudes."""
    table = pole.to_pandas()
    _title(ws, f"{pole.case_name}: four-pole parameters of the mount",
           "K11, K22: driving-point dynamic stiffness at the engine and at the pylon pins; K21: blocked transfer "
           "dynamic stiffness (both other terminals blocked)")
    columns = [("frequency (Hz)", "Hz")] + [(name.replace(" N/m", " (N/m)").replace(" deg", " (deg)"),
                                              "N/m" if name.endswith(" N/m") else "deg") for name in table.columns]
    top = _TABLE_TOP + 1
    ws.cell(_TABLE_TOP, 1, "four-pole parameters").font = Font(bold=True)
    _table(ws, top, columns, [[frequency, *row] for frequency, row in zip(table.index, table.to_numpy(), strict=True)])
    chart = _log_log_chart("Dynamic stiffness", "|K| (N/m)")
    x = Reference(ws, min_col=1, min_row=top + 1, max_row=top + len(table))
    magnitudes = {col: name[1:name.index("|", 1)].split() for col, name in enumerate(table.columns, start=2)
                  if name.startswith("|")}                                  # "|K11 x| N/m": K11, x
    quantities = list(dict.fromkeys(quantity for quantity, _ in magnitudes.values()))
    for col, (quantity, direction) in magnitudes.items():
        series = Series(Reference(ws, min_col=col, min_row=top + 1, max_row=top + len(table)), x,
                        title=f"{quantity} {direction}")
        style_series(series, direction, group=quantities.index(quantity))
        chart.series.append(series)
    _show_axes(chart)
    ws.add_chart(chart, "A4")
    print_setup(ws, table_below=_TABLE_TOP)
    ws.page_setup.fitToWidth, ws.print_title_cols = 2, "A:A"     # 19 columns: two pages wide, each with its frequencies


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _metadata(ws, book: CaseBook, runs: list[RunResult], written: WriteOutcome | None) -> None:
    def version(name: str) -> str:
        try:
            return metadata.version(name)
        except metadata.PackageNotFoundError:
            return "not installed"

    _title(ws, "Provenance", "SHA-256 of each file as it is on disk after this run wrote it")
    rows = [["input file", str(book.path.resolve())], ["input SHA-256 as read", book.sha256]]
    if written is not None:
        label = "case workbook with the results" if written.reason is None else "results workbook (beside the input)"
        rows += [[label, str(written.path.resolve())], [f"{label}: SHA-256", _sha256(written.path)]]
        if written.reason is not None:
            rows += [["input not overwritten because", written.reason],
                     ["input SHA-256 now", _sha256(book.path)]]
    rows += [["case", book.case.name], ["runs", ", ".join(run.spec.name for run in runs)],
             ["date", datetime.datetime.now().astimezone().isoformat(timespec="seconds")],
             ["python", platform.python_version()], ["platform", platform.platform()]]
    rows += [[f"version {name}", version(name)] for name in PACKAGES]
    _table(ws, 3, [("item", "text"), ("value", "text")], rows)
    ws.column_dimensions["B"].width = 100
    print_setup(ws, header_rows=3)


def is_report(path: Path) -> bool:
    """True if the file at *path* is a report workbook this module wrote and nobody saved since.

    A report someone annotated and saved (in Excel or LibreOffice, which keep
    its keywords) is theirs: it is not replaced.
    """
    return untouched(path, "report")


def write_report(path: str | Path, book: CaseBook, runs: list[RunResult],
                 written: WriteOutcome | None = None, *, four_pole=None, pictures=None, loads=None,
                 fatigue=None) -> WriteOutcome:
    """Write the report workbook of *runs* to *path* (atomically), or beside it.

    An existing *path* is replaced only if it is a report this module wrote,
    unchanged since (:func:`is_report`), not read-only and not open in Excel
    or LibreOffice; otherwise (the case workbook itself, a report someone
    annotated, any other file) the report goes to a new name beside it.

    Parameters
    ----------
    path : str or Path
    book : CaseBook
        The case workbook as read.
    runs : list of RunResult
    written : WriteOutcome, optional
        Where the results were written (:func:`~workbook.excel.writer.write_results`):
        the metadata records that file's SHA-256 as it is now.
    four_pole : FourPole, optional
        The mount's four-pole set: a Four-pole sheet (:func:`four_pole_sheet`).
    pictures : workbook.excel.pictures.Pictures, optional
        The pictures of *runs*, being drawn (:func:`~workbook.excel.pictures.start_pictures`);
        default: drawn here.
    loads : pandas.DataFrame, optional
        The solved load cases (:func:`~workbook.excel.loads_sheet.loads_frame`): a Loads sheet.
    fatigue : pandas.DataFrame, optional
        The links' fatigue (:func:`~workbook.excel.fatigue_sheet.fatigue_frame`): a Fatigue sheet.

    Returns
    -------
    WriteOutcome
    """
    target, reason = new_file_target(path, "report", is_report)
    workbook = Workbook()
    workbook.properties.creator, workbook.properties.keywords = "mountwb", REPORT_KEYWORDS
    workbook.active.title = "Summary"
    _summary(workbook.active, book, runs)
    if book.tests:
        _validation(workbook.create_sheet("Validation"), runs, book.tests)
    _transmissibility(workbook.create_sheet("Transmissibility"), runs)
    _modes(workbook.create_sheet("Modes"), runs)
    _warnings(workbook.create_sheet("Warnings"), runs)
    _plots(workbook.create_sheet("Plots"), runs, draw_pictures(runs) if pictures is None else pictures.result())
    _model_cards(workbook.create_sheet("Model card"), runs)
    if loads is not None:
        ws = workbook.create_sheet("Loads")
        _title(ws, f"{book.case.name}: limit load cases", loads_sheet.NOTE)
        write_frame(ws, loads, top=4, fill=_HEADER_FILL, quantities=loads_sheet.QUANTITIES)
    if fatigue is not None:
        ws = workbook.create_sheet("Fatigue")
        _title(ws, f"{book.case.name}: link fatigue", fatigue_sheet.NOTE)
        write_frame(ws, fatigue, top=4, fill=_HEADER_FILL, quantities=fatigue_sheet.QUANTITIES)
    if four_pole is not None:
        four_pole_sheet(workbook.create_sheet(FOUR_POLE_SHEET), four_pole)
    _metadata(workbook.create_sheet("Metadata"), book, runs, written)
    return WriteOutcome(save_atomic(workbook, target, finish=lambda data: signed(data, "report")), reason)
