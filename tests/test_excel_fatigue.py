"""The Speed spectrum sheet and the S-N columns of a case workbook, and the Result fatigue sheet a run writes.

A template filled by hand and saved by LibreOffice reads back into the
spectrum and S-N curve typed; bad cells are refused at their cells with
nothing written; the written fatigue table (workbook and report) holds the
numbers of ``mountwb stress --json`` and survives a LibreOffice save.
"""
from __future__ import annotations

import json
import shutil

import pytest
from excel_helpers import SOFFICE, TEMPLATE, column_of, make_cheap, save_in_libreoffice, set_cells, sha256
from openpyxl import load_workbook
from openpyxl.utils import get_column_letter

from workbook.cli.main import main
from workbook.excel.reader import read_workbook
from workbook.model.spectrum import SpeedBand, SpeedSpectrum, reference_speed_spectra

SHEET = "Speed spectrum"
#: The first empty row of the template's Speed spectrum sheet (the reference LP and HP spectra above).
NEW_ROW = 9


def _template(folder, name="case.xlsx"):
    target = folder / name
    shutil.copyfile(TEMPLATE, target)
    return target


def _links_cell(header: str, row: int = 3) -> str:
    return f"{get_column_letter(column_of(load_workbook(TEMPLATE)['Links'], header))}{row}"


@pytest.mark.skipif(SOFFICE is None, reason="LibreOffice (soffice) is not on PATH")
def test_a_template_filled_and_saved_by_libreoffice_reads_back_the_spectrum(tmp_path):
    path = _template(tmp_path)
    set_cells(path, {(SHEET, "excitation", NEW_ROW): "sweep", (SHEET, "speed", NEW_ROW): 1200,
                     (SHEET, "to speed", NEW_ROW): 1800, (SHEET, "hours", NEW_ROW): 12.5,
                     ("Links", "endurance cycles", 3): 2e6, ("Links", "fatigue exponent", 3): -0.09})
    save_in_libreoffice(path, tmp_path / "scratch")
    case = read_workbook(path).case
    assert case.speed_spectra == (*reference_speed_spectra(), SpeedSpectrum("sweep", (SpeedBand(12.5, 20.0, 30.0),)))
    material = case.links[0].model.material
    assert (material.endurance_cycles, material.fatigue_exponent) == (2e6, -0.09)
    assert case.links[1].model.material.fatigue_exponent == pytest.approx(-0.0851, abs=1e-4)    # the steel preset's


BAD_CELLS = {
    "negative hours": ({(SHEET, "hours", 4): -3}, SHEET, ["cell D4", "column 'hours'", "found -3", "a number >= 0"]),
    "speed outside the sweep": ({(SHEET, "excitation", NEW_ROW): "sweep", (SHEET, "speed", NEW_ROW): 20000,
                                 (SHEET, "hours", NEW_ROW): 1}, SHEET,
                                ["cell B9", "found 20000", "a speed within the speeds of 'sweep', 5 to 300 Hz"]),
    "unknown excitation": ({(SHEET, "excitation", 3): "IP rotor"}, SHEET,
                           ["cell A3", "found 'IP rotor'", "an excitation of the case"]),
    "text hours": ({(SHEET, "hours", 5): "long"}, SHEET, ["cell D5", "found 'long'", "a number"]),
    "positive fatigue exponent": ({("Links", "fatigue exponent", 3): 0.1}, "Links",
                                  [f"cell {_links_cell('fatigue exponent')}", "between -1 and 0"]),
}


@pytest.mark.parametrize("name", list(BAD_CELLS))
def test_a_bad_spectrum_cell_exits_2_naming_sheet_and_cell(tmp_path, capsys, name):
    edits, sheet, expected = BAD_CELLS[name]
    path = _template(tmp_path)
    set_cells(path, edits)
    before, files = sha256(path), sorted(tmp_path.iterdir())
    assert main(["check", str(path)]) == 2
    assert main(["run", str(path), "--no-progress"]) == 2
    message = capsys.readouterr().err
    for text in ["case.xlsx", f"sheet '{sheet}'", *expected]:
        assert text in message, f"{name}: {text!r} not in\n{message}"
    assert sha256(path) == before and sorted(tmp_path.iterdir()) == files


@pytest.mark.slow
def test_the_written_fatigue_sheets_hold_the_numbers_of_mountwb_stress(tmp_path, capsys):
    """The template on coarse links, its spectra on the LP and HP rotors: Result fatigue and the report's
    Fatigue sheet equal ``mountwb stress --json``, and a LibreOffice save keeps them."""
    path = _template(tmp_path)
    make_cheap(path)
    wb = load_workbook(path)
    for sheet in ("Load cases", SHEET):                  # one load case, one speed per rotor (rows 3 and 6): a short run
        for row in range(4, wb[sheet].max_row + 1):
            if sheet == "Load cases" or row != 6:
                for col in range(1, wb[sheet].max_column + 1):
                    wb[sheet].cell(row, col).value = None
    wb.save(path)
    set_cells(path, {(SHEET, "to speed", 3): None, (SHEET, "to speed", 6): None})
    report = tmp_path / "report.xlsx"
    assert main(["run", str(path), "--run", "LP rotor", "--no-progress", "--report", str(report)]) == 0
    capsys.readouterr()
    assert main(["stress", str(path), "--json"]) == 0
    fatigue = json.loads(capsys.readouterr().out)["fatigue"]
    harmonic = {(e["excitation"], link): f for e in fatigue["excitations"] for link, f in e["links"].items()}
    spectra = {(s["excitation"], link): d for s in fatigue["spectra"] for link, d in s["links"].items()}
    assert [s["excitation"] for s in fatigue["spectra"]] == ["LP rotor", "HP rotor"]
    card = [line for (line,) in load_workbook(path)["Result model card"].iter_rows(max_col=1, values_only=True) if line]
    assert any("[on ] limit load cases: 1 for the links' static margins" in line for line in card)
    assert any("[off] link fatigue: no flexible link" in line for line in card)       # the run's links are rigid
    if SOFFICE is not None:
        save_in_libreoffice(path, tmp_path / "scratch")
    for book, title, top in ((load_workbook(path), "Result fatigue", 2), (load_workbook(report), "Fatigue", 4)):
        sheet = book[title]
        header = [cell.value for cell in sheet[top]]
        rows = [dict(zip(header, values, strict=False)) for values in sheet.iter_rows(min_row=top + 1, values_only=True)
                if values[0] is not None]
        kinds = [row["kind"] for row in rows]
        assert kinds.count("harmonic") == len(harmonic) and kinds.count("spectrum") == len(spectra) > 0
        assert kinds.count("all spectra") == len(fatigue["life_hours"])
        for row in rows:
            if row["kind"] == "harmonic":
                answer = harmonic[(row["excitation"], row["link"])]
                assert (row["peak sigma_a MPa"], row["sigma_m MPa"]) == pytest.approx(
                    (answer["peak_alternating"] / 1e6, answer["mean"] / 1e6), rel=1e-9)
                assert (row["Goodman"], row["Gerber"]) == pytest.approx((answer["goodman"], answer["gerber"]), rel=1e-9)
                assert row["at"] == answer["region"]
            elif row["kind"] == "spectrum":
                answer = spectra[(row["excitation"], row["link"])]
                assert row["peak sigma_ar MPa"] == pytest.approx(answer["equivalent"] / 1e6, rel=1e-9)
                assert row["Miner D"] == answer["damage"] == 0.0     # 0.03 MPa against 235 and 510 MPa
                assert row["life h"] == "infinite"
                assert row["hours"] == 150 and row["frequency Hz"] == {"LP rotor": 15, "HP rotor": 150}[row["excitation"]]
