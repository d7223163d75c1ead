"""Runs of a case workbook: results written back safely, the report workbook.

Runs use the workbook's own settings sheet for short runs on coarse rigid
links (see ``excel_helpers.make_cheap``).
"""
from __future__ import annotations

import dataclasses
import shutil
import zipfile

import numpy as np
import pytest
from excel_helpers import CHEAP_SETTINGS, column_of, copy_reference, give_cached_value, make_cheap, set_cells, sha256
from openpyxl import Workbook, load_workbook
from openpyxl.chart import BarChart, Reference
from openpyxl.comments import Comment
from openpyxl.styles import Font, PatternFill

from workbook.cli.main import main
from workbook.excel import layout as L
from workbook.excel.files import save_atomic, unsupported_content
from workbook.excel.writer import MARKER, MARKER_CELL
from workbook.model.case import AnalysisSettings, ForceTransducers
from workbook.model.reference import HP_ROTOR, LP_ROTOR, reference_case, reference_sweep
from workbook.solve.pipeline import run_case

INPUT_SHEETS = [L.INSTRUCTIONS_SHEET] + [table.sheet for table in L.TABLES]
#: Measured amplitudes of the test-data rows added below, N.
TEST_LP_Y, TEST_HINGE_Z = 2.0, 40.0


def _decorate(path):
    """User formatting, a comment, a note column, a formula and test data: all must survive a run."""
    wb = load_workbook(path)
    hinges = wb["Hinges"]
    hinges["A3"].font = Font(bold=True, color="FF0000")
    hinges["A4"].fill = PatternFill("solid", fgColor="FFFF00")
    hinges["G3"].number_format = "0.00E+00"
    hinges["A5"].comment = Comment("checked by J. Doe", "J. Doe")
    hinges.cell(1, 20, "# note")
    hinges.cell(3, 20, "bearing from supplier X")
    tests = wb["Test data"]
    for row, values in enumerate((("LP rotor", None, "y", TEST_LP_Y), ("LP rotor", "front-up-left", "z", TEST_HINGE_Z)),
                                 start=3):
        for header, value in zip(("run", "location", "direction", "amplitude"), values, strict=True):
            tests.cell(row, column_of(tests, header)).value = value
    wb.save(path)


def _snapshot(path):
    """Every input cell's value and style, the drop-downs, widths and panes of the input sheets."""
    wb = load_workbook(path)
    shot = {}
    for name in INPUT_SHEETS:
        ws = wb[name]
        cells = {c.coordinate: (c.value, *map(repr, (c.font, c.fill, c.border, c.alignment, c.protection)),
                                c.number_format, None if c.comment is None else c.comment.text)
                 for row in ws.iter_rows() for c in row}
        shot[name] = (cells, sorted(str(dv.sqref) + str(dv.formula1) for dv in ws.data_validations.dataValidation),
                      {k: d.width for k, d in ws.column_dimensions.items()}, ws.freeze_panes)
    return shot


@pytest.fixture(scope="module")
def cheap(tmp_path_factory, cache_dir):
    """A cheap copy of the reference workbook with test data (not run)."""
    path = copy_reference(tmp_path_factory.mktemp("cheap"), "cheap.xlsx")
    make_cheap(path)
    _decorate(path)
    return path


@pytest.fixture(scope="module")
def ran(cheap, tmp_path_factory):
    """The cheap workbook after ``mountwb run --report``."""
    folder = tmp_path_factory.mktemp("ran")
    path = folder / "case.xlsx"
    shutil.copyfile(cheap, path)
    before, digest = _snapshot(path), sha256(path)
    report = folder / "report.xlsx"
    assert main(["run", str(path), "--no-progress", "--report", str(report)]) == 0
    return path, before, digest, report


def _cheap_python_case():
    """The case of the cheap workbook built in Python: reference mount, rigid links, cheap settings."""
    analysis = AnalysisSettings(**{k.replace(" ", "_"): v for k, v in CHEAP_SETTINGS.items()})
    return reference_case(analysis=analysis, element_size=0.030).with_rigid_links()


def _sheet_rows(ws, header_row=2):
    header = [c.value for c in ws[header_row]]
    return [dict(zip(header, values, strict=True)) for values in ws.iter_rows(min_row=header_row + 1, values_only=True)
            if any(v is not None for v in values)]


@pytest.mark.slow
def test_input_sheets_are_unchanged(ran):
    path, before, _, _ = ran
    assert _snapshot(path) == before


@pytest.mark.slow
def test_results_written_back_match_a_python_run(ran):
    path = ran[0]
    wb = load_workbook(path)
    assert [n for n in wb.sheetnames if n.startswith(L.RESULT_PREFIX)] == [
        "Result efficiency", "Result hinges", "Result sweep", "Result model card"]
    assert all(wb[n][MARKER_CELL].value.startswith(f"{MARKER}: {n} #") and wb[n].column_dimensions["Z"].hidden
               for n in wb.sheetnames if n.startswith(L.RESULT_PREFIX))
    rows = _sheet_rows(wb["Result efficiency"])
    assert len(rows) == 3 * (1 + 1 + 4)          # LP, HP, 4 sweep points x 3 directions
    # the same case built in Python (reference, rigid links, cheap settings) gives identical numbers
    python = run_case(dataclasses.replace(_cheap_python_case(), excitations=(LP_ROTOR, HP_ROTOR)))
    for run in python.runs:
        sheet = {r["direction"]: r for r in rows if r["run"] == run.name}
        for i, d in enumerate("xyz"):
            assert sheet[d]["T"] == pytest.approx(run.transmissibility[i], rel=1e-9)
            assert sheet[d]["eta %"] == pytest.approx(100 * (1 - run.transmissibility[i]), rel=1e-9)
            assert sheet[d]["dB"] == pytest.approx(20 * np.log10(run.transmissibility[i]), rel=1e-9)
    sweep = _sheet_rows(wb["Result sweep"])
    assert [r["frequency Hz"] for r in sweep] == pytest.approx(list(reference_sweep(4).frequencies_hz))
    # isolation at the rotor frequencies, amplification somewhere near the mounted modes at 5-20 Hz
    assert min(r["eta % y"] for r in sweep[:2]) < 0 < min(r["eta % y"] for r in sweep[2:])


def test_run_on_the_test_rig(tmp_path):
    """A Test rig row builds the transducers: the model card says so and T is the Python case's."""
    path = copy_reference(tmp_path)
    make_cheap(path)
    set_cells(path, {("Test rig", f"stiffness {axis}", 3): 1e8 for axis in "xyz"})
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    wb = load_workbook(path)
    card = [str(cell.value) for cell in wb["Result model card"]["A"]]
    assert any(line.startswith("  [on ] test-rig force-sensor compliance: 6 transducers, k = (1e+08, 1e+08, 1e+08)")
               for line in card)
    assert sum("force transducer (point mass)" in line for line in card) == 6
    case = dataclasses.replace(_cheap_python_case(), excitations=(LP_ROTOR,),
                               test_rig=ForceTransducers((1e8, 1e8, 1e8)))
    python = run_case(case).runs[0]
    sheet = {r["direction"]: r for r in _sheet_rows(wb["Result efficiency"])}
    assert [sheet[d]["T"] for d in "xyz"] == pytest.approx(list(python.transmissibility), rel=1e-9)


@pytest.mark.slow
def test_test_data_error(ran):
    wb = load_workbook(ran[0])
    lp_y = next(r for r in _sheet_rows(wb["Result efficiency"]) if r["run"] == "LP rotor" and r["direction"] == "y")
    assert lp_y["test amplitude N"] == TEST_LP_Y
    assert lp_y["error %"] == pytest.approx((lp_y["amplitude N"] - TEST_LP_Y) / TEST_LP_Y * 100, rel=1e-12)
    hinge = [r for r in _sheet_rows(wb["Result hinges"]) if r["test amplitude N"] is not None]
    assert [(r["run"], r["location"], r["direction"]) for r in hinge] == [("LP rotor", "front-up-left", "z")]
    assert hinge[0]["error %"] == pytest.approx((hinge[0]["amplitude N"] / TEST_HINGE_Z - 1) * 100, rel=1e-12)
    others = [r for r in _sheet_rows(wb["Result efficiency"]) if not (r["run"] == "LP rotor" and r["direction"] == "y")]
    assert all(r["error %"] is None for r in others)


@pytest.mark.slow
def test_report_workbook(ran):
    path, _, digest, report = ran
    wb = load_workbook(report)
    assert wb.sheetnames == ["Summary", "Validation", "Transmissibility", "Modes", "Warnings", "Plots", "Model card",
                             "Metadata"]
    validation = _sheet_rows(wb["Validation"], header_row=3)   # the pylon-sum test point only
    assert [(r["run"], r["direction"]) for r in validation] == [("LP rotor", "y")]
    lp_y = validation[0]
    assert lp_y["T test (-)"] == pytest.approx(TEST_LP_Y / 1000.0, rel=1e-12)
    assert lp_y["error (%)"] == pytest.approx((lp_y["T sim (-)"] - lp_y["T test (-)"]) / lp_y["T test (-)"] * 100,
                                              rel=1e-9)
    assert lp_y["level test (dB)"] == pytest.approx(20 * np.log10(lp_y["T test (-)"]), rel=1e-12)
    assert len(wb["Summary"]._charts) == 1 and len(wb["Transmissibility"]._charts) == 1
    assert len(wb["Modes"]._charts) == 1
    chart = wb["Transmissibility"]._charts[0]
    assert len(chart.series) == 6 and chart.x_axis.delete is False      # sweep and single runs, x y z each
    assert len(wb["Plots"]._images) == 3
    summary = _sheet_rows(wb["Summary"], header_row=4)[:2]
    efficiency = {(r["run"], r["direction"]): r for r in _sheet_rows(load_workbook(path)["Result efficiency"])}
    assert [r["run"] for r in summary] == ["LP rotor", "HP rotor"]
    for row in summary:
        for d in "xyz":
            answer = efficiency[(row["run"], d)]
            assert [row[f"eta (%) {d}"], row[f"T (-) {d}"], row[f"level (dB) {d}"]] == pytest.approx(
                [answer["eta %"], answer["T"], answer["dB"]], rel=1e-12)
    modes = _sheet_rows(wb["Modes"], header_row=3)
    card = [str(c.value) for c in load_workbook(path)["Result model card"]["A"]]
    lp_modes = [r["frequency (Hz)"] for r in modes if r["run"] == "LP rotor"]
    assert lp_modes and all(f"{f:7.2f} Hz" in "\n".join(card) for f in lp_modes)
    meta = {r["item"]: r["value"] for r in _sheet_rows(wb["Metadata"], header_row=3)}
    assert meta["input SHA-256 as read"] == digest
    assert meta["case workbook with the results: SHA-256"] == sha256(path)
    assert meta["version openpyxl"] and meta["version exudyn"] != "not installed"
    assert any(str(c.value).startswith("Model card: reference mount / LP rotor") for c in wb["Model card"]["A"])


def test_rerun_replaces_our_sheets_and_keeps_formula_values(cheap, tmp_path, capsys):
    path = tmp_path / "case.xlsx"
    shutil.copyfile(cheap, path)
    set_cells(path, {("Engine", "mass", 3): "=3000+568"})
    give_cached_value(path, "xl/worksheets/sheet3.xml", "A3", 3568)
    for _ in range(2):
        assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    wb = load_workbook(path)
    assert [n for n in wb.sheetnames if n.startswith(L.RESULT_PREFIX)] == [
        "Result efficiency", "Result hinges", "Result model card"]
    assert {r["run"] for r in _sheet_rows(wb["Result efficiency"])} == {"LP rotor"}
    assert wb["Engine"]["A3"].value == "=3000+568"
    assert load_workbook(path, data_only=True)["Engine"]["A3"].value == 3568
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.xlsx"]      # no temporary files left


def _user_sheet(path):
    wb = load_workbook(path)
    wb.create_sheet("Result efficiency")["A1"] = "my own notes"
    wb.save(path)


def _chart(path):
    wb = load_workbook(path)
    ws = wb.create_sheet("My chart")
    for row in range(1, 4):
        ws.cell(row, 1, row)
    chart = BarChart()
    chart.add_data(Reference(ws, min_col=1, min_row=1, max_row=3))
    ws.add_chart(chart, "C1")
    wb.save(path)


def _lock(path):
    path.with_name("~$" + path.name).write_bytes(b"owner")


@pytest.mark.parametrize("prepare, reason", [
    (_user_sheet, "sheets named 'Result efficiency' that were not written by mountwb"),
    (_chart, "cannot keep (charts)"),
    (_lock, "open in Excel"),
])
def test_workbook_not_overwritten(cheap, tmp_path, capsys, prepare, reason):
    path = tmp_path / "case.xlsx"
    shutil.copyfile(cheap, path)
    prepare(path)
    digest = sha256(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    out = capsys.readouterr().out
    assert reason in out and "was not overwritten" in out
    assert sha256(path) == digest
    separate = [p for p in tmp_path.iterdir() if p.name.startswith("case-results-")]
    assert len(separate) == 1
    wb = load_workbook(separate[0])
    assert wb.sheetnames == ["Result efficiency", "Result hinges", "Result model card"]
    assert {r["run"] for r in _sheet_rows(wb["Result efficiency"])} == {"LP rotor"}


def _zip_with(path, extra: dict):
    with zipfile.ZipFile(path, "a") as archive:
        for name, data in extra.items():
            archive.writestr(name, data)


@pytest.mark.parametrize("extra, found", [
    ({"xl/vbaProject.bin": b"\0"}, "macros (VBA)"),
    ({"xl/pivotTables/pivotTable1.xml": b"<x/>"}, "pivot tables"),
    ({"xl/externalLinks/externalLink1.xml": b"<x/>"}, "external links"),
    ({"xl/media/image1.png": b"png"}, "images"),
    ({"xl/worksheets/sheet99.xml": b'<worksheet><extLst><ext><x14:dataValidations count="1">'
                                   b"</x14:dataValidations></ext></extLst></worksheet>"},
     "data-validation extensions (lists from other sheets)"),
])
def test_unsupported_content_is_detected(tmp_path, extra, found):
    path = copy_reference(tmp_path)
    assert unsupported_content(path) == []
    _zip_with(path, extra)
    assert unsupported_content(path) == [found]


def test_save_is_atomic(tmp_path):
    path = copy_reference(tmp_path)
    digest = sha256(path)

    class Failing(Workbook):
        def save(self, filename):
            super().save(filename)
            raise OSError("disk full")

    with pytest.raises(OSError):
        save_atomic(Failing(), path)
    assert sha256(path) == digest
    assert [p.name for p in tmp_path.iterdir()] == ["case.xlsx"]


def test_unknown_run_name_is_bad_input(cheap, capsys):
    digest = sha256(cheap)
    assert main(["run", str(cheap), "--no-progress", "--run", "IP rotor"]) == 2
    assert "'IP rotor'" in capsys.readouterr().err
    assert sha256(cheap) == digest


@pytest.mark.parametrize("option", [["--time-budget", "0"], ["--time-budget", "-5"], ["--rigid"]])
def test_an_option_of_json_cases_is_refused_for_a_workbook(cheap, capsys, option):
    digest = sha256(cheap)
    assert main(["run", str(cheap), "--no-progress", "--run", "LP rotor", *option]) == 2
    assert "--json, --rigid, --method and --time-budget are for JSON cases" in capsys.readouterr().err
    assert sha256(cheap) == digest


def test_report_never_replaces_the_case(cheap, tmp_path, capsys):
    path = tmp_path / "case.xlsx"
    shutil.copyfile(cheap, path)
    digest = sha256(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor", "--report", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"--report {path}: that is an input of this command" in err
    assert sha256(path) == digest and sorted(p.name for p in tmp_path.iterdir()) == ["case.xlsx"]


def test_a_report_of_frequency_domain_runs_plots_their_answers(tmp_path):
    """The default method answers the reference rows in the frequency domain:
    no force histories, so the report plots the efficiency instead of them."""
    path = copy_reference(tmp_path)
    make_cheap(path)
    set_cells(path, {("Case", "method", 3): "auto"})
    report = tmp_path / "report.xlsx"
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor", "--report", str(report)]) == 0
    assert len(load_workbook(report)["Plots"]._images) == 1
