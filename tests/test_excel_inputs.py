"""Input cells read as the user sees them, in workbooks edited and saved by LibreOffice Calc (those tests are
slow: each starts LibreOffice; skipped without ``soffice``), and the bounds of a case, a study and a run."""
from __future__ import annotations

import dataclasses
import json
import time

import pytest
from excel_helpers import column_of, copy_reference, make_cheap, saved_by_libreoffice, set_cells, sha256
from openpyxl import load_workbook

from workbook.cli.main import main
from workbook.errors import CaseError
from workbook.excel.impedance_sheet import SHEET as IMPEDANCE_SHEET
from workbook.excel.reader import read_workbook
from workbook.model.case import RunUp, Sweep
from workbook.model.codec import from_json, to_json
from workbook.model.pylon_impedance import FORMAT_HEADER
from workbook.model.reference import reference_case

#: A Rotors row, a Test rig row and an Engine casing row, as ``set_cells`` edits.
ROTOR_ROW = {("Rotors", "name", 3): "LP spool", ("Rotors", "polar inertia", 3): 100, ("Rotors", "speed", 3): 59}
RIG_ROW = {("Test rig", f"stiffness {axis}", 3): 1e8 for axis in "xyz"}
CASING_ROW = {("Engine casing", header, 3): value for header, value in (
    ("radius", 500), ("wall thickness", 25), ("x start", -1.8), ("x end", 0.7), ("front ring x", 0.0),
    ("front ring width", 80), ("front ring radius", 620), ("rear ring x", -1.72), ("rear ring width", 80),
    ("rear ring radius", 580), ("bearing 1 x", 0.35), ("bearing 2 x", -1.2), ("element size", 120),
    ("bearing band", 40))}


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


@pytest.mark.slow    # LibreOffice saves the workbook
def test_a_cell_showing_5_percent_is_5_percent_in_a_percent_or_plain_column(tmp_path):
    """Link modal damping with the unit cell '%' and hinge loss factor with '-': a cell typed '5 %' is 0.05 in
    both; a plain 5 under '%' stays 0.05, and so is the text '5 %' in a text cell."""
    path = copy_reference(tmp_path)

    def change(wb):
        links = wb["Links"]
        links.cell(2, column_of(links, "modal damping"), "%")
        _type_percent(links, "modal damping", 3, 5)
        links.cell(4, column_of(links, "modal damping"), 5)
        _type_percent(wb["Hinges"], "loss factor", 3, 5)
        hinges = wb["Hinges"]
        cell = hinges.cell(4, column_of(hinges, "loss factor"), "5 %")
        cell.number_format = "@"                                   # a text cell: '5 %' stays text

    _edit(path, change)
    saved_by_libreoffice(path)
    ws = load_workbook(path)["Links"]
    assert "%" in ws.cell(3, column_of(ws, "modal damping")).number_format     # LibreOffice kept it a percentage
    case = read_workbook(path).case
    assert case.links[0].modal_damping == pytest.approx(0.05, rel=1e-12)
    assert case.links[1].modal_damping == pytest.approx(0.05, rel=1e-12)
    assert case.hinges[0].loss_factor == pytest.approx(0.05, rel=1e-12)
    assert case.hinges[1].loss_factor == pytest.approx(0.05, rel=1e-12)


@pytest.mark.slow    # LibreOffice saves the workbook
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


# -- sheet names --------------------------------------------------------------------------------------------


def _rename(titles: dict):
    """Rename sheets (through a name of its own: openpyxl, like Excel, takes 'Test Rig' for the 'Test rig' it
    renames and would make it 'Test Rig1')."""
    def change(wb):
        for old, new in titles.items():
            wb[old].title = "renamed"
            wb["renamed"].title = new
    return change


@pytest.mark.slow    # LibreOffice saves the workbook
def test_optional_sheets_are_found_whatever_the_letter_case_and_spaces(tmp_path):
    path = copy_reference(tmp_path)
    set_cells(path, {**ROTOR_ROW, **RIG_ROW, **CASING_ROW})
    _edit(path, _rename({"Test rig": "Test Rig", "Engine casing": "Engine Casing", "Rotors": "Rotors "}))
    saved_by_libreoffice(path)
    assert {"Test Rig", "Engine Casing", "Rotors "} <= set(load_workbook(path).sheetnames)
    case = read_workbook(path).case
    assert [rotor.name for rotor in case.rotors] == ["LP spool"]
    assert case.test_rig is not None and case.test_rig.stiffness == (1e8, 1e8, 1e8)
    assert case.engine.casing is not None


@pytest.mark.slow    # LibreOffice saves the workbook
def test_two_sheets_of_one_name_are_refused(tmp_path, capsys):
    path = copy_reference(tmp_path)
    set_cells(path, ROTOR_ROW)

    def change(wb):
        wb.copy_worksheet(wb["Rotors"]).title = "Rotors "

    _edit(path, change)
    saved_by_libreoffice(path)
    _refused(path, capsys, "found \"sheet 'Rotors', sheet 'Rotors '\"", "expected one sheet named 'Rotors'")


@pytest.mark.slow    # LibreOffice saves the workbook
def test_a_sheet_named_close_to_a_sheet_read_is_refused(tmp_path, capsys):
    path = copy_reference(tmp_path)
    set_cells(path, {**ROTOR_ROW, **RIG_ROW})
    _edit(path, _rename({"Test rig": "Test-rig", "Rotors": "Rotor"}))
    _edit(path, lambda wb: setattr(wb.copy_worksheet(wb["Runs"]), "title", "Runs (2)"))
    saved_by_libreoffice(path)
    message = _refused(path, capsys, "sheet 'Test-rig': found 'Test-rig', expected a sheet name the package reads "
                       "(did you mean 'Test rig'?", "sheet 'Rotor': found 'Rotor'", "did you mean 'Rotors'?")
    assert "Runs (2)'" not in message      # a copy beside its sheet is the user's


# -- a mesh file and a geometry -----------------------------------------------------------------------------


@pytest.mark.slow    # LibreOffice saves the workbook
def test_a_row_with_a_mesh_file_and_a_geometry_is_refused(tmp_path, capsys):
    """A Links row and the Engine casing row that give a mesh file and keep their parametric geometry."""
    path = copy_reference(tmp_path)
    (tmp_path / "meshes").mkdir()
    for name in ("front-left.inp", "casing.inp"):
        (tmp_path / "meshes" / name).write_text("*NODE\n")
    set_cells(path, {**CASING_ROW, ("Engine casing", "mesh file", 3): "meshes/casing.inp",
                     ("Links", "mesh file", 3): "meshes/front-left.inp", ("Links", "bore A node set", 3): "BORE_A",
                     ("Links", "bore B node set", 3): "BORE_B"})
    saved_by_libreoffice(path)
    _refused(path, capsys, "sheet 'Links', cell AB3, column 'mesh file': found 'meshes/front-left.inp', expected a "
             "mesh file or a parametric geometry, not both (row 3 also gives the geometry: 'eye outer radius' in M3, "
             "'eye thickness' in O3, 'shank width' in P3, 'shank thickness' in Q3",
             "sheet 'Engine casing', cell Y3, column 'mesh file': found 'meshes/casing.inp'",
             "'radius' in A3, 'wall thickness' in B3, 'x start' in C3, 'x end' in D3, 'front ring x' in E3")


# -- every bad cell named, every problem at once ----------------------------------------------------------


@pytest.mark.slow    # LibreOffice saves the workbook
def test_bad_cells_found_by_trying_each_column_kind_are_named_together(tmp_path, capsys):
    """Cells that gave Python's own words (or stopped the check): an empty casing 'x start', a superscript
    two as a mode count or a fidelity, an Arabic-Indic three as a stiffness, a number so long as a mesh file
    name that the system cannot look it up, unit cells 'mm/0' and '('."""
    path = copy_reference(tmp_path)
    set_cells(path, {**CASING_ROW, ("Engine casing", "x start", 3): None,
                     ("Links", "modes", 3): "\u00b2", ("Runs", "fidelity", 4): "\u00b2",
                     ("Hinges", "stiffness", 4): "\u0663", ("Links", "mesh file", 5): 1e300,
                     ("Static loads", "force x", 2): "mm/0", ("Excitations", "phase", 2): "("})
    saved_by_libreoffice(path)
    message = _refused(path, capsys)
    expected = ["sheet 'Engine casing', cell C3, column 'x start': found empty, expected a position, m",
                "sheet 'Links', cell T3, column 'modes': found '\u00b2', expected auto, static, a mode count",
                "sheet 'Runs', cell E4, column 'fidelity': found '\u00b2', expected rigid, static",
                "sheet 'Hinges', cell G4, column 'stiffness': found '\u0663', expected a number",
                "sheet 'Links', cell AB5, column 'mesh file': found '1000000000000000052504760255204420248704",
                "cannot be looked at: File name too long",
                "sheet 'Static loads', cell C2, column 'force x (unit)': found 'mm/0', expected a known unit",
                "sheet 'Excitations', cell O2, column 'phase (unit)': found '(', expected a known unit"]
    for text in expected:
        assert text in message, f"{text!r} not in\n{message}"
    assert "NoneType" not in message and "invalid literal" not in message


@pytest.mark.slow    # LibreOffice saves the workbook
def test_an_empty_ring_width_is_named(tmp_path, capsys):
    path = copy_reference(tmp_path)
    set_cells(path, {**CASING_ROW, ("Engine casing", "rear ring width", 3): None})
    saved_by_libreoffice(path)
    _refused(path, capsys, "sheet 'Engine casing', cell H3:J3, column 'rear ring x to rear ring radius': found "
             "(-1.72, None, 580), expected a ring's mid-plane x, width and outer radius, m")


# -- bounded counts -----------------------------------------------------------------------------------------


@pytest.mark.slow    # LibreOffice saves the workbook
def test_a_million_sweep_points_and_a_million_modes_are_refused_at_once(tmp_path, capsys):
    """The sweep's 'sweep points' and a link's 'modes' name their cells, the value and the bound; the check
    takes about as long as any other (it took 20 to 40 s for 1e6 points, and blamed the name cell)."""
    path = copy_reference(tmp_path)
    set_cells(path, {("Excitations", "sweep points", 5): 1_000_000, ("Links", "modes", 4): 1_000_000})
    saved_by_libreoffice(path)
    start = time.perf_counter()
    _refused(path, capsys, "sheet 'Excitations', cell R5, column 'sweep points': found 1000000, expected a whole "
             "number from 1 to 10,000 (the most points a sweep takes)",
             "sheet 'Links', cell T4, column 'modes': found 1000000, expected a whole number from 0 to 1,000")
    assert time.perf_counter() - start < 15


def _long_sweep(data):
    data["excitations"][-1]["frequencies_hz"] = [1.0 + k for k in range(20_000)]


def _many_modes(data):
    data["links"][0]["modes"] = 5000


@pytest.mark.parametrize("change, named", [
    (_long_sweep, ["excitation 'sweep'", "frequencies_hz", "20,000 frequencies", "at most 10,000"]),
    (_many_modes, ["link 'front-left'", "modes", "5000", "from 0 to 1,000"]),
])
def test_json_cases_are_bounded_too(change, named):
    data = json.loads(to_json(reference_case(sweep=True)))
    change(data)
    with pytest.raises(CaseError) as error:
        from_json(json.dumps(data))
    for words in named:
        assert words in str(error.value)


def test_a_run_up_and_a_sweep_built_in_python_are_bounded():
    template = reference_case().excitations[0]
    with pytest.raises(CaseError, match="points.*found 1000000.*from 2 to 10,000"):
        RunUp.speeds("up", dataclasses.replace(template, amplitude=None, unbalance=1e-3), 600.0, 6000.0, 1_000_000)
    with pytest.raises(CaseError, match="points.*found 1000000000000000.0.*from 1 to 10,000"):
        Sweep.band("sweep", template, 5.0, 300.0, 1e15)


@pytest.mark.parametrize("vary", [["--vary=hinge_stiffness=1e6:1e8:1000000"],
                                  ["--vary=hinge_stiffness=1e6:1e8:1000", "--vary=clearance=0:1e-3:1000"],
                                  ["--vary=hinge_stiffness=1e6:1e8", "--lhs=10000000"]])
def test_a_study_of_millions_of_rows_is_refused(tmp_path, capsys, vary):
    path = copy_reference(tmp_path)
    start = time.perf_counter()
    assert main(["study", "params", str(path), "--output", str(tmp_path / "out"), *vary]) == 2
    assert time.perf_counter() - start < 15
    message = capsys.readouterr().err
    assert "rows; a study has at most 100,000" in message, message
    assert not (tmp_path / "out").exists()


# -- the pylon impedance table and the runs -------------------------------------------------------------------


def _pylon_sheet(wb, frequencies, pins) -> None:
    """A Pylon impedance sheet: 100 MN/m along each axis at each pin, at each of *frequencies* (Hz)."""
    ws = wb.create_sheet(IMPEDANCE_SHEET)
    ws.append(list(FORMAT_HEADER))
    ws.append(["Hz", ""] + ["MN/m"] * 18)
    diagonal = {f"K{a}{a} re" for a in "xyz"}
    for frequency in frequencies:
        for pin in pins:
            ws.append([frequency, pin] + [100.0 if column in diagonal else 0.0 for column in FORMAT_HEADER[2:]])


@pytest.mark.slow    # LibreOffice saves the workbook
def test_check_finds_a_pylon_table_that_does_not_cover_a_run(tmp_path, capsys):
    """The reference sweep runs from 5 Hz; a table from 10 Hz covers the rotor runs but not the sweep."""
    path = copy_reference(tmp_path)
    pins = [hinges[0] for _, hinges in read_workbook(path).case.pylon_pins()]
    _edit(path, lambda wb: _pylon_sheet(wb, (10.0, 100.0, 300.0), pins))
    saved_by_libreoffice(path)
    message = _refused(path, capsys, "sheet 'Runs', cell B5, column 'excitation': found 'sweep', expected an "
                       "excitation within the pylon impedance table: run 'sweep' excites 5 to 300 Hz, the table "
                       "(case.xlsx, sheet 'Pylon impedance') covers 10 to 300 Hz")
    assert "cell B3" not in message and "cell B4" not in message


@pytest.mark.slow
def test_a_failing_run_is_named_and_the_answers_of_the_others_are_written(tmp_path, capsys):
    """The HP rotor run, started from rest, plans more time steps than any meant run (numerical trouble,
    exit 1): the LP rotor and sweep runs' answers are written all the same."""
    path = copy_reference(tmp_path)
    make_cheap(path)
    set_cells(path, {("Case", "start", 3): "rest", ("Runs", "settle time", 4): 1e5})
    assert main(["run", str(path), "--no-progress"]) == 1
    message = capsys.readouterr().err
    assert "run 'HP rotor' (excitation 'HP rotor') failed, numerical trouble:" in message, message
    assert "the answers of 2 run(s) were written; 'HP rotor' failed" in message
    rows = list(load_workbook(path)["Result efficiency"].iter_rows(min_row=3, values_only=True))
    assert {row[0] for row in rows} == {"LP rotor", "sweep"}


def test_check_finds_a_pylon_table_with_the_time_domain(tmp_path, capsys):
    """The time domain has no frequency-dependent pylon: a run it would answer is refused by check, the rotor
    runs; the sweep on the linear scene takes the frequency domain and is fine."""
    path = copy_reference(tmp_path)
    pins = [hinges[0] for _, hinges in read_workbook(path).case.pylon_pins()]
    _edit(path, lambda wb: _pylon_sheet(wb, (1.0, 400.0), pins))
    set_cells(path, {("Case", "method", 3): "time"})
    message = _refused(path, capsys, "sheet 'Runs', cell B3, column 'excitation': found 'LP rotor', expected no "
                       "frequency-dependent pylon impedance in the time domain", "(run 'LP rotor')",
                       "sheet 'Runs', cell B4")
    assert "cell B5" not in message


@pytest.mark.slow
def test_a_run_whose_input_fails_while_running_is_named_and_nothing_is_written(tmp_path, capsys):
    """A mesh file that is no mesh (check sees that it exists; the run reads it): the run names itself, bad
    input (exit 2), and no file is changed."""
    path = copy_reference(tmp_path)
    make_cheap(path)
    (tmp_path / "front-left.inp").write_text("not a mesh\n")
    set_cells(path, {("Links", "mesh file", 3): "front-left.inp", ("Links", "bore A node set", 3): "BORE_A",
                     ("Links", "bore B node set", 3): "BORE_B",
                     **{("Links", header, 3): None for header in ("eye outer radius", "eye thickness", "shank width",
                                                                 "shank thickness")}})
    assert main(["check", str(path)]) == 0
    before, files = sha256(path), sorted(tmp_path.iterdir())
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor", "--run", "sweep"]) == 2
    message = capsys.readouterr().err
    assert "run 'LP rotor' (excitation 'LP rotor') failed, bad input:" in message, message
    assert "front-left.inp" in message and "nothing was written" in message
    assert sha256(path) == before and sorted(tmp_path.iterdir()) == files
