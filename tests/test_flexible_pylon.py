"""A flexible pylon given as a point dynamic stiffness per pin.

Closed form: the single-DOF engine (mass M on four hinges s = k + i w d,
each to its own pin) on a pylon of point dynamic stiffness z per pin: hinge
and pylon are two springs in series, ``s_e = s z / (s + z)``, so
``T = |4 s_e / (4 s_e - w^2 M)|``. A rigid pylon is the limit z -> infinity
of the whole reference mount. Bad tables are refused naming file, row and
column.
"""
import csv
import dataclasses
import math

import numpy as np
import pytest
from excel_helpers import copy_reference
from openpyxl import load_workbook
from test_sdof import DAMPING, MASS, NATURAL_HZ, STIFFNESS, sdof_case

from workbook.cli.main import main
from workbook.errors import EXIT_BAD_INPUT, CaseError, TableError, WorkbookError
from workbook.excel.impedance_sheet import SHEET
from workbook.excel.reader import read_workbook
from workbook.model.case import AnalysisSettings, Imbalance, ImbalancePlane
from workbook.model.codec import from_json, to_json
from workbook.model.pylon_impedance import FORMAT_HEADER, PylonImpedance, read_impedance_csv
from workbook.model.reference import LP_ROTOR
from workbook.solve.pipeline import run_case

PYLON_STIFFNESS = 3.0 * STIFFNESS      # per pin, N/m
PYLON_MASS = 40.0                       # per pin, kg
PYLON_DAMPING = 2.0 * DAMPING           # per pin, N s/m
RATIOS = (0.4, 1.1, 2.7)


def _rows(frequencies, pins, value, units=("Hz", "N/m")):
    """Header, units and data rows of a table whose Z_p at each pin is *value(f)* (3x3)."""
    rows = [list(FORMAT_HEADER), [units[0], ""] + [units[1]] * 18]
    for frequency in frequencies:
        matrix = np.asarray(value(frequency), dtype=complex)
        for pin in pins:
            cells = [v for entry in matrix.reshape(-1) for v in (entry.real, entry.imag)]
            rows.append([frequency, pin] + cells)
    return rows


def _write(path, rows):
    with path.open("w", newline="") as handle:
        csv.writer(handle).writerows(rows)
    return path


def _pylon(frequency):
    w = 2 * math.pi * frequency
    return (PYLON_STIFFNESS + 1j * w * PYLON_DAMPING - w ** 2 * PYLON_MASS) * np.eye(3)


def _sdof(ratios=RATIOS):
    case = sdof_case(ratios)
    return dataclasses.replace(case, analysis=AnalysisSettings(method="auto"))


def _pins(case):
    return [hinges[0] for _, hinges in case.pylon_pins()]


def test_soft_pylon_is_two_springs_in_series(tmp_path):
    case = _sdof()
    frequencies = [ratio * NATURAL_HZ for ratio in RATIOS]
    table = _write(tmp_path / "pylon.csv", _rows([1.0, *frequencies, 100.0], _pins(case), _pylon))
    result = run_case(dataclasses.replace(case, pylon=read_impedance_csv(table)))
    for ratio, frequency in zip(RATIOS, frequencies, strict=True):
        w = 2 * math.pi * frequency
        hinge = STIFFNESS + 1j * w * DAMPING
        pylon = _pylon(frequency)[0, 0]
        series = hinge * pylon / (hinge + pylon)
        expected = abs(4 * series / (4 * series - w ** 2 * MASS))
        run = result.run(f"r = {ratio:g}")
        np.testing.assert_allclose(run.transmissibility[1:], [expected, expected], rtol=1e-6)
        assert run.transmissibility[0] < 1e-9
        card = result.model_cards[run.name]
        assert any(e.name.startswith("flexible pylon") and "pylon.csv" in e.detail for e in card.effects)
        assert not any("rigid" in e.detail for e in card.effects if e.name.startswith("test-rig"))


def test_between_table_frequencies_real_and_imaginary_parts_are_linear(tmp_path):
    """A table at 5 and 15 Hz only: the run at 11 Hz sees the straight line
    between the two entries (real and imaginary parts), not the pylon's
    mass-spring law."""
    case = _sdof((1.1,))
    table = read_impedance_csv(_write(tmp_path / "pylon.csv", _rows([5.0, 15.0], _pins(case), _pylon)))
    run = run_case(dataclasses.replace(case, pylon=table)).runs[0]
    w = 2 * math.pi * 11.0
    hinge = STIFFNESS + 1j * w * DAMPING
    pylon = 0.4 * _pylon(5.0)[0, 0] + 0.6 * _pylon(15.0)[0, 0]
    series = hinge * pylon / (hinge + pylon)
    np.testing.assert_allclose(run.transmissibility[1], abs(4 * series / (4 * series - w ** 2 * MASS)), rtol=1e-6)


@pytest.mark.slow
def test_a_rigid_pylon_is_the_limit_of_a_stiff_one(coarse_reference):
    """The reference mount: as Z_p grows to infinity T tends to the rigid-pylon run's T (the rotors, and
    an imbalance of two planes in opposite phase, whose responses add plane by plane)."""
    front, rear = np.add(LP_ROTOR.point, (0.8, 0.0, 0.0)), np.add(LP_ROTOR.point, (-0.8, 0.0, 0.0))
    planes = Imbalance("two planes", (ImbalancePlane(tuple(front), unbalance=0.002),
                                      ImbalancePlane(tuple(rear), unbalance=0.002, phase_deg=180.0)),
                       frequency_hz=LP_ROTOR.frequency_hz)
    case = dataclasses.replace(coarse_reference, excitations=coarse_reference.excitations + (planes,))
    rigid = run_case(case)
    frequencies = [x.frequency for x in case.single_frequency_excitations()]
    grid = [min(frequencies) / 2, max(frequencies) * 2]
    pins = _pins(case)
    errors = []
    for stiffness in (1e12, 1e16):
        impedance = PylonImpedance.from_array("stiff", grid, pins, np.broadcast_to(stiffness * np.eye(3),
                                                                                   (2, len(pins), 3, 3)))
        stiff = run_case(dataclasses.replace(case, pylon=impedance))
        errors.append(max(np.abs(stiff.run(r.name).transmissibility / r.transmissibility - 1).max()
                          for r in rigid.runs))
    assert errors[1] < 1e-6
    assert errors[1] < errors[0]


def test_the_table_travels_with_a_json_case(tmp_path):
    case = _sdof()
    table = read_impedance_csv(_write(tmp_path / "pylon.csv", _rows([1.0, 40.0], _pins(case), _pylon)))
    with_table = dataclasses.replace(case, pylon=table)
    assert from_json(to_json(with_table)) == with_table


def test_the_workbook_sheet_is_the_csv_table(tmp_path):
    book = copy_reference(tmp_path)
    pins = _pins(read_workbook(book).case)
    rows = _rows([5.0, 300.0], pins, _pylon, units=("Hz", "MN/m"))        # the reference sweep: 5 to 300 Hz
    wb = load_workbook(book)
    sheet = wb.create_sheet(SHEET)
    for row in rows:
        sheet.append(row)
    wb.save(book)
    from_sheet = read_workbook(book).case.pylon
    from_csv = read_impedance_csv(_write(tmp_path / "pylon.csv", rows))
    np.testing.assert_allclose(from_sheet.values, from_csv.values, rtol=1e-15)
    np.testing.assert_allclose(from_csv.values[1, 0], _pylon(300.0) * 1e6, rtol=1e-12)
    assert from_sheet.source == f"{book.name}, sheet '{SHEET}'"
    wb[SHEET].delete_rows(3, 1)                     # the first pin at 10 Hz
    wb.save(book)
    with pytest.raises(WorkbookError) as error:
        read_workbook(book)
    assert SHEET in str(error.value) and pins[0] in str(error.value)


def _table_problem(tmp_path, edit):
    case = _sdof((1.1,))
    rows = _rows([5.0, 15.0], _pins(case), _pylon)
    edit(rows)
    path = _write(tmp_path / "bad.csv", rows)
    with pytest.raises((TableError, CaseError)) as error:
        dataclasses.replace(case, pylon=read_impedance_csv(path))
    return str(error.value)


def _set(row, column, value):
    def edit(rows):
        rows[row - 1][FORMAT_HEADER.index(column)] = value
    return edit


@pytest.mark.parametrize("edit, words", [
    (_set(4, "Kyz im", "soft"), ["bad.csv", "row 4", "'Kyz im'", "'soft'", "a finite number"]),
    (_set(7, "frequency", 4.0), ["bad.csv", "row 7", "'frequency'", "increase"]),
    (_set(2, "Kxx re", "kg"), ["bad.csv", "row 2", "'Kxx re'", "stiffness"]),
    (_set(2, "frequency", "zorks"), ["bad.csv", "row 2", "'frequency'", "a known unit"]),
    (_set(1, "Kzz im", "Kzz imag"), ["bad.csv", "row 1", "'Kzz im'"]),
    (lambda rows: [row.pop() for row in rows], ["bad.csv", "row 1", "'Kzz im'"]),
    (lambda rows: rows.pop(3), ["bad.csv", "hinge 1", "at 5 Hz", "every pin at every frequency"]),
    (lambda rows: rows.__delitem__(slice(2, None, 4)), ["bad.csv", "pin", "hinge 0"]),
], ids=["non-numeric cell", "decreasing frequency", "unit of another dimension", "unknown unit",
        "unknown column", "missing column", "pin missing at one frequency", "pin missing everywhere"])
def test_a_bad_table_is_named_by_file_row_and_column(tmp_path, edit, words):
    message = _table_problem(tmp_path, edit)
    for word in words:
        assert word in message, message


def test_the_command_line_refuses_bad_tables_and_the_time_domain(tmp_path, capsys):
    case = _sdof((1.1,))
    path = tmp_path / "case.json"
    path.write_text(to_json(case))
    bad = _write(tmp_path / "bad.csv", _rows([5.0, 15.0], _pins(case)[1:], _pylon))
    assert main(["run", str(path), "--pylon-impedance", str(bad)]) == EXIT_BAD_INPUT
    assert "bad.csv" in capsys.readouterr().err
    good = _write(tmp_path / "pylon.csv", _rows([5.0, 15.0], _pins(case), _pylon))
    assert main(["run", str(path), "--pylon-impedance", str(good), "--method", "time"]) == EXIT_BAD_INPUT
    error = capsys.readouterr().err
    assert "time domain" in error and "pylon.csv" in error
    narrow = _write(tmp_path / "narrow.csv", _rows([1.0, 5.0], _pins(case), _pylon))
    assert main(["run", str(path), "--pylon-impedance", str(narrow)]) == EXIT_BAD_INPUT
    error = capsys.readouterr().err
    assert "narrow.csv" in error and "11" in error and "1 to 5 Hz" in error

