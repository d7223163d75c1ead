"""Outputs never replace or lose a user's work: the case workbook as a user saves it, other runs' results,
files changed or protected meanwhile, and every output path a command is given.

The user's files are saved by LibreOffice headless (open and save as .xlsx), as
a user's Excel or LibreOffice writes them (shared strings, its own document
properties); those tests are skipped, with the reason, when ``soffice`` is not
on PATH.
"""
from __future__ import annotations

import pytest
from excel_helpers import SOFFICE, copy_reference, make_cheap, save_in_libreoffice, sha256
from openpyxl import load_workbook
from openpyxl.chart import BarChart, Reference

from workbook.cli.main import main

needs_libreoffice = pytest.mark.skipif(SOFFICE is None, reason="LibreOffice (soffice) is not on PATH: "
                                                                "apt-get install libreoffice-calc-nogui")


@pytest.fixture
def folder(tmp_path):
    """A folder of its own for the user's files (LibreOffice's profile stays outside it)."""
    path = tmp_path / "work"
    path.mkdir()
    return path


def _cheap_case(folder, name="case.xlsx"):
    path = copy_reference(folder, name)
    make_cheap(path)
    return path


def _names(folder):
    return sorted(p.name for p in folder.iterdir())


def _result_runs(path, sheet="Result efficiency"):
    return {row[0] for row in load_workbook(path)[sheet].iter_rows(min_row=3, values_only=True)}


@needs_libreoffice
def test_a_workbook_saved_by_libreoffice_gets_its_results_written_into_it(folder, tmp_path, capsys):
    """Saved by LibreOffice (shared strings, an empty custom-properties part), run, saved again, run again."""
    path = save_in_libreoffice(_cheap_case(folder), tmp_path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    assert f"results written to {path}" in capsys.readouterr().out
    assert _names(folder) == ["case.xlsx"] and _result_runs(path) == {"LP rotor"}
    save_in_libreoffice(path, tmp_path)
    assert main(["run", str(path), "--no-progress", "--run", "HP rotor"]) == 0
    assert f"results written to {path}" in capsys.readouterr().out
    assert _names(folder) == ["case.xlsx"] and "HP rotor" in _result_runs(path)


@needs_libreoffice
def test_a_chart_the_user_made_still_keeps_the_workbook_from_being_rewritten(folder, tmp_path, capsys):
    path = _cheap_case(folder)
    wb = load_workbook(path)
    chart = BarChart()
    chart.add_data(Reference(wb["Links"], min_col=3, min_row=3, max_row=6))
    wb["Links"].add_chart(chart, "H2")
    wb.save(path)
    save_in_libreoffice(path, tmp_path)
    digest = sha256(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    assert "content this program cannot keep (charts" in capsys.readouterr().out
    assert sha256(path) == digest and len(_names(folder)) == 2


def _rows(path, sheet):
    return list(load_workbook(path)[sheet].iter_rows(min_row=3, values_only=True))


@needs_libreoffice
def test_a_run_of_one_row_keeps_the_results_of_the_other_runs(folder, tmp_path):
    """HP rotor and the sweep, saved by LibreOffice, then LP rotor alone: the others' rows and cards stay."""
    path = copy_reference(folder)
    make_cheap(path, sweep_points=2)
    assert main(["run", str(path), "--no-progress", "--run", "HP rotor", "--run", "sweep"]) == 0
    save_in_libreoffice(path, tmp_path)
    before = {sheet: _rows(path, sheet) for sheet in ("Result efficiency", "Result hinges", "Result sweep")}
    note = load_workbook(path)["Result sweep"]["A1"].value
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    assert _names(folder) == ["case.xlsx"]
    wb = load_workbook(path)
    assert wb["Result sweep"]["A1"].value == note and _rows(path, "Result sweep") == before["Result sweep"]
    for sheet in ("Result efficiency", "Result hinges"):
        rows = _rows(path, sheet)
        assert [row for row in rows if row[0] != "LP rotor"] == before[sheet]
        assert {row[0] for row in rows} == {"LP rotor", "HP rotor", "sweep"}
    assert "the results of 'HP rotor', 'sweep' are from an earlier run" in wb["Result efficiency"]["A1"].value
    card = [cell.value for cell in wb["Result model card"]["A"]]
    assert [line for line in card if str(line).startswith("Run '")] == ["Run 'HP rotor'", "Run 'sweep'",
                                                                         "Run 'LP rotor'"]
