"""The case workbook and the report as a spreadsheet application shows and prints them.

LibreOffice Calc converts the written workbooks headless: to PDF (pages),
to OpenDocument (the native charts it found) and to CSV (the values it
reads, raw and as shown). The tests run when ``soffice`` is on PATH
(``.ci/run`` installs it) and are skipped, with the reason, otherwise.
"""
from __future__ import annotations

import csv
import math
import re
import zipfile

import pytest
from excel_helpers import SOFFICE, copy_reference, make_cheap, sha256, soffice_convert
from openpyxl import load_workbook

from workbook.cli.main import main
from workbook.excel.styling import FORMATS

pytestmark = [pytest.mark.skipif(SOFFICE is None, reason="LibreOffice (soffice) is not on PATH: "
                                                          "apt-get install libreoffice-calc-nogui"),
              pytest.mark.slow]
#: Points of the reference sweep (cases/reference.xlsx).
REFERENCE_SWEEP_POINTS = 25
#: Printed pages the whole reference report may take: 17 on cheap settings, of which its three model
#: cards, wrapped readably, take 8 and the warnings of its rigid links 3.
MAX_REPORT_PAGES = 18
#: The smallest printed text allowed anywhere, pt.
MIN_FONT_PT = 6.0
_CSV = "Text - txt - csv (StarCalc):44,34,76,1,,0,false,true,{shown},false,false{sheets}"


def _pages(pdf) -> int:
    return len(re.findall(rb"/Type\s*/Page\b(?!s)", pdf.read_bytes()))


def _csv(path):
    with open(path, newline="", encoding="utf-8") as stream:
        return list(csv.reader(stream))


@pytest.fixture(scope="module")
def reference_run(tmp_path_factory):
    """The reference workbook (its 3 runs, the 25-point sweep) on cheap settings, run with a report,
    then converted by LibreOffice."""
    folder = tmp_path_factory.mktemp("libreoffice")
    case = copy_reference(folder)
    make_cheap(case, sweep_points=REFERENCE_SWEEP_POINTS)
    report = folder / "report.xlsx"
    assert main(["run", str(case), "--no-progress", "--report", str(report)]) == 0
    out = folder / "converted"
    soffice_convert(folder, "pdf", case, report, outdir=out)
    soffice_convert(folder, "ods", report, outdir=out)
    soffice_convert(folder, "csv:" + _CSV.format(shown="false", sheets=",-1"), case, report, outdir=out / "raw")
    soffice_convert(folder, "csv:" + _CSV.format(shown="true", sheets=",-1"), report, outdir=out / "shown")
    return case, report, out


def _smallest_fonts(pdf) -> list[float]:
    """The smallest printed text size of each page, pt (text size x text matrix x page transform)."""
    from pypdf import PdfReader

    smallest = []
    for page in PdfReader(pdf).pages:
        sizes = []

        def visit(text, cm, tm, font, size, sizes=sizes):
            if text.strip():
                sizes.append(size * math.hypot(tm[0], tm[1]) * math.hypot(cm[0], cm[1]))

        page.extract_text(visitor_text=visit)
        smallest.append(min(sizes, default=math.inf))
    return smallest


def test_every_printed_page_is_readable(reference_run):
    """No text on any page of the report or the case workbook is smaller than MIN_FONT_PT (the model card,
    long lines fitted to the page width, printed at 1.2 pt)."""
    _, _, out = reference_run
    _assert_readable(out / "report.pdf")


def _assert_readable(pdf) -> None:
    smallest = _smallest_fonts(pdf)
    small = {page: round(size, 1) for page, size in enumerate(smallest, start=1) if size < MIN_FONT_PT}
    assert not small, f"{pdf.name}: pages with text below {MIN_FONT_PT} pt: {small}"


def test_the_four_pole_and_study_workbooks_print_readably(tmp_path):
    """The four-pole workbook (60 frequencies: its table continues over pages) and a parameter study's
    sheet, each converted to PDF: readable text, units in the headings, numbers formatted."""
    import dataclasses

    from workbook.model.codec import to_json
    from workbook.model.reference import LP_ROTOR, reference_case
    from workbook.studies.parallel import run_rows
    from workbook.studies.parametric import grid, study_cases
    from workbook.studies.sensitivity import study_frame, table_path, write_study

    case = tmp_path / "case.json"
    rigid = dataclasses.replace(reference_case().with_rigid_links(), excitations=(LP_ROTOR,))
    case.write_text(to_json(rigid))
    pole = tmp_path / "four-pole.xlsx"
    assert main(["four-pole", str(case), "--points", "60", "--xlsx", str(pole)]) == 0
    rows = grid({"hinge_stiffness": [2e7, 4e7]})
    frame = study_frame(rows, run_rows(study_cases(rigid, rows)))
    (tmp_path / "study").mkdir()
    sheet = next(p for p in write_study(frame, ["hinge_stiffness"], table_path(tmp_path / "study")) if p.suffix == ".xlsx")
    out = tmp_path / "pdf"
    soffice_convert(tmp_path, "pdf", pole, sheet, outdir=out)
    _assert_readable(out / "four-pole.pdf")
    _assert_readable(out / "parameter-study.pdf")
    assert _pages(out / "four-pole.pdf") >= 3                      # the chart, then the table over pages
    ws = load_workbook(pole)["Four-pole"]
    assert ws.print_title_rows == "$29:$30" and ws.cell(31, 2).number_format == FORMATS["N/m"]
    study = load_workbook(sheet)["Parameter study"]
    header = [c.value for c in study[1]]
    assert "hinge stiffness N/m" in header and study.print_title_rows == "$1:$1"
    assert study.cell(2, header.index("T x") + 1).number_format == FORMATS["T"]


def _rgb(fill) -> str:
    """The RGB text of a colour fill as openpyxl reads it back."""
    colour = fill.srgbClr
    return colour if isinstance(colour, str) else colour.val


def test_the_charts_show_every_answer(reference_run):
    """Straight lines between the points, one colour per direction, filled markers for the single runs;
    a table below a chart starts a page and repeats its caption and header on every page."""
    _, report, _ = reference_run
    ws = load_workbook(report)["Transmissibility"]
    chart = ws._charts[0]
    assert chart.scatterStyle == "lineMarker"
    colours = {"x": "1F77B4", "y": "FF7F0E", "z": "2CA02C"}
    for series in chart.series:
        title = series.tx.strRef.f if series.tx.strRef is not None else series.tx.v
        direction = title[-1]
        assert series.smooth is False or series.smooth is None
        if title.startswith("single-frequency runs"):
            assert series.marker.symbol == "circle"
            assert _rgb(series.marker.graphicalProperties.solidFill) == colours[direction]
        else:
            assert _rgb(series.graphicalProperties.line.solidFill) == colours[direction]
    assert ws.print_title_rows == "$29:$30" and [b.id for b in ws.row_breaks.brk] == [28]
    assert ws.cell(30, 1).value == "frequency (Hz)"


def test_the_reference_report_prints_on_at_most_max_pages(reference_run):
    _, _, out = reference_run
    assert 6 <= _pages(out / "report.pdf") <= MAX_REPORT_PAGES


def test_the_case_workbook_prints_one_page_wide(reference_run):
    """Every sheet one page wide: the pages are those of the rows (about 40 rows a page), not of the columns."""
    case, _, out = reference_run
    wb = load_workbook(case)
    rows = sum(ws.max_row for ws in wb.worksheets)
    assert _pages(out / "case.pdf") <= rows / 30 + len(wb.worksheets)
    for ws in wb.worksheets:
        assert ws.page_setup.orientation == "landscape" and ws.page_setup.fitToWidth == 1, ws.title
        assert ws.sheet_properties.pageSetUpPr.fitToPage, ws.title


def test_libreoffice_finds_the_native_charts(reference_run):
    _, _, out = reference_run
    with zipfile.ZipFile(out / "report.ods") as archive:
        objects = sorted({name.split("/")[0] for name in archive.namelist()
                          if re.match(r"Object \d+/content\.xml$", name)})
        charts = {}
        for name in objects:
            xml = archive.read(f"{name}/content.xml").decode()
            title = re.search(r"<chart:title\b.*?<text:p>(.*?)</text:p>", xml, re.S).group(1)
            charts[title] = (re.search(r'chart:class="chart:(\w+)"', xml).group(1), xml.count("<chart:series"))
    assert charts["Pylon transmissibility"] == ("scatter", 6)        # the sweep and the single runs, x y z
    assert charts["Pylon isolation efficiency"] == ("bar", 3)
    assert charts["Mounted modes (LP rotor)"] == ("bar", 1)


def test_values_read_back_equal_the_answers(reference_run):
    """The report's numbers, as LibreOffice reads them, are the answers written into the case workbook."""
    case, _, out = reference_run
    answers = {}
    for row in _csv(out / "raw" / "case-Result efficiency.csv")[2:]:
        answers[(row[0], row[1], row[3])] = [float(v) for v in row[5:8]]      # run, point, direction: T, eta %, dB
    values = load_workbook(case)["Result efficiency"]
    header = [c.value for c in values[2]]
    for row in values.iter_rows(min_row=3, values_only=True):
        record = dict(zip(header, row, strict=True))
        assert answers[(record["run"], record["point"], record["direction"])] == pytest.approx(
            [record["T"], record["eta %"], record["dB"]], rel=1e-12)
    summary = _csv(out / "raw" / "report-Summary.csv")
    head = summary.index(next(r for r in summary if r[:2] == ["run", "frequency (Hz)"]))
    for row in summary[head + 1:head + 3]:
        for i, d in enumerate("xyz"):
            t, eta, db = answers[(row[0], row[0], d)]
            assert [float(row[2 + i]), float(row[5 + i]), float(row[8 + i])] == pytest.approx([eta, t, db],
                                                                                             rel=1e-12)
    curve = _csv(out / "raw" / "report-Transmissibility.csv")
    sweep = [r for r in _csv(out / "raw" / "case-Result efficiency.csv")[2:] if r[0] == "sweep"]
    start = next(i for i, r in enumerate(curve) if r[:1] == ["sweep"]) + 2
    rows = curve[start:start + REFERENCE_SWEEP_POINTS]
    assert len(rows) == REFERENCE_SWEEP_POINTS and len(sweep) == 3 * REFERENCE_SWEEP_POINTS
    for row in rows:
        points = [r for r in sweep if abs(float(r[2]) - float(row[0])) < 1e-9 * float(row[0])]
        assert {r[3]: float(r[5]) for r in points} == pytest.approx(
            {d: float(row[1 + i]) for i, d in enumerate("xyz")}, rel=1e-12)


def test_numbers_are_shown_by_their_quantity(reference_run):
    _, report, out = reference_run
    shown = _csv(out / "shown" / "report-Summary.csv")
    head = next(i for i, r in enumerate(shown) if r[:2] == ["run", "frequency (Hz)"])
    for row in shown[head + 1:head + 3]:
        assert re.fullmatch(r"\d+\.\d\d", row[1])                                   # Hz
        assert all(re.fullmatch(r"-?\d+\.\d\d %", v) for v in row[2:5])              # eta
        assert all(re.fullmatch(r"\d\.\d{4}|\d\.\d{3}E-\d\d", v) for v in row[5:8])  # T
        assert all(re.fullmatch(r"-?\d+\.\d", v) for v in row[8:11])                 # dB
    wb = load_workbook(report)
    for ws in wb.worksheets:
        assert ws.page_setup.orientation == "landscape" and ws.page_setup.fitToWidth == 1, ws.title
    summary = wb["Summary"]
    assert summary.page_setup.fitToHeight == 1                                     # the summary: one page
    header = [c.value for c in summary[4]]
    assert header[:3] == ["run", "frequency (Hz)", "eta (%) x"] and "level (dB) z" in header
    assert summary.cell(5, 3).number_format == FORMATS["eta"] and summary.cell(5, 9).number_format == FORMATS["dB"]
    for name in ("Transmissibility", "Modes", "Metadata", "Warnings"):
        assert wb[name].column_dimensions["A"].width >= 9


def test_provenance_matches_the_files_on_disk(reference_run):
    case, report, _ = reference_run
    ws = load_workbook(report)["Metadata"]
    items = {row[0]: row[1] for row in ws.iter_rows(min_row=4, values_only=True)}
    assert items["case workbook with the results"] == str(case.resolve())
    assert items["case workbook with the results: SHA-256"] == sha256(case)
    assert items["input SHA-256 as read"] != sha256(case)          # the file was read before the results went in


def test_warnings_are_recorded(tmp_path):
    """A run too short to settle warns; the warning is in the report's Warnings sheet."""
    case = copy_reference(tmp_path)
    make_cheap(case)
    wb = load_workbook(case)
    column = next(c.column for c in wb["Case"][1] if c.value == "steady tolerance")
    wb["Case"].cell(3, column, 1e-9)
    wb.save(case)
    report = tmp_path / "report.xlsx"
    assert main(["run", str(case), "--no-progress", "--run", "LP rotor", "--report", str(report)]) == 0
    rows = list(load_workbook(report)["Warnings"].iter_rows(min_row=4, values_only=True))
    assert rows and all(row[0] == "LP rotor" for row in rows)
    assert any(row[2].startswith("not steady") for row in rows)
