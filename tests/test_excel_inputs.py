"""Input cells read as the user sees them, in workbooks edited and saved by LibreOffice Calc."""
from __future__ import annotations

import pytest
from excel_helpers import column_of, copy_reference, saved_by_libreoffice, sha256
from openpyxl import load_workbook

from workbook.cli.main import main
from workbook.excel.reader import read_workbook


def _edit(path, change) -> None:
    wb = load_workbook(path)
    change(wb)
    wb.save(path)


def _type_percent(ws, header: str, row: int, shown: float) -> None:
    """What typing '<shown> %' into a cell does: the cell holds shown / 100 with a percent number format."""
    cell = ws.cell(row, column_of(ws, header), shown / 100)
    cell.number_format = "0%"


def _refused(path, capsys, *texts) -> str:
    """``check`` and ``run`` refuse *path* naming *texts*, changing no file; the message."""
    before, files = sha256(path), sorted(path.parent.iterdir())
    assert main(["check", str(path)]) == 2
    message = capsys.readouterr().err
    for text in texts:
        assert text in message, f"{text!r} not in\n{message}"
    assert main(["run", str(path), "--no-progress"]) == 2
    assert sha256(path) == before and sorted(path.parent.iterdir()) == files
    return message


# -- percentages --------------------------------------------------------------------------------------------


def test_a_cell_showing_5_percent_is_5_percent_in_a_percent_or_plain_column(tmp_path):
    """Link modal damping with the unit cell '%' and hinge loss factor with '-': a cell typed '5 %' is 0.05 in
    both; a plain 5 under '%' stays 0.05."""
    path = copy_reference(tmp_path)

    def change(wb):
        links = wb["Links"]
        links.cell(2, column_of(links, "modal damping"), "%")
        _type_percent(links, "modal damping", 3, 5)
        links.cell(4, column_of(links, "modal damping"), 5)
        _type_percent(wb["Hinges"], "loss factor", 3, 5)

    _edit(path, change)
    saved_by_libreoffice(path)
    ws = load_workbook(path)["Links"]
    assert "%" in ws.cell(3, column_of(ws, "modal damping")).number_format     # LibreOffice kept it a percentage
    case = read_workbook(path).case
    assert case.links[0].modal_damping == pytest.approx(0.05, rel=1e-12)
    assert case.links[1].modal_damping == pytest.approx(0.05, rel=1e-12)
    assert case.hinges[0].loss_factor == pytest.approx(0.05, rel=1e-12)


def test_a_percentage_where_no_percentage_fits_is_refused(tmp_path, capsys):
    """A percent-formatted cell in a length column or a count column, and a '%' unit cell over counts."""
    path = copy_reference(tmp_path)

    def change(wb):
        _type_percent(wb["Links"], "eye outer radius", 3, 4000)
        _type_percent(wb["Excitations"], "sweep points", 5, 2500)
        wb["Case"].cell(2, column_of(wb["Case"], "measured periods"), "%")

    _edit(path, change)
    saved_by_libreoffice(path)
    _refused(path, capsys, "sheet 'Links', cell M3, column 'eye outer radius': found '4000 %'",
             "not formatted as a percentage", "sheet 'Excitations', cell R5, column 'sweep points': found '2500 %'",
             "sheet 'Case', cell G2, column 'measured periods (unit)': found '%'", "a count has no unit")
