"""Case workbooks: a user's work is never misread, lost or overwritten.

Every test builds real .xlsx files (openpyxl, or by editing the zip parts as
Excel and LibreOffice write them) and runs the real commands on them.
"""
from __future__ import annotations

import shutil

import pytest
from excel_helpers import copy_reference, make_cheap
from openpyxl import load_workbook

from workbook.cli.main import main


@pytest.fixture(scope="module")
def cheap_ran(tmp_path_factory, cache_dir):
    """A cheap copy of the reference workbook after one run of 'LP rotor'."""
    path = copy_reference(tmp_path_factory.mktemp("safety"), "ran.xlsx")
    make_cheap(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    return path


def _copy(source, folder, name="case.xlsx"):
    target = folder / name
    shutil.copyfile(source, target)
    return target


@pytest.mark.slow
def test_copied_and_renamed_result_sheets_are_the_users(cheap_ran, tmp_path):
    path = _copy(cheap_ran, tmp_path)
    wb = load_workbook(path)
    copy = wb.copy_worksheet(wb["Result efficiency"])
    copy.title = "Result efficiency (2)"
    copy["A1"] = "kept for the design review"
    wb["Result hinges"].title = "Result LP baseline"
    wb.save(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    wb = load_workbook(path)
    assert {"Result efficiency (2)", "Result LP baseline", "Result efficiency", "Result hinges"} <= set(wb.sheetnames)
    assert wb["Result efficiency (2)"]["A1"].value == "kept for the design review"
    assert wb["Result LP baseline"].max_row == wb["Result hinges"].max_row
    assert sum(n == "Result efficiency" for n in wb.sheetnames) == 1
