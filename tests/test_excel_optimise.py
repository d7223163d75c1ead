"""The Optimise sheet of a case workbook: read into the problem, bad cells named, run by mountwb optimise."""
from __future__ import annotations

import json

import pytest
from excel_helpers import REFERENCE, TEMPLATE, column_of, copy_reference
from openpyxl import load_workbook

import workbook.excel.layout as L
from workbook.cli.main import main
from workbook.design.optimise import Constraint
from workbook.errors import WorkbookError
from workbook.excel.reader import read_workbook


def _with_sheet(path, rows, links_element_size=None):
    """The workbook at *path* with an Optimise sheet of *rows* (dicts by header), SI units, in place of its
    own; with *links_element_size* (mm) its links meshed so, and the reference sweep removed (the rotors only)."""
    book = load_workbook(path)
    if L.OPTIMISE.sheet in book.sheetnames:
        del book[L.OPTIMISE.sheet]
    ws = book.create_sheet(L.OPTIMISE.sheet)
    for col, column in enumerate(L.OPTIMISE.columns, start=1):
        ws.cell(L.HEADER_ROW, col, column.header)
        ws.cell(L.UNIT_ROW, col, "-" if column.kind == "number" else None)
        for row, values in enumerate(rows, start=L.FIRST_DATA_ROW):
            ws.cell(row, col, values.get(column.header))
    if links_element_size is not None:
        links = book["Links"]
        for row in range(L.FIRST_DATA_ROW, links.max_row + 1):
            links.cell(row, column_of(links, "element size"), links_element_size)
        for sheet, header in (("Excitations", "name"), ("Runs", "run")):
            ws = book[sheet]
            rows_named = [r for r in range(L.FIRST_DATA_ROW, ws.max_row + 1)
                          if ws.cell(r, column_of(ws, header)).value == "sweep"]
            for r in reversed(rows_named):
                ws.delete_rows(r)
    book.save(path)
    return path


ROWS = [{"kind": "variable", "name": "hinge_stiffness/front", "low": 5e6, "high": 2e8},
        {"kind": "variable", "name": "hinge_loss_factor/all", "low": 0.01, "high": 0.2},
        {"kind": "constraint", "name": "displacement", "value": 0.002},
        {"kind": "constraint", "name": "fatigue", "value": 2},
        {"kind": "constraint", "name": "margin", "value": 0},
        {"kind": "constraint", "name": "modes_outside", "low": 50, "high": 70},
        {"kind": "band", "name": "LP rotor", "low": 40, "high": 62},
        {"kind": "objective", "name": "weighted"}, {"kind": "starts", "value": 2}]


def test_the_sheet_reads_into_the_problem(tmp_path):
    sheet = read_workbook(_with_sheet(copy_reference(tmp_path), ROWS)).optimise
    assert sheet.variables == {"hinge_stiffness/front": (5e6, 2e8), "hinge_loss_factor/all": (0.01, 0.2)}
    assert sheet.constraints == (Constraint("displacement", 0.002), Constraint("fatigue", 2.0),
                                 Constraint("margin", 0.0), Constraint("modes_outside", (50.0, 70.0)))
    assert sheet.bands == {"LP rotor": (40.0, 62.0)}
    assert (sheet.objective, sheet.starts) == ("weighted", 2)
    section = [{"kind": "variable", "name": "section_scale", "low": 0.9, "high": 1.1}]
    assert read_workbook(_with_sheet(copy_reference(tmp_path, "section.xlsx"), section)).optimise.variables == \
        {"section_scale": (0.9, 1.1)}


def test_a_written_problem_reads_back_to_itself(tmp_path):
    """Every kind of row (a band and a modes_outside range included) written by case_workbook, saved and read
    again: the same problem, in the template's columns and units."""
    from workbook.excel.files import save_atomic
    from workbook.excel.template import case_workbook

    book = read_workbook(_with_sheet(copy_reference(tmp_path), ROWS))
    assert book.optimise is not None and book.optimise.bands and book.optimise.starts == 2
    written = save_atomic(case_workbook(book.case, book.runs, optimise=book.optimise), tmp_path / "written.xlsx")
    again = read_workbook(written)
    assert again.optimise == book.optimise and again.case == book.case
    ws = load_workbook(written)[L.OPTIMISE.sheet]
    assert [ws.cell(L.UNIT_ROW, col).value for col in range(3, 6)] == ["-"] * 3
    assert [ws.cell(row, 1).value for row in range(L.FIRST_DATA_ROW, ws.max_row + 1)] == [row["kind"] for row in ROWS]


def test_the_generated_workbooks_have_an_empty_optimise_sheet_and_older_ones_without_it_still_load(tmp_path):
    """The template's and the reference workbook's Optimise sheet: headers, units, no row (a run never
    optimises), an Instructions entry; a workbook written before the sheet existed reads to the same case."""
    for path in (TEMPLATE, REFERENCE):
        book = load_workbook(path)
        ws = book[L.OPTIMISE.sheet]
        assert [ws.cell(L.HEADER_ROW, col).value for col in range(1, 6)] == ["kind", "name", "low", "high", "value"]
        assert [ws.cell(L.UNIT_ROW, col).value for col in range(3, 6)] == ["-"] * 3
        assert ws.max_row == L.UNIT_ROW
        assert any(str(row[0]).startswith("Optimise (optional") for row in book["Instructions"].values)
        assert read_workbook(path).optimise is None
    old = copy_reference(tmp_path, "old.xlsx")
    book = load_workbook(old)
    del book[L.OPTIMISE.sheet]
    book.save(old)
    read_old, read_new = read_workbook(old), read_workbook(REFERENCE)
    assert read_old.optimise is None and read_old.case == read_new.case and read_old.runs == read_new.runs


@pytest.mark.parametrize("row, words", [
    ({"kind": "variable", "name": "hinge_stifness/front", "low": 1e6, "high": 1e8}, ["cell B3", "hinge_stifness"]),
    ({"kind": "variable", "name": "hinge_stiffness/front", "low": 1e8, "high": 1e6}, ["cell C3:D3", "LOW < HIGH"]),
    ({"kind": "variable", "name": "clearance", "low": 0, "high": 1e-4}, ["cell B3", "new preparation"]),
    ({"kind": "variable", "name": "section_scale", "low": 0, "high": 1.2}, ["cell C3:D3", "section > 0"]),
    ({"kind": "constraint", "name": "weight", "value": 3}, ["B3:E3", "fatigue>=FACTOR"]),
    ({"kind": "band", "name": "fan", "low": 40, "high": 62}, ["cell B3", "LP rotor, HP rotor"]),
    ({"kind": "band", "name": "LP rotor", "low": 62, "high": 40}, ["cell C3:D3", "0 < LOW < HIGH"]),
    ({"kind": "starts", "value": 1.5}, ["cell E3", "whole number"]),
])
def test_a_bad_cell_is_named(tmp_path, row, words):
    with pytest.raises(WorkbookError) as error:
        read_workbook(_with_sheet(copy_reference(tmp_path), [row]))
    text = str(error.value)
    assert "Optimise" in text
    for word in words:
        assert word in text


def test_optimise_without_vary_needs_the_sheet(tmp_path, capsys):
    assert main(["optimise", str(copy_reference(tmp_path))]) == 2
    assert "Optimise sheet lists no variable" in capsys.readouterr().err
    assert main(["optimise"]) == 2


@pytest.mark.slow
def test_mountwb_optimise_runs_the_sheets_problem(tmp_path, cache_dir, capsys):
    """One variable and a displacement limit from the sheet (coarse links, the two rotors): the optimum meets
    the limit."""
    rows = [{"kind": "variable", "name": "hinge_loss_factor/all", "low": 0.01, "high": 0.2},
            {"kind": "constraint", "name": "displacement", "value": 0.003}, {"kind": "starts", "value": 1}]
    path = _with_sheet(copy_reference(tmp_path), rows, links_element_size=30)
    assert main(["optimise", str(path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert list(report["values"]) == ["hinge_loss_factor/all"] and len(report["starts"]) == 1
    displacement = [row for row in report["table"] if row["kind"] == "constraint"]
    assert displacement and all(row["after"] <= 0.003 for row in displacement)
