"""The Four-pole sheet of the run report: the numbers read back from the
.xlsx are the four-pole set's."""
import numpy as np
import pytest
from excel_helpers import copy_reference, make_cheap, set_cells
from openpyxl import load_workbook

from workbook.cli.main import main
from workbook.errors import EXIT_BAD_INPUT
from workbook.excel.reader import read_workbook
from workbook.excel.report import FOUR_POLE_SHEET
from workbook.solve.four_pole import REPORT_GRID, frequency_grid
from workbook.solve.pipeline import four_pole


def _sheet_table(ws):
    """Header and numeric rows of the sheet's table (the row whose first cell is 'frequency (Hz)')."""
    rows = list(ws.iter_rows(values_only=True))
    top = next(n for n, row in enumerate(rows) if row[0] == "frequency (Hz)")
    header = [cell for cell in rows[top] if cell is not None]
    data = np.array([row[:len(header)] for row in rows[top + 1:] if row[0] is not None], dtype=float)
    return header, data


@pytest.mark.slow
def test_the_report_four_pole_sheet_holds_the_four_pole_set(tmp_path, cache_dir):
    path = copy_reference(tmp_path)
    make_cheap(path)
    set_cells(path, {("Case", "method", 3): "auto"})
    report = tmp_path / "report.xlsx"
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor", "--report", str(report),
                 "--four-pole"]) == 0
    header, data = _sheet_table(load_workbook(report)[FOUR_POLE_SHEET])
    pole = four_pole(read_workbook(path).case, frequency_grid(*REPORT_GRID))
    np.testing.assert_allclose(data[:, 0], pole.frequencies_hz, rtol=1e-12)
    for quantity in ("K11", "K21", "K22"):
        values = pole.direction_values(quantity)
        for d, axis in enumerate("xyz"):
            magnitude = data[:, header.index(f"|{quantity} {axis}| (N/m)")]
            phase = data[:, header.index(f"{quantity} {axis} (deg)")]
            np.testing.assert_allclose(magnitude, np.abs(values[:, d]), rtol=1e-9)
            np.testing.assert_allclose(np.exp(1j * np.radians(phase)), np.exp(1j * np.angle(values[:, d])),
                                       atol=1e-9)


def test_four_pole_needs_a_report(tmp_path, capsys):
    path = copy_reference(tmp_path)
    assert main(["run", str(path), "--no-progress", "--four-pole"]) == EXIT_BAD_INPUT
    assert "--report" in capsys.readouterr().err
    assert main(["run", "--no-progress", "--four-pole"]) == EXIT_BAD_INPUT
    assert "mountwb four-pole" in capsys.readouterr().err
    assert not list(tmp_path.glob("*report*"))
