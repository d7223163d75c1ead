"""The Load cases sheet of a case workbook and the Result loads sheet a run writes.

A template filled by hand and saved by LibreOffice reads back into the load
cases typed; bad cells are refused at their cells with nothing written; the
written loads table holds the numbers of ``mountwb loads --json`` and the
nominal stresses of the Links sheet's shank sizes.
"""
from __future__ import annotations

import dataclasses
import json
import shutil

import pytest
from excel_helpers import SOFFICE, TEMPLATE, column_of, make_cheap, save_in_libreoffice, set_cells, sha256
from openpyxl import load_workbook

from workbook.cli.main import main
from workbook.errors import UnwritableCase
from workbook.excel.reader import read_workbook
from workbook.excel.template import case_workbook
from workbook.model.case import PointForce, PointMoment
from workbook.model.load_cases import LoadCase, reference_load_cases
from workbook.model.reference import reference_case

SHEET = "Load cases"
#: The first empty row of the template's Load cases sheet (its five reference load cases above).
NEW_ROW = 8


def _template(folder, name="case.xlsx"):
    target = folder / name
    shutil.copyfile(TEMPLATE, target)
    return target


@pytest.mark.skipif(SOFFICE is None, reason="LibreOffice (soffice) is not on PATH")
def test_a_template_filled_and_saved_by_libreoffice_reads_back_the_load_cases(tmp_path):
    path = _template(tmp_path)
    typed = {"name": "reverse thrust, 1.2 g", "thrust": -40, "load factor z": -1.2, "torque": -5,
             "force x": 1000, "force y": -2000, "force z": 500, "force point x": 0.5, "force point y": 0,
             "force point z": 0.3, "moment x": 0, "moment y": 1500, "moment z": 0, "factor of safety": 1.25, "fail-safe link": "front-left",
             "description": "typed by hand"}
    set_cells(path, {(SHEET, header, NEW_ROW): value for header, value in typed.items()}
              | {("Links", "yield strength", 3): 400, ("Links", "ultimate strength", 3): 520})
    save_in_libreoffice(path, tmp_path / "scratch")
    case = read_workbook(path).case
    expected = LoadCase("reverse thrust, 1.2 g", thrust=-40e3, load_factors=(0.0, 0.0, -1.2), torque=-5e3,
                        forces=(PointForce("force", (1000.0, -2000.0, 500.0), (0.5, 0.0, 0.3)),),
                        moments=(PointMoment("moment", (0.0, 1500.0, 0.0)),), factor_of_safety=1.25,
                        without_link="front-left", description="typed by hand")
    assert case.load_cases == (*reference_load_cases(), expected)
    material = case.links[0].model.material
    assert (material.yield_strength, material.ultimate_strength, material.endurance_strength) == (400e6, 520e6, 235e6)


BAD_CELLS = {
    "negative factor of safety": ({("factor of safety", 4): -1.5}, ["cell T4", "column 'factor of safety'",
                                                                     "found -1.5", "factor of safety >= 1"]),
    "unknown fail-safe link": ({("fail-safe link", 5): "rear-centre"}, ["cell U5", "found 'rear-centre'",
                                                                         "one of the case's links (front-left"]),
    "text in a number cell": ({("thrust", 3): "full"}, ["cell C3", "column 'thrust'", "found 'full'", "a number"]),
    "force without its point": ({("force z", 6): 10}, ["cell N6", "column 'force point x'", "found empty"]),
}


@pytest.mark.parametrize("name", list(BAD_CELLS))
def test_a_bad_load_case_cell_exits_2_naming_sheet_and_cell(tmp_path, capsys, name):
    edits, expected = BAD_CELLS[name]
    path = _template(tmp_path)
    set_cells(path, {(SHEET, header, row): value for (header, row), value in edits.items()})
    before, files = sha256(path), sorted(tmp_path.iterdir())
    assert main(["check", str(path)]) == 2
    assert main(["run", str(path), "--no-progress"]) == 2
    message = capsys.readouterr().err
    for text in ["case.xlsx", f"sheet '{SHEET}'", *expected]:
        assert text in message, f"{name}: {text!r} not in\n{message}"
    assert sha256(path) == before and sorted(tmp_path.iterdir()) == files


def test_a_load_case_with_two_extra_forces_is_not_written():
    force = PointForce("f", (1.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    case = dataclasses.replace(reference_case(), load_cases=(LoadCase("two", forces=(force, force)),))
    with pytest.raises(UnwritableCase, match="load case 'two': a Load cases row holds one extra force"):
        case_workbook(case, ())


def test_the_written_loads_sheet_holds_the_numbers_of_mountwb_loads(tmp_path, capsys):
    """Two load cases (take-off and its fail-safe variant) on coarse links: the Result loads sheet equals
    ``mountwb loads --json``, and each nominal stress is the axial force over the Links sheet's shank."""
    path = _template(tmp_path)
    make_cheap(path)
    wb = load_workbook(path)
    ws = wb[SHEET]
    for row in (3, 5, 6):                                       # keep 'take-off' and 'take-off, rear-middle failed'
        for col in range(1, ws.max_column + 1):
            ws.cell(row, col).value = None
    wb.save(path)
    assert main(["run", str(path), "--run", "LP rotor", "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["loads", str(path), "--json"]) == 0
    answers = {(lc["load_case"], link): stress for lc in json.loads(capsys.readouterr().out)["load_cases"]
               for link, stress in lc["links"].items()}
    book = load_workbook(path)
    sheet = book["Result loads"]
    header = [cell.value for cell in sheet[2]]
    rows = [dict(zip(header, values, strict=False)) for values in sheet.iter_rows(min_row=3, values_only=True)]
    assert len(rows) == len(answers) == 8 + 7
    links = book["Links"]
    shank = {links.cell(r, 1).value: links.cell(r, column_of(links, "shank width")).value
             * links.cell(r, column_of(links, "shank thickness")).value * 1e-6 for r in range(3, links.max_row + 1)}
    assert links.cell(2, column_of(links, "shank width")).value == "mm"
    for row in rows:
        answer = answers[(row["load case"], row["link"])]
        assert row["axial force N"] == pytest.approx(answer["axial_force"], rel=1e-9)
        for column, key in (("nominal stress MPa", "nominal_stress"), ("von Mises MPa", "von_mises"),
                            ("max principal MPa", "max_principal")):
            assert row[column] == pytest.approx(answer[key] / 1e6, rel=1e-9)
        assert (row["MS yield"], row["MS ultimate"]) == pytest.approx((answer["yield_margin"],
                                                                       answer["ultimate_margin"]), rel=1e-9)
        assert row["von Mises at"] == answer["von_mises_region"]
        assert row["nominal stress MPa"] == pytest.approx(row["axial force N"] / shank[row["link"]] / 1e6, rel=1e-12)
        assert row["link removed"] == (None if row["load case"] == "take-off" else "rear-middle")
    assert "rear-middle" not in {row["link"] for row in rows if row["link removed"]}
