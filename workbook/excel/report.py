"""The report workbook of a run: summary, native charts, plots, model cards, metadata.

Sheets:

- ``Summary``: pylon isolation efficiency per run and direction (single
  frequencies) with a native bar chart;
- ``Validation`` (with test data): the seed study's validation table, pylon
  T and eta simulated and measured per run and direction, error =
  (sim - test) / test x 100 %;
- ``Transmissibility``: pylon T per direction against frequency with a
  native scatter chart (one curve per sweep run and direction; the single
  frequency runs as points);
- ``Plots``: one PNG per run (force histories, or T against frequency for a
  sweep);
- ``Model card``: the model card of every run;
- ``Metadata``: input file and its SHA-256, package versions, date.
"""
from __future__ import annotations

import datetime
import io
import platform
import zipfile
from importlib import metadata
from pathlib import Path
from typing import Union

from openpyxl import Workbook
from openpyxl.chart import BarChart, Reference, ScatterChart, Series
from openpyxl.drawing.image import Image
from openpyxl.styles import Font

from workbook.excel.files import new_file_target, save_atomic
from workbook.excel.reader import CaseBook
from workbook.excel.writer import RunResult, WriteOutcome, card_lines, result_frames
from workbook.model.case import DIRECTIONS

__all__ = ["write_report", "is_report", "PACKAGES", "REPORT_KEYWORDS"]

#: Document keywords that mark a report workbook (an existing report may be replaced).
REPORT_KEYWORDS = "mountwb report"

#: Distributions whose versions the metadata sheet records.
PACKAGES = ("engine-mount-workbook", "exudyn", "scikit-fem", "numpy", "scipy", "pandas", "openpyxl", "pint",
            "matplotlib")


def _rows(ws, header: list, rows: list, start: int = 1) -> None:
    for col, name in enumerate(header, start=1):
        ws.cell(start, col, name).font = Font(bold=True)
    for r, values in enumerate(rows, start=start + 1):
        for col, value in enumerate(values, start=1):
            ws.cell(r, col, value)


def _show_axes(chart) -> None:
    """Write the axes as shown: Excel hides an axis whose ``delete`` flag openpyxl leaves out."""
    chart.x_axis.delete = False
    chart.y_axis.delete = False


def _summary(ws, case_name: str, runs: list[RunResult]) -> None:
    ws["A1"] = f"{case_name}: pylon isolation efficiency eta = (1 - T) x 100 %"
    ws["A1"].font = Font(bold=True, size=13)
    rows = [[run.spec.name, point.frequency_hz, *point.efficiency, *point.transmissibility]
            for run in runs if len(run.result.runs) == 1 for point in run.result.runs]
    _rows(ws, ["run", "frequency Hz", *(f"eta % {d}" for d in DIRECTIONS), *(f"T {d}" for d in DIRECTIONS)],
          rows, start=3)
    ws.column_dimensions["A"].width = 28
    if not rows:
        return
    chart = BarChart()
    chart.title, chart.y_axis.title, chart.x_axis.title = "Pylon isolation efficiency", "eta %", "run"
    chart.add_data(Reference(ws, min_col=3, max_col=5, min_row=3, max_row=3 + len(rows)), titles_from_data=True)
    chart.set_categories(Reference(ws, min_col=1, min_row=4, max_row=3 + len(rows)))
    chart.width, chart.height = 18, 9
    _show_axes(chart)
    ws.add_chart(chart, "J3")


def _validation(ws, runs: list[RunResult], tests: tuple) -> None:
    ws["A1"] = "Validation: pylon transmissibility, simulation against test; error = (sim - test) / test x 100 %"
    ws["A1"].font = Font(bold=True, size=13)
    frame = result_frames(runs, tests)["efficiency"]
    frame = frame[frame["test amplitude N"].notna()]
    t_test = frame["T"] * frame["test amplitude N"] / frame["amplitude N"]
    rows = [[row["run"], row["frequency Hz"], row["direction"], row["T"], t, row["error %"], row["eta %"],
             (1 - t) * 100] for (_, row), t in zip(frame.iterrows(), t_test)]
    _rows(ws, ["run", "frequency Hz", "direction", "T sim", "T test", "error %", "eta sim %", "eta test %"], rows,
          start=3)


def _transmissibility(ws, runs: list[RunResult]) -> None:
    ws["A1"] = "Pylon transmissibility T = |F_pylon| / |F_exc| against frequency"
    ws["A1"].font = Font(bold=True, size=13)
    groups = [(run.spec.name, run.result.runs) for run in runs if len(run.result.runs) > 1]
    singles = sorted((p for run in runs if len(run.result.runs) == 1 for p in run.result.runs),
                     key=lambda p: p.frequency_hz)
    if singles:
        groups.append(("single-frequency runs", singles))
    chart = ScatterChart()
    chart.title, chart.x_axis.title, chart.y_axis.title = "Transmissibility", "frequency Hz", "T"
    chart.x_axis.scaling.logBase = 10
    chart.y_axis.scaling.logBase = 10
    chart.width, chart.height = 18, 10
    row = 3
    for name, points in groups:
        _rows(ws, ["frequency Hz", *(f"{name}: T {d}" for d in DIRECTIONS)],
              [[p.frequency_hz, *p.transmissibility] for p in points], start=row)
        x = Reference(ws, min_col=1, min_row=row + 1, max_row=row + len(points))
        for i, _ in enumerate(DIRECTIONS):
            series = Series(Reference(ws, min_col=2 + i, min_row=row, max_row=row + len(points)), x,
                            title_from_data=True)
            if name == "single-frequency runs":
                series.marker.symbol, series.graphicalProperties.line.noFill = "circle", True
            chart.series.append(series)
        row += len(points) + 3
    ws.column_dimensions["A"].width = 14
    _show_axes(chart)
    ws.add_chart(chart, "G3")


def _figure(run: RunResult):
    import matplotlib.pyplot as plt

    result = run.result
    if len(result.runs) == 1:
        return result.plot_time_histories()
    fig, ax = plt.subplots(figsize=(8, 4.5), constrained_layout=True)
    frequencies = [p.frequency_hz for p in result.runs]
    for i, d in enumerate(DIRECTIONS):
        ax.loglog(frequencies, [p.transmissibility[i] for p in result.runs], marker="o", ms=3, label=d)
    ax.axhline(1.0, color="0.6", lw=0.8, ls="--")
    ax.set_xlabel("frequency Hz")
    ax.set_ylabel("pylon transmissibility T")
    ax.legend(title="direction")
    ax.set_title(f"{result.case_name}: {run.spec.name}")
    return fig


def _plots(ws, runs: list[RunResult]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    row = 1
    for run in runs:
        ws.cell(row, 1, f"Run '{run.spec.name}'").font = Font(bold=True)
        fig = _figure(run)
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=80)
        plt.close(fig)
        image = Image(io.BytesIO(buffer.getvalue()))
        ws.add_image(image, f"A{row + 1}")
        row += int(image.height / 20) + 4


def _metadata(ws, book: CaseBook, runs: list[RunResult]) -> None:
    def version(name: str) -> str:
        try:
            return metadata.version(name)
        except metadata.PackageNotFoundError:
            return "not installed"

    rows = [["input file", str(book.path.resolve())], ["input SHA-256", book.sha256],
            ["case", book.case.name], ["runs", ", ".join(run.spec.name for run in runs)],
            ["date", datetime.datetime.now().astimezone().isoformat(timespec="seconds")],
            ["python", platform.python_version()], ["platform", platform.platform()]]
    rows += [[f"version {name}", version(name)] for name in PACKAGES]
    _rows(ws, ["item", "value"], rows)
    ws.column_dimensions["A"].width, ws.column_dimensions["B"].width = 28, 80


def is_report(path: Path) -> bool:
    """True if the file at *path* is a report workbook this module wrote (its keywords say so)."""
    try:
        with zipfile.ZipFile(path) as archive:
            core = archive.read("docProps/core.xml")
    except (OSError, KeyError, zipfile.BadZipFile):
        return False
    return f"<cp:keywords>{REPORT_KEYWORDS}</cp:keywords>".encode() in core


def write_report(path: Union[str, Path], book: CaseBook, runs: list[RunResult]) -> WriteOutcome:
    """Write the report workbook of *runs* to *path* (atomically), or beside it.

    An existing *path* is replaced only if it is a report this module wrote
    and not open in Excel or LibreOffice; otherwise (the case workbook
    itself, any other file) the report goes to a new name beside it.

    Returns
    -------
    WriteOutcome
    """
    target, reason = new_file_target(path, "report", is_report)
    workbook = Workbook()
    workbook.properties.creator, workbook.properties.keywords = "mountwb", REPORT_KEYWORDS
    workbook.active.title = "Summary"
    _summary(workbook.active, book.case.name, runs)
    if book.tests:
        _validation(workbook.create_sheet("Validation"), runs, book.tests)
    _transmissibility(workbook.create_sheet("Transmissibility"), runs)
    _plots(workbook.create_sheet("Plots"), runs)
    cards = workbook.create_sheet("Model card")
    for row, line in enumerate(card_lines(runs), start=1):
        cards.cell(row, 1, line).font = Font(name="Consolas", bold=line.startswith("Run '"))
    _metadata(workbook.create_sheet("Metadata"), book, runs)
    return WriteOutcome(save_atomic(workbook, target), reason)
