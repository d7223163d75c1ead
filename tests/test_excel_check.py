"""Reading and checking case workbooks: units, formulas, and the bad-input suite."""
from __future__ import annotations

import dataclasses
import datetime
import io
import re
import zipfile

import pytest
from excel_helpers import REFERENCE, TEMPLATE, column_of, compound_file, copy_reference, give_cached_value, set_cells, sha256
from openpyxl import load_workbook
from openpyxl.chart import BarChart, Reference

from workbook.cli.main import main
from workbook.errors import UnitProblem, WorkbookError
from workbook.excel.reader import read_workbook
from workbook.excel.template import case_workbook, reference_workbook, template_workbook, write_workbook
from workbook.model.case import ForceTransducers
from workbook.model.codec import to_dict
from workbook.model.reference import HP_SPOOL, LP_SPOOL, reference_case
from workbook.model.units import si_factor

#: A Rotors row and a Test rig row, as ``set_cells`` edits.
ROTOR_ROW = {("Rotors", "name", 3): "LP spool", ("Rotors", "polar inertia", 3): 100, ("Rotors", "speed", 3): 59}
RIG_ROW = {("Test rig", f"stiffness {axis}", 3): 1e8 for axis in "xyz"}


def _numbers(case):
    """Everything that decides a case's numbers (sweeps as their frequencies), as plain data."""
    return to_dict(dataclasses.replace(case, excitations=case.single_frequency_excitations()))


# -- units ------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("text, si_unit, factor", [
    ("mm", "m", 1e-3), ("kN/mm", "N/m", 1e6), ("t", "kg", 1e3), ("rpm", "Hz", 1 / 60), ("1/min", "Hz", 1 / 60),
    ("g", "m/s^2", 9.80665), ("g*mm", "kg*m", 1e-6), ("g", "kg", 1e-3), ("GPa", "Pa", 1e9), ("kN", "N", 1e3),
    ("%", "-", 0.01), ("-", "-", 1.0), ("kN*s/mm", "N*s/m", 1e6), ("lbf", "N", 4.4482216152605),
])
def test_unit_factors(text, si_unit, factor):
    assert si_factor(text, si_unit) == pytest.approx(factor, rel=1e-12)


@pytest.mark.parametrize("text, si_unit", [("kg", "N/m"), ("mmm", "m"), ("", "m"), ("g", "m"), ("Hz", "-")])
def test_bad_units(text, si_unit):
    with pytest.raises(UnitProblem):
        si_factor(text, si_unit)


# -- generated workbooks ---------------------------------------------------------------------------------------


def _members(path):
    """Zip members and contents, without the save-time stamp (docProps/core.xml)."""
    with zipfile.ZipFile(path) as archive:
        return {name: archive.read(name) for name in archive.namelist() if name != "docProps/core.xml"}


@pytest.mark.parametrize("make, committed", [(template_workbook, TEMPLATE), (reference_workbook, REFERENCE)])
def test_committed_workbooks_are_what_the_code_generates(tmp_path, make, committed):
    generated, _ = write_workbook(make(), tmp_path / committed.name)
    assert _members(generated) == _members(committed), \
        f"{committed.name} is stale: regenerate it with `mountwb template {committed} [--reference] --replace`"


def test_reference_workbook_is_the_python_default():
    book = read_workbook(REFERENCE)
    assert _numbers(book.case) == _numbers(reference_case(sweep=True))
    assert [(r.name, r.excitation) for r in book.runs] == [("LP rotor", "LP rotor"), ("HP rotor", "HP rotor"),
                                                           ("sweep", "sweep")]
    lp, hp = (book.run_case(run).excitations[0] for run in book.runs[:2])
    assert (lp.frequency, lp.force_amplitude, hp.frequency, hp.force_amplitude) == (59.0, 1000.0, 248.5, 1000.0)
    loads = {load.name: load for load in book.case.static_loads}
    assert loads["thrust"].force == (23_000.0, 0.0, 0.0)
    assert book.case.engine.mass * -loads["gravity"].acceleration[2] == pytest.approx(35_000, rel=1e-3)


def test_template_has_units_drop_downs_and_instructions():
    wb = load_workbook(TEMPLATE)
    assert wb.sheetnames[0] == "Instructions"
    links = wb["Links"]
    assert links.cell(2, column_of(links, "eye outer radius")).value == "mm"
    assert links.cell(2, column_of(links, "E")).value == "GPa"
    lists = {str(dv.sqref): dv.formula1 for dv in links.data_validations.dataValidation}
    letter = links.cell(1, column_of(links, "material")).column_letter
    assert lists[f"{letter}3:{letter}500"] == '"steel,titanium"'
    assert links.cell(3, column_of(links, "material")).value == "steel"
    assert read_workbook(TEMPLATE).runs[3].fidelity == "rigid"


def test_units_are_converted_on_reading(tmp_path):
    path = copy_reference(tmp_path)
    wb = load_workbook(path)
    engine, hinges, excitations = wb["Engine"], wb["Hinges"], wb["Excitations"]
    engine.cell(2, column_of(engine, "mass"), "t")
    engine.cell(3, column_of(engine, "mass"), 3.568)
    hinges.cell(2, column_of(hinges, "stiffness"), "kN/mm")
    hinges.cell(3, column_of(hinges, "stiffness"), 20)
    hinges.cell(2, column_of(hinges, "radial clearance"), "µm")
    hinges.cell(3, column_of(hinges, "radial clearance"), 50)
    excitations.cell(2, column_of(excitations, "frequency"), "rpm")
    excitations.cell(3, column_of(excitations, "frequency"), 3540)
    wb.save(path)
    set_cells(path, {**ROTOR_ROW, ("Rotors", "speed", 2): "rpm", ("Rotors", "speed", 3): 3540,
                     ("Rotors", "polar inertia", 2): "t*mm^2", ("Rotors", "polar inertia", 3): 1e5,
                     **RIG_ROW, ("Test rig", "stiffness z", 2): "kN/mm", ("Test rig", "stiffness z", 3): 300,
                     ("Test rig", "mass", 2): "g", ("Test rig", "mass", 3): 800})
    case = read_workbook(path).case
    assert case.engine.mass == pytest.approx(3568.0, rel=1e-12)
    assert case.hinges[0].stiffness == pytest.approx(2.0e7, rel=1e-12)
    assert case.hinges[0].radial_clearance == pytest.approx(5e-5, rel=1e-12)
    assert case.excitations[0].frequency == pytest.approx(59.0, rel=1e-12)
    assert case.rotors[0].frequency == pytest.approx(59.0, rel=1e-12)
    assert case.rotors[0].polar_inertia == pytest.approx(100.0, rel=1e-12)
    assert case.test_rig.stiffness == pytest.approx((1e8, 1e8, 3e8), rel=1e-12)
    assert case.test_rig.mass == pytest.approx(0.8, rel=1e-12)


def test_hinge_values_per_direction_and_loss_factors_are_read_and_written_back(tmp_path):
    """Radial 2 / axial columns make three values (an empty one: as the first column); the
    frame comes from its radial 1 and axial directions; the case writes back to the same cells."""
    path = copy_reference(tmp_path)
    axial = (0.0, 0.6, 0.8)
    set_cells(path, {("Hinges", "stiffness axial", 3): 5e6, ("Hinges", "loss factor", 3): 0.05,
                     ("Hinges", "loss factor axial", 3): 0.1, ("Links", "loss factor", 3): 0.002,
                     ("Links", "modal damping", 3): 0.02,
                     **{("Hinges", f"frame radial 1 {a}", 3): v for a, v in zip("xyz", (1.0, 0.0, 0.0), strict=True)},
                     **{("Hinges", f"frame axial {a}", 3): v for a, v in zip("xyz", axial, strict=True)}})
    case = read_workbook(path).case
    hinge, plain = case.hinges[0], case.hinges[1]
    assert hinge.stiffness == (plain.stiffness, plain.stiffness, 5e6)
    assert hinge.loss_factor == (0.05, 0.05, 0.1)
    assert not hinge.isotropic and plain.isotropic
    assert hinge.frame == ((1.0, 0.0, 0.0), (0.0, 0.8, -0.6), axial)
    assert case.links[0].loss_factor == 0.002 and case.links[0].modal_damping == 0.02
    again = tmp_path / "again.xlsx"
    write_workbook(case_workbook(case, read_workbook(path).runs), again)
    assert _numbers(read_workbook(again).case) == _numbers(case)


def test_rotors_and_test_rig_are_read(tmp_path):
    path = copy_reference(tmp_path)
    set_cells(path, {**ROTOR_ROW, ("Rotors", "name", 4): "HP spool", ("Rotors", "polar inertia", 4): 15,
                     ("Rotors", "speed", 4): 248.5, ("Rotors", "spin axis", 4): "z",
                     **RIG_ROW, ("Test rig", "stiffness z", 3): 3e8, ("Test rig", "mass", 3): 0.5,
                     **{("Test rig", f"damping {axis}", 3): 20 for axis in "xyz"}})
    expected = dataclasses.replace(reference_case(sweep=True),
                                   rotors=(LP_SPOOL, dataclasses.replace(HP_SPOOL, axis=(0, 0, 1))),
                                   test_rig=ForceTransducers((1e8, 1e8, 3e8), mass=0.5, damping=(20, 20, 20)))
    case = read_workbook(path).case
    assert _numbers(case) == _numbers(expected)
    assert case.effects.gyroscopics and case.effects.rig_sensors
    set_cells(path, {("Case", "gyroscopics", 3): "no", ("Case", "rig sensors", 3): "no"})
    effects = read_workbook(path).case.effects
    assert (effects.gyroscopics, effects.rig_sensors) == (False, False)


def test_rotors_and_test_rig_sheets_are_optional(tmp_path):
    """A workbook made before the Rotors and Test rig sheets (and their effect columns) still reads."""
    path = copy_reference(tmp_path)
    wb = load_workbook(path)
    for sheet in ("Rotors", "Test rig"):
        wb.remove(wb[sheet])
    wb["Case"].delete_cols(column_of(wb["Case"], "gyroscopics"), 2)
    wb.save(path)
    case = read_workbook(path).case
    assert (case.rotors, case.test_rig) == ((), None)
    assert _numbers(case) == _numbers(reference_case(sweep=True))


def _with_cached_value(path, sheet_index, cell, value):
    """Give the formula in *cell* of the *sheet_index*-th sheet a cached value, as Excel would."""
    member = f"xl/worksheets/sheet{sheet_index}.xml"
    with zipfile.ZipFile(path) as archive:
        contents = {name: archive.read(name) for name in archive.namelist()}
    xml = contents[member].decode()
    xml, count = re.subn(rf'(<c r="{cell}"[^>]*>\s*<f>[^<]*</f>)\s*(<v\s*/>|<v></v>)?', rf"\1<v>{value}</v>", xml)
    assert count == 1
    contents[member] = xml.encode()
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in contents.items():
            archive.writestr(name, data)


def test_formula_cells_are_read_as_their_cached_values(tmp_path):
    path = copy_reference(tmp_path)
    set_cells(path, {("Engine", "mass", 3): "=3000+568"})
    _with_cached_value(path, 3, "A3", 3568)   # Instructions, Case, Engine
    assert read_workbook(path).case.engine.mass == 3568.0


@pytest.mark.parametrize("read", [True, False], ids=["a sheet read", "a sheet of notes"])
def test_a_cached_value_that_cannot_be_read_is_bad_input(tmp_path, read):
    """A formula cell whose cached value is no number: the workbook is refused as unreadable, not a crash."""
    path = copy_reference(tmp_path)
    if read:
        set_cells(path, {("Engine", "mass", 3): "=3000+568"})
        sheet, cell = 3, "A3"     # Instructions, Case, Engine
    else:
        wb = load_workbook(path)
        wb["Instructions"]["H1"] = "=1+1"
        wb.save(path)
        sheet, cell = 1, "H1"
    _with_cached_value(path, sheet, cell, "abc")
    with pytest.raises(WorkbookError, match="a readable Excel .xlsx workbook"):
        read_workbook(path)


def test_a_sheet_whose_stored_size_is_wrong_is_read_whole(tmp_path):
    """Some programs store a sheet's size as 'A1' whatever it holds: every cell stored is read all the same."""
    path = copy_reference(tmp_path)
    with zipfile.ZipFile(path) as archive:
        contents = {name: archive.read(name) for name in archive.namelist()}
    for name in [name for name in contents if name.startswith("xl/worksheets/sheet")]:
        contents[name], count = re.subn(rb'<dimension ref="[^"]*"\s*/>', b'<dimension ref="A1"/>', contents[name])
        assert count == 1
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in contents.items():
            archive.writestr(name, data)
    book, reference = read_workbook(path), read_workbook(REFERENCE)
    assert to_dict(book.case) == to_dict(reference.case)
    assert (book.runs, book.tests) == (reference.runs, reference.tests)


# -- the bad-input suite ---------------------------------------------------------------------------------------


def _edit(edits):
    return lambda path: set_cells(path, edits)


def _edit_wb(change):
    def apply(path):
        wb = load_workbook(path)
        change(wb)
        wb.save(path)
    return apply


def _hinge_row(wb, name):
    ws = wb["Hinges"]
    return next(r for r in range(3, ws.max_row + 1) if ws.cell(r, 1).value == name)


def _move_hinge(wb):
    ws = wb["Hinges"]
    col = column_of(ws, "position x")
    ws.cell(3, col, ws.cell(3, col).value + 0.005)


def _write_bytes(data):
    def apply(path):
        path.write_bytes(data(path))
    return apply


def _zip_of_text(path):
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        archive.writestr("notes.txt", "not a workbook")
    return buffer.getvalue()


def _opendocument(path):
    """The bytes of an OpenDocument spreadsheet (the start of one LibreOffice saves as .ods)."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        archive.writestr("mimetype", "application/vnd.oasis.opendocument.spreadsheet")
        archive.writestr("content.xml", "<office:document-content/>")
    return buffer.getvalue()


def _date_formatted_mass(wb):
    wb["Engine"]["A3"].number_format = "yyyy-mm-dd"


def _formula_error(path):
    set_cells(path, {("Engine", "mass", 3): '=1+"a"'})
    give_cached_value(path, "xl/worksheets/sheet3.xml", "A3", "#VALUE!", error=True)


def _link_without_hinges(wb):
    """Delete the rows of the Hinges sheet that hold link 'rear-right' (row 6 of the Links sheet)."""
    ws = wb["Hinges"]
    assert wb["Links"]["A6"].value == "rear-right"
    for row in range(ws.max_row, 2, -1):
        if "rear-right" in (ws.cell(row, 2).value, ws.cell(row, 3).value):
            ws.delete_rows(row)


def _no_pylon(wb):
    ws = wb["Hinges"]
    for row in range(3, ws.max_row + 1):
        for col in (2, 3):
            if ws.cell(row, col).value == "pylon":
                ws.cell(row, col).value = "engine"


def _chart_sheet_named_runs(wb):
    """A chart sheet named 'Runs' in place of the Runs sheet."""
    chart = BarChart()
    chart.add_data(Reference(wb["Hinges"], min_col=7, min_row=3, max_row=18))
    index = wb.sheetnames.index("Runs")
    wb.remove(wb["Runs"])
    wb.create_chartsheet("Runs", index).add_chart(chart)


def _cleared_header(wb):
    """The header of the optional column 'stiffness axial' cleared, its value in row 4 kept."""
    ws = wb["Hinges"]
    col = column_of(ws, "stiffness axial")
    ws.cell(1, col).value = None
    ws.cell(4, col).value = 5e7


def _values_beside_the_table(wb):
    ws = wb["Links"]
    col = ws.max_column + 2
    for row in (3, 5, 6):
        ws.cell(row, col, "spare part")
    ws.cell(4, col + 1, " ")    # shows nothing: not a value


BAD_INPUTS = {
    "missing sheet": (_edit_wb(lambda wb: wb.remove(wb["Hinges"])), ["sheet 'Hinges'"]),
    "missing column": (_edit_wb(lambda wb: wb["Hinges"].delete_cols(column_of(wb["Hinges"], "stiffness"))),
                       ["sheet 'Hinges'", "column 'stiffness'"]),
    "text in a number cell": (_edit({("Hinges", "stiffness", 4): "stiff"}), ["sheet 'Hinges'", "cell G4", "'stiff'",
                                                                             "a number"]),
    "empty required cell": (_edit({("Links", "name", 4): None}), ["sheet 'Links'", "cell A4", "a value"]),
    "zero mass": (_edit({("Engine", "mass", 3): 0}), ["sheet 'Engine'", "cell A3", "found 0"]),
    "negative mass": (_edit({("Engine", "mass", 3): -5}), ["sheet 'Engine'", "cell A3", "found -5"]),
    "negative stiffness": (_edit({("Hinges", "stiffness", 5): -2e7}), ["sheet 'Hinges'", "cell G5", "> 0"]),
    "zero stiffness": (_edit({("Hinges", "stiffness", 6): 0}), ["sheet 'Hinges'", "cell G6"]),
    "unknown unit": (_edit({("Links", "eye outer radius", 2): "mmm"}), ["sheet 'Links'", "cell M2", "'mmm'",
                                                                        "a known unit"]),
    "unit of the wrong dimension": (_edit({("Hinges", "stiffness", 2): "kg"}), ["cell G2", "'kg'", "stiffness"]),
    "hinge naming an unknown body": (_edit({("Hinges", "body B", 3): "front-lefty"}),
                                     ["sheet 'Hinges'", "cell C3", "'front-lefty'", "front-left"]),
    "duplicate link names": (_edit({("Links", "name", 4): "front-left"}), ["sheet 'Links'", "cell A4",
                                                                          "not used before (row 3)"]),
    "duplicate hinge names": (_edit({("Hinges", "name", 9): "front-up-left"}), ["sheet 'Hinges'", "cell A9"]),
    "hinge far from its link's eye": (_edit_wb(_move_hinge), ["sheet 'Hinges'", "cell D3:F3", "an eye centre",
                                                              "5 mm away"]),
    "missing mesh file": (_edit({("Links", "mesh file", 3): "meshes/front-left.msh"}),
                          ["sheet 'Links'", "cell AB3", "'meshes/front-left.msh'", "mesh file"]),
    "not an xlsx file": (_write_bytes(lambda p: b"name,mass\nengine,3568\n"),
                         ["case.xlsx", "22 bytes of text that are not a zip archive (a CSV or text file",
                          "save it as an .xlsx workbook"]),
    "corrupt zip": (_write_bytes(lambda p: p.read_bytes()[:3000]),
                    ["case.xlsx", "3000 bytes of an incomplete zip archive", "a complete Excel .xlsx"]),
    "an empty file": (_write_bytes(lambda p: b""), ["case.xlsx", "found 'an empty file (0 bytes)'"]),
    "an OpenDocument spreadsheet": (_write_bytes(_opendocument), ["case.xlsx", "an OpenDocument spreadsheet (.ods)",
                                                                  "Excel 2007-365 .xlsx"]),
    "a zip that is not a workbook": (_write_bytes(_zip_of_text), ["case.xlsx", "readable Excel .xlsx"]),
    "formula without a cached value": (_edit({("Engine", "mass", 3): "=3000+568"}),
                                       ["sheet 'Engine'", "cell A3", "'=3000+568'", "calculated value"]),
    "unknown material": (_edit({("Links", "material", 5): "unobtainium"}), ["cell I5", "steel, titanium"]),
    "bad yes/no": (_edit({("Links", "flexible", 3): "maybe"}), ["sheet 'Links'", "cell U3", "yes or no"]),
    "bad modes": (_edit({("Links", "modes", 3): "lots"}), ["sheet 'Links'", "cell T3", "mode count"]),
    "length not matching the ends": (_edit({("Links", "length", 3): 0.3}), ["sheet 'Links'", "cell H3",
                                                                            "distance between end A and end B"]),
    "bore larger than the eye": (_edit({("Links", "bore radius", 3): 45}), ["sheet 'Links'", "cell M3:Q3",
                                                                           "the bore radius (0.045 m)"]),
    "too few steps per period": (_edit({("Case", "steps per period", 3): 4}), ["sheet 'Case'", "cell C3",
                                                                               "at least 8"]),
    "unknown analysis method": (_edit({("Case", "method", 3): "fast"}), ["sheet 'Case'", "cell O3", "'fast'"]),
    "negative time budget": (_edit({("Case", "time budget", 3): -5}), ["sheet 'Case'", "cell M3", "found -5", "a number > 0"]),
    "two rows in the Case sheet": (_edit({("Case", "name", 4): "second"}), ["sheet 'Case'", "row 4"]),
    "misspelt column": (_edit({("Hinges", "damping", 1): "dampng"}), ["sheet 'Hinges'", "cell H1", "'dampng'"]),
    "negative frequency": (_edit({("Excitations", "frequency", 3): -59}), ["sheet 'Excitations'", "cell F3"]),
    "inertia not positive definite": (_edit({("Engine", "Ixy", 3): 5000}), ["sheet 'Engine'", "cell E3:J3",
                                                                            "positive definite"]),
    "sweep with a frequency": (_edit({("Excitations", "frequency", 5): 10}), ["sheet 'Excitations'", "cell F5",
                                                                             "sweep"]),
    "run of an unknown excitation": (_edit({("Runs", "excitation", 3): "IP rotor"}),
                                     ["sheet 'Runs'", "cell B3", "'IP rotor'", "LP rotor"]),
    "unknown fidelity": (_edit({("Runs", "fidelity", 4): "super"}), ["sheet 'Runs'", "cell E4", "rigid, static"]),
    "frequency override on a sweep": (_edit({("Runs", "frequency", 5): 100}), ["sheet 'Runs'", "cell C5"]),
    "negative gap": (_edit({("Runs", "gap", 3): -0.1}), ["sheet 'Runs'", "cell F3", ">= 0"]),
    "test data of an unknown run": (_edit({("Test data", "run", 3): "IP rotor", ("Test data", "direction", 3): "y",
                                           ("Test data", "amplitude", 3): 30}),
                                    ["sheet 'Test data'", "cell A3", "'IP rotor'"]),
    "no runs": (_edit_wb(lambda wb: wb["Runs"].delete_rows(3, 3)), ["sheet 'Runs'", "at least one run"]),
    "text in a polar-inertia cell": (_edit({**ROTOR_ROW, ("Rotors", "polar inertia", 3): "heavy"}),
                                     ["sheet 'Rotors'", "cell B3", "column 'polar inertia'", "'heavy'", "a number"]),
    "zero rotor speed": (_edit({**ROTOR_ROW, ("Rotors", "speed", 3): 0}), ["sheet 'Rotors'", "cell C3", "> 0"]),
    "unknown spin axis": (_edit({**ROTOR_ROW, ("Rotors", "spin axis", 3): "w"}),
                          ["sheet 'Rotors'", "cell D3", "'w'", "one of x, y, z"]),
    "duplicate rotor names": (_edit({**ROTOR_ROW, **{(sheet, header, 4): value for (sheet, header, _), value
                                                      in ROTOR_ROW.items()}}),
                              ["sheet 'Rotors'", "cell A4", "not used before (row 3)"]),
    "unknown unit of a rotor": (_edit({**ROTOR_ROW, ("Rotors", "polar inertia", 2): "kg*mmm"}),
                                ["sheet 'Rotors'", "cell B2", "'kg*mmm'", "a known unit"]),
    "negative transducer stiffness": (_edit({**RIG_ROW, ("Test rig", "stiffness y", 3): -1e8}),
                                      ["sheet 'Test rig'", "cell A3:C3", "column 'stiffness'", "-100000000",
                                       "three numbers > 0"]),
    "transducer stiffness of the wrong dimension": (_edit({**RIG_ROW, ("Test rig", "stiffness x", 2): "kg"}),
                                                    ["sheet 'Test rig'", "cell A2", "'kg'", "stiffness"]),
    "two rows in the Test rig sheet": (_edit({**RIG_ROW, **{(sheet, header, 4): value for (sheet, header, _), value
                                                             in RIG_ROW.items()}}),
                                       ["sheet 'Test rig'", "row 4", "exactly one row"]),
    "ambiguous text number": (_edit({("Engine", "mass", 3): "3,568"}),
                              ["sheet 'Engine'", "cell A3", "'3,568'", "3568 (',' separating thousands)",
                               "3.568 (',' as the decimal separator)"]),
    "ambiguous text number with a dot": (_edit({("Hinges", "stiffness", 4): "2.500"}),
                                         ["sheet 'Hinges'", "cell G4", "2500", "2.5"]),
    "merged cells": (_edit_wb(lambda wb: wb["Hinges"].merge_cells("B3:C5")),
                     ["sheet 'Hinges'", "cell B3:C5", "not merged"]),
    "number formatted as a date": (_edit_wb(_date_formatted_mass),
                                   ["sheet 'Engine'", "cell A3", "'3568 formatted as the date 1909-10-07'",
                                    "format it as a number"]),
    "formula error": (_formula_error, ["sheet 'Engine'", "cell A3", "'#VALUE!'", "formula error #VALUE!"]),
    "RPM": (_edit({("Excitations", "frequency", 2): "RPM"}), ["cell F2", "'RPM'", "did you mean 'rpm'?"]),
    "U/min": (_edit({("Excitations", "frequency", 2): "U/min"}), ["cell F2", "'U/min'", "did you mean 'rpm'?"]),
    "Ns/m": (_edit({("Hinges", "damping", 2): "Ns/m"}), ["cell H2", "'Ns/m'", "did you mean 'N*s/m'?"]),
    "a stray value in the last row": (_edit_wb(lambda wb: wb["Hinges"].cell(1048576, 1, "x")),
                                      ["sheet 'Hinges'", "cell A1048576", "'x'", "at most 10000 rows are read"]),
    "an .xls workbook": (_write_bytes(lambda p: compound_file({"Workbook": 4096})),
                         ["case.xlsx", "Excel 97-2003 workbook (.xls)", "save it as Excel Workbook .xlsx"]),
    "a password-protected workbook": (_write_bytes(lambda p: compound_file({"EncryptionInfo": 4096,
                                                                             "EncryptedPackage": 8192})),
                                      ["case.xlsx", "encrypted with a password", "without a password"]),
    "a rig record naming a device": (_edit({("Test data", "run", 3): "LP rotor", ("Test data", "rig record", 3): "/dev/zero"}),
                                     ["sheet 'Test data'", "'/dev/zero'", "not a regular file"]),
    "absurd hinge stiffness": (_edit({("Hinges", "stiffness", 4): 1e300}),
                               ["sheet 'Hinges'", "cell G4", "found 1e+300", "at most 1e+14 N/m"]),
    "absurd length in the wrong unit": (_edit({("Links", "end A x", 2): "km"}),
                                        ["sheet 'Links'", "cell B5", "found -1600 m", "at most 1000 m"]),
    "a link without hinges": (_edit_wb(_link_without_hinges),
                              ["sheet 'Links'", "cell B6:D6", "a hinge at end A of link 'rear-right'",
                               "cell E6:G6", "a hinge at end B of link 'rear-right'", "mechanism"]),
    "no hinge to the pylon": (_edit_wb(_no_pylon),
                              ["sheet 'Hinges'", "at least one hinge to the pylon"]),
    "bad rig sensors switch": (_edit({("Case", "rig sensors", 3): "sometimes"}),
                               ["sheet 'Case'", "cell V3", "yes or no"]),
    "negative loss factor": (_edit({("Hinges", "loss factor", 4): -0.1}),
                             ["sheet 'Hinges'", "cell K4", "column 'loss factor'", "found -0.1", ">= 0"]),
    "negative axial loss factor": (_edit({("Hinges", "loss factor axial", 5): -0.05}),
                                   ["sheet 'Hinges'", "cell Q5", "column 'loss factor axial'", "found -0.05", ">= 0"]),
    "zero axial stiffness": (_edit({("Hinges", "stiffness axial", 6): 0}),
                             ["sheet 'Hinges'", "cell M6", "column 'stiffness axial'", "> 0"]),
    "hinge frame not orthonormal": (_edit({("Hinges", "frame radial 1 x", 4): 1, ("Hinges", "frame radial 1 y", 4): 0,
                                           ("Hinges", "frame radial 1 z", 4): 0, ("Hinges", "frame axial x", 4): 0.5,
                                           ("Hinges", "frame axial y", 4): 0, ("Hinges", "frame axial z", 4): 1}),
                                    ["sheet 'Hinges'", "cell R4:W4", "orthonormal"]),
    "hinge frame with one direction": (_edit({("Hinges", "frame axial x", 4): 0, ("Hinges", "frame axial y", 4): 0,
                                              ("Hinges", "frame axial z", 4): 1}),
                                       ["sheet 'Hinges'", "cell R4:W4", "three"]),
    "negative link loss factor": (_edit({("Links", "loss factor", 3): -0.01}),
                                  ["sheet 'Links'", "cell AO3", "found -0.01", ">= 0"]),
    "link modal damping of one": (_edit({("Links", "modal damping", 3): 1.0}),
                                  ["sheet 'Links'", "cell AP3", "column 'modal damping'", "found 1", "< 1"]),
    "unknown time-domain start": (_edit({("Case", "start", 3): "sometimes"}),
                                  ["sheet 'Case'", "column 'start'", "sometimes", "steady"]),
    "negative element size": (_edit({("Links", "element size", 4): -1}),
                              ["sheet 'Links'", "cell R4", "column 'element size'", "found -1", "a mesh size > 0"]),
    "a run name typed as 1-2, made a date": (_edit({("Runs", "run", 4): datetime.datetime(2026, 1, 2)}),
                                            ["sheet 'Runs'", "cell A4", "found 'the date 2026-01-02'",
                                             "text, not a date", "format the cell as Text"]),
    "a number typed with its unit": (_edit({("Hinges", "stiffness", 4): "20 kN/mm"}),
                                     ["sheet 'Hinges'", "cell G4", "found '20 kN/mm'", "a number without its unit",
                                      "the unit, kN/mm, goes in the column's unit cell, row 2"]),
    "a chart sheet named Runs": (_edit_wb(_chart_sheet_named_runs),
                                 ["sheet 'Runs'", "found 'a chart sheet'", "a sheet of cells named 'Runs'"]),
    "a value under a cleared header": (_edit_wb(_cleared_header),
                                       ["sheet 'Hinges'", "cell M4", "found 50000000", "a column header in cell M1",
                                        "values would be ignored"]),
    "values in a column without a header": (_edit_wb(_values_beside_the_table),
                                            ["1 problem found", "sheet 'Links'", "cell AW3", "'spare part'", "cell AW1",
                                             "2 more cells below it", "starting with '#'"]),
    "zero element size": (_edit({("Links", "element size", 3): 0}),
                          ["sheet 'Links'", "cell R3", "column 'element size'", "found 0", "a mesh size > 0"]),
}


@pytest.mark.parametrize("name", list(BAD_INPUTS))
def test_bad_input(tmp_path, capsys, name):
    change, expected = BAD_INPUTS[name]
    path = copy_reference(tmp_path)
    change(path)
    before, files = sha256(path), sorted(tmp_path.iterdir())
    assert main(["check", str(path)]) == 2
    message = capsys.readouterr().err
    for text in expected:
        assert text in message, f"{name}: {text!r} not in\n{message}"
    assert main(["run", str(path), "--no-progress"]) == 2
    assert sha256(path) == before, "the input was changed"
    assert sorted(tmp_path.iterdir()) == files, "a file was written"


def test_every_problem_is_reported_at_once(tmp_path):
    path = copy_reference(tmp_path)
    set_cells(path, {("Engine", "mass", 3): "heavy", ("Hinges", "stiffness", 2): "kg",
                     ("Links", "name", 5): "front-left", ("Runs", "fidelity", 3): "super"})
    with pytest.raises(WorkbookError) as error:
        read_workbook(path)
    cells = {(p.sheet, p.cell) for p in error.value.problems}
    assert {("Engine", "A3"), ("Hinges", "G2"), ("Links", "A5")} <= cells
    # the run sheet is checked against the case once the case is valid
    set_cells(path, {("Engine", "mass", 3): 3568, ("Hinges", "stiffness", 2): "N/m", ("Links", "name", 5): "rear-left"})
    with pytest.raises(WorkbookError) as error:
        read_workbook(path)
    assert [(p.sheet, p.cell) for p in error.value.problems] == [("Runs", "E3")]


def test_check_passes_the_shipped_workbooks(capsys):
    for path in (REFERENCE, TEMPLATE):
        assert main(["check", str(path)]) == 0
    assert "OK - case 'reference mount': 8 links, 16 hinges" in capsys.readouterr().out


def test_run_overrides(tmp_path):
    path = tmp_path / "template.xlsx"
    path.write_bytes(TEMPLATE.read_bytes())
    set_cells(path, {("Runs", "hinge stiffness", 2): "kN/mm", ("Runs", "hinge stiffness", 5): 35,
                     ("Runs", "amplitude", 5): 1.5, ("Runs", "amplitude", 2): "kN"})
    book = read_workbook(path)
    case = {run.name: book.run_case(run) for run in book.runs}
    rigid = case["LP rotor, rigid links"]
    assert not rigid.effects.flexible_links and [e.name for e in rigid.excitations] == ["LP rotor"]
    assert {link.modes for link in case["HP rotor, 20 modes"].links} == {20}
    assert case["HP rotor, 20 modes"].effects.flexible_links
    assert [h.radial_clearance for h in case["LP rotor, 0.05 mm gap"].hinges] == pytest.approx([5e-5] * 16, rel=1e-12)
    assert case["LP rotor at 4000 rpm"].excitations[0].frequency == pytest.approx(4000 / 60, rel=1e-12)
    sweep = case["sweep"].excitations[0]
    assert len(sweep.frequencies_hz) == 25 and sweep.frequencies_hz[0] == pytest.approx(5.0)
    overridden = case["sweep"]
    assert {h.stiffness for h in overridden.hinges} == {3.5e7}
    assert {e.force_amplitude for e in overridden.single_frequency_excitations()} == {1500.0}
    assert {h.stiffness for h in case["LP rotor"].hinges} == {2.0e7}


def test_mesh_link_and_missing_geometry_column(tmp_path):
    path = copy_reference(tmp_path)
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "front-left.inp").write_text("*NODE\n")
    set_cells(path, {("Links", "mesh file", 3): "meshes/front-left.inp", ("Links", "mesh unit", 3): "mm",
                     ("Links", "bore A node set", 3): "BORE_A", ("Links", "bore B node set", 3): "BORE_B",
                     ("Hinges", "body A", 3): "Pylon",
                     **{("Links", header, 3): None for header in ("eye outer radius", "eye thickness", "shank width",
                                                                 "shank thickness")}})
    case = read_workbook(path).case
    mesh = case.links[0].model.mesh
    assert case.links[0].model.geometry is None and case.hinges[0].body_a == "pylon"
    assert mesh.path == str(tmp_path / "meshes" / "front-left.inp") and mesh.scale == pytest.approx(1e-3)
    assert [b.node_set for b in mesh.bores] == ["BORE_A", "BORE_B"]
    # a geometric bore needs its centre, axis and radius; the parametric links need their sizes
    set_cells(path, {("Links", "bore B node set", 3): None})
    wb = load_workbook(path)
    wb["Links"].delete_cols(column_of(wb["Links"], "eye thickness"))
    wb.save(path)
    with pytest.raises(WorkbookError) as error:
        read_workbook(path)
    messages = [str(p) for p in error.value.problems]
    assert sum("column 'eye thickness'" in m for m in messages) == 1
    assert any("cell AH3, column 'mesh bore B x'" in m and "bore B of a mesh link" in m for m in messages)


def test_the_case_sheet_chooses_the_analysis_method(tmp_path):
    from workbook.excel.reader import read_workbook

    path = copy_reference(tmp_path)
    assert read_workbook(path).case.analysis.method == "auto"
    set_cells(path, {("Case", "method", 3): "time"})
    assert read_workbook(path).case.analysis.method == "time"


@pytest.mark.parametrize("text, mass", [("3568", 3568.0), ("3 568", 3568.0), ("3568,5", 3568.5), ("3.568,5", 3568.5),
                                        ("3,568.5", 3568.5), ("0,5", 0.5), ("1,234,567", 1234567.0)])
def test_text_numbers_with_one_reading_are_read(tmp_path, text, mass):
    path = copy_reference(tmp_path)
    set_cells(path, {("Engine", "mass", 3): text})
    assert read_workbook(path).case.engine.mass == mass


def test_invisible_characters_pasted_into_cells_are_read_as_the_cells_show(tmp_path):
    """A zero-width space, a byte-order mark or a soft hyphen (pasted from a web page or a PDF) is not part of
    the name, header, choice or number the cell shows: the hinges still find their link."""
    path = copy_reference(tmp_path)
    set_cells(path, {("Links", "name", 3): "front-left\u200b", ("Links", "name", 4): "\ufefffront-right",
                     ("Links", "name", 5): "rear-\u00adleft", ("Hinges", "stiffness", 1): "stiff\u200bness",
                     ("Excitations", "type", 3): "rotating\u200e", ("Engine", "mass", 3): "3568\u200b"})
    assert to_dict(read_workbook(path).case) == to_dict(read_workbook(REFERENCE).case)


@pytest.mark.parametrize("name, named", [("case.ods", "an OpenDocument spreadsheet"), ("case.csv", "a CSV table"),
                                         ("case.xls", "an Excel 97-2003 workbook")])
def test_a_spreadsheet_of_another_kind_is_named_by_run(tmp_path, capsys, name, named):
    path = tmp_path / name
    path.write_bytes(_opendocument(path) if name.endswith(".ods") else b"name,mass\nengine,3568\n")
    assert main(["run", str(path), "--no-progress"]) == 2
    assert f"{named} is not read as a case; save it as an Excel workbook (.xlsx)" in capsys.readouterr().err
    assert sorted(tmp_path.iterdir()) == [path]
