"""Write case workbooks: the template (templates/) and ready cases (cases/).

Both are generated from a :class:`~workbook.model.case.Case` and its runs with the
sheet layout of :mod:`workbook.excel.layout`; the committed files are what
this module writes (a test keeps them equal). Each quantity is written in
the column's display unit (mm for link sizes, GPa for moduli) when that
reads back to the identical number, else in SI.
"""
from __future__ import annotations

import dataclasses
import datetime
from pathlib import Path
from typing import Any, Iterable

import numpy as np
from openpyxl import Workbook
from openpyxl.styles import Alignment, Font, PatternFill
from openpyxl.utils import get_column_letter
from openpyxl.worksheet.datavalidation import DataValidation

import workbook.excel.layout as L
from flexbodies.materials import STRENGTH_FIELDS
from workbook.errors import UnwritableCase
from workbook.excel.files import new_file_target, save_atomic
from workbook.excel.optimise_sheet import OptimiseSheet, optimise_rows
from workbook.excel.runs import RunSpec, TestPoint
from workbook.excel.styling import print_setup
from workbook.model import case as cm
from workbook.model.casing import DEFAULT_CORE_SPIN_HZ
from workbook.model.load_cases import LoadCase, reference_load_cases
from workbook.model.units import si_factor

__all__ = ["case_rows", "case_workbook", "template_workbook", "reference_workbook", "write_workbook",
           "TEMPLATE_RUNS", "REFERENCE_RUNS"]

#: Fixed creation date: generated files depend on the code only.
_CREATED = datetime.datetime(2026, 1, 1)
_HEADER_FILL = PatternFill("solid", fgColor="DDEBF7")
_UNIT_FILL = PatternFill("solid", fgColor="F2F2F2")
#: Rows of the template that get the drop-down lists.
_VALIDATED_ROWS = 500

#: The seed study's runs (cases/reference.xlsx).
REFERENCE_RUNS = (RunSpec("LP rotor", "LP rotor"), RunSpec("HP rotor", "HP rotor"), RunSpec("sweep", "sweep"))
#: Example runs of the template: the seed runs and some overrides.
TEMPLATE_RUNS = REFERENCE_RUNS + (
    RunSpec("LP rotor, rigid links", "LP rotor", fidelity="rigid"),
    RunSpec("HP rotor, 20 modes", "HP rotor", fidelity=20),
    RunSpec("LP rotor, 0.05 mm gap", "LP rotor", gap=5e-5),
    RunSpec("LP rotor at 4000 rpm", "LP rotor", frequency=4000 / 60),
)

#: The Instructions sheet, one cell per line.
_INSTRUCTIONS = (
    "Engine Mount Workbook: case workbook",
    "One sheet per input table. Row 1: column headers. Row 2: the unit of each column. "
    "Rows 3 on: one item per row.",
    "Units: write any unit of the right kind in row 2 (mm, m, kN, t, kN/mm, rpm, GPa, ...); "
    "values are converted to SI on reading.",
    "'g' is standard gravity (9.80665 m/s^2) in an acceleration column and gram everywhere else "
    "(e.g. an unbalance in g*mm).",
    "Frequencies count cycles: 1 rpm = 1/60 Hz. A column without dimension takes '-' (or '%').",
    "Axes: x heading (along the engine axis, forward), y lateral, z vertical (up). "
    "Bodies: 'pylon' (ground), 'engine' or a link name.",
    "A hinge joins two bodies at a point; on a link that point must be one of the link's eye centres.",
    "Vectors take three columns (x, y, z). Empty optional cells take the default. "
    "Columns headed '#...' are your notes.",
    "A link is parametric (eye and shank sizes) or a mesh file (path relative to this workbook) "
    "with its two bores: node sets or centre, axis and bore radius.",
    "Formulas are allowed: the values Excel last calculated are read (save the file from Excel).",
    "Runs: each row runs one excitation; the other columns override the case for that run "
    "(frequency, amplitude, fidelity, gap, stiffness, ...).",
    "Fidelity: rigid (every link rigid), static (static modes only), auto (the low-frequency rule), "
    "a mode count, or a cut-off such as '2000 Hz'.",
    "Rotors and Test rig (optional, empty: none): spinning rotors whose gyroscopic moments act on the engine, "
    "and the rig's force transducers under the pylon pins; 'gyroscopics' and 'rig sensors' in Case switch them off.",
    "Load cases (optional): limit loads (thrust, load factors in g, torque, a point force and a moment, factor of "
    "safety, a fail-safe link); a run then writes 'Result loads': link forces, stresses and margins of safety.",
    "Links: yield, ultimate and endurance strength columns override the material preset's.",
    "Test data: measured force amplitudes (pylon sum or a hinge, per direction); "
    "the results show error = (sim - test) / test x 100 %.",
    "Optimise (optional, empty: none): the design optimisation 'mountwb optimise CASE.xlsx' runs, one row per "
    "variable (a study parameter with low and high, e.g. hinge_stiffness/front or section_scale), constraint, "
    "speed band, objective or starts; SI units. A run never optimises.",
    "Check a workbook:  mountwb check CASE.xlsx     "
    "Run it:  mountwb run CASE.xlsx [--run NAME] [--report REPORT.xlsx]",
    "A run writes sheets named 'Result ...' back into the workbook and never changes the input sheets.",
    "The rows below list every column.",
)


def _display(value: float, factor: float) -> float:
    return value / factor


def _row_for_link(link: cm.Link) -> dict:
    model = link.model
    if model.geometry is None:
        raise UnwritableCase(f"link {link.name!r}: only parametric links can be written (a mesh link is written by hand)")
    import flexbodies

    row = {"name": link.name, **_vector("end_a", link.end_a), **_vector("end_b", link.end_b),
           "element_size": model.element_size, "interface": model.interface, "modes": link.modes,
           "flexible": link.flexible, "stiffness_damping": link.stiffness_damping,
           "mass_damping": link.mass_damping, "spin_frequency_hz": link.spin_frequency_hz,
           "loss_factor": link.loss_factor or None, "modal_damping": link.modal_damping or None}
    row.update({key: getattr(model.geometry, key) for key in
                ("eye_outer_radius", "bore_radius", "thickness", "shank_width", "shank_thickness")})
    if model.material.haigh_curve is not None:
        raise UnwritableCase(f"link {link.name!r}: the Haigh curve of material {model.material.name!r} has no Links "
                             "column (a case with one is kept as a case file)")
    base = flexbodies.material(model.material.name.split(" ")[0])
    row["material"] = base.name
    row.update({key: getattr(model.material, key) for key in ("youngs_modulus", "poisson_ratio", "density",
                                                               *STRENGTH_FIELDS)
                if getattr(model.material, key) != getattr(base, key)})
    if link.bore_axis is not None:
        row.update(_vector("bore_axis", link.bore_axis))
    return row


def _vector(key: str, values) -> dict:
    return {f"{key}_{axis}": value for axis, value in zip("xyz", values, strict=True)}


def _rows_for_excitation(excitation: cm.Excitation) -> list[dict]:
    """The Excitations rows of one excitation: one row, or one per imbalance plane
    (the first with the speed, the axis and any sweep or run-up)."""
    row: dict[str, Any] = {"name": excitation.name}
    if isinstance(excitation, cm.Simultaneous):
        raise UnwritableCase(f"excitation {excitation.name!r}: simultaneous excitations have no Excitations row; "
                             f"run them from Python or a JSON case")
    if isinstance(excitation, cm.RunUp):
        f = excitation.frequencies_hz
        row.update(sweep_from=f[0], sweep_to=f[-1], sweep_points=len(f), run_up=excitation.speed_unit)
        template = excitation.template
    elif isinstance(excitation, cm.Sweep):
        f = excitation.frequencies_hz
        spacing = next((name for name, space in (("log", np.geomspace), ("linear", np.linspace))
                        if np.allclose(space(f[0], f[-1], len(f)), f, rtol=1e-12)), None)
        if spacing is None:
            raise UnwritableCase(f"excitation {excitation.name!r}: only log or linear sweeps can be written")
        row.update(sweep_from=f[0], sweep_to=f[-1], sweep_points=len(f), sweep_spacing=spacing)
        template = excitation.template
    else:
        template = excitation
        row["frequency"] = excitation.frequency
    if isinstance(template, (cm.RotatingForce, cm.Imbalance)) and template.axis != (1.0, 0.0, 0.0):
        row.update(_vector("axis", template.axis))
    if isinstance(template, cm.Imbalance):
        return [{**(row if k == 0 else {"name": excitation.name}), "type": "imbalance plane",
                 **_vector("point", plane.point), "amplitude": plane.amplitude, "unbalance": plane.unbalance,
                 "phase": plane.phase_deg or None} for k, plane in enumerate(template.planes)]
    row.update(**_vector("point", template.point), phase=template.phase_deg or None)
    if isinstance(template, cm.RotatingForce):
        row.update(type="rotating", amplitude=template.amplitude, unbalance=template.unbalance)
    else:
        row.update(type="harmonic", amplitude=template.amplitude, **_vector("direction", template.direction))
    return [row]


def _row_for_load(load: cm.StaticLoad) -> dict:
    if isinstance(load, cm.PointForce):
        return {"name": load.name, "type": "force", **_vector("force", load.force), **_vector("point", load.point)}
    if isinstance(load, cm.PointMoment):
        return {"name": load.name, "type": "moment", **_vector("moment", load.moment)}
    return {"name": load.name, "type": "gravity", **_vector("acceleration", load.acceleration)}


def _row_for_load_case(load_case: LoadCase) -> dict:
    """A Load cases row: its extra point force and moment, at most one of each, are named by the sheet."""
    if len(load_case.forces) > 1 or len(load_case.moments) > 1:
        raise UnwritableCase(f"load case {load_case.name!r}: a Load cases row holds one extra force and one moment; "
                             "a load case with more is given in Python or JSON")
    row = {"name": load_case.name, "description": load_case.description or None, "thrust": load_case.thrust or None,
           **_vector("load_factors", load_case.load_factors), "torque": load_case.torque or None,
           "factor_of_safety": load_case.factor_of_safety, "without_link": load_case.without_link}
    if load_case.thrust_point is not None:
        row.update(_vector("thrust_point", load_case.thrust_point))
    for force in load_case.forces:
        row.update(**_vector("force", force.force), **_vector("force_point", force.point))
    for moment in load_case.moments:
        row.update(_vector("moment", moment.moment))
    return row


def _row_for_rotor(rotor: cm.Rotor) -> dict:
    axis = {vector: letter for letter, vector in L.AXES.items()}.get(rotor.axis)
    if axis is None:
        raise UnwritableCase(f"rotor {rotor.name!r}: only rotors spinning about +x, +y or +z can be written")
    return {"name": rotor.name, "polar_inertia": rotor.polar_inertia, "frequency_hz": rotor.frequency, "axis": axis}


def _rows_for_test_rig(rig: cm.ForceTransducers | None) -> list[dict]:
    if rig is None:
        return []
    return [{**_vector("stiffness", rig.stiffness), "mass": rig.mass, **_vector("damping", rig.damping)}]


def _rows_for_casing(casing) -> list[dict]:
    """The Engine casing row of a parametric casing (none for a rigid engine)."""
    import flexbodies

    if casing is None:
        return []
    g = casing.geometry
    if g is None:
        raise UnwritableCase("engine casing: only a parametric casing can be written (a mesh casing is written by hand)")
    if len(g.rings) > len(L.CASING_RINGS) or len(casing.bearing_planes) > len(L.CASING_BEARINGS):
        raise UnwritableCase(f"engine casing: at most {len(L.CASING_RINGS)} rings and {len(L.CASING_BEARINGS)} bearing "
                             "planes can be written")
    if any(casing.bearing_damping) or casing.core_spin_hz != DEFAULT_CORE_SPIN_HZ:
        raise UnwritableCase("engine casing: bearing damping and a core spin frequency other than the default have no "
                             "column; such a casing is given in Python or JSON")
    base = flexbodies.material(casing.material.name.split(" ")[0])
    radial, axial = casing.bearing_stiffness
    row = {"radius": g.radius, "thickness": g.thickness, "x_start": g.x_start, "x_end": g.x_end,
           **{f"{key}_{name}": value for key, ring in zip(L.CASING_RINGS, g.rings, strict=False)
              for name, value in (("x", ring.x), ("width", ring.width), ("radius", ring.outer_radius))},
           **dict(zip(L.CASING_BEARINGS, casing.bearing_planes, strict=False)), "material": base.name,
           **{key: getattr(casing.material, key) for key in ("youngs_modulus", "poisson_ratio", "density")
              if getattr(casing.material, key) != getattr(base, key)},
           "element_size": casing.element_size, "spider_radius": casing.spider_radius,
           "bearing_band": casing.bearing_band, "bearing_radial": radial, "bearing_axial": axial,
           "modal_damping": casing.modal_damping, "modes": casing.modes}
    return [row]


def _per_direction(hinge: cm.Hinge, key: str) -> dict:
    """A hinge's *key* as one cell, or three (radial 1 in *key*, then radial 2 and axial)."""
    values = hinge.values(key)
    row = {key: float(values[0])}
    if np.ptp(values) > 0:
        row.update({f"{key}_radial_2": float(values[1]), f"{key}_axial": float(values[2])})
    return row


def _frame(hinge: cm.Hinge) -> dict:
    """A hinge's own frame as its radial 1 and axial directions (none: empty)."""
    if hinge.frame is None:
        return {}
    return {**_vector("frame_radial_1", hinge.frame[0]), **_vector("frame_axial", hinge.frame[2])}


def case_rows(case: cm.Case, runs: Iterable[RunSpec], tests: Iterable[TestPoint] = (),
              optimise: OptimiseSheet | None = None) -> dict[str, list[dict]]:
    """The rows of every input sheet (values in SI, by column key) for *case* (and the Optimise sheet's for the
    problem *optimise*; None: no row)."""
    inertia = case.engine.inertia
    settings = {"name": case.name, "description": case.description or None,
                **dataclasses.asdict(case.analysis), **dataclasses.asdict(case.effects)}
    engine = {"mass": case.engine.mass, **_vector("cg", case.engine.center_of_mass),
              **{f"i{a}{b}": inertia[i][j] for (a, i), (b, j) in
                 ((("x", 0), ("x", 0)), (("y", 1), ("y", 1)), (("z", 2), ("z", 2)),
                  (("x", 0), ("y", 1)), (("x", 0), ("z", 2)), (("y", 1), ("z", 2)))}}
    hinges = [{"name": h.name, "body_a": h.body_a, "body_b": h.body_b, **_vector("position", h.position),
               **_per_direction(h, "stiffness"), **_per_direction(h, "damping"),
               "radial_clearance": h.radial_clearance or None, "contact_stiffness": h.contact_stiffness,
               **_per_direction(h, "loss_factor"), **_frame(h)} for h in case.hinges]
    return {
        L.CASE.sheet: [settings], L.ENGINE.sheet: [engine],
        L.LINKS.sheet: [_row_for_link(link) for link in case.links],
        L.HINGES.sheet: hinges,
        L.STATIC_LOADS.sheet: [_row_for_load(load) for load in case.static_loads],
        L.EXCITATIONS.sheet: [row for e in case.excitations for row in _rows_for_excitation(e)],
        L.LOAD_CASES.sheet: [_row_for_load_case(load_case) for load_case in case.load_cases],
        L.SPEED_SPECTRUM.sheet: [{"excitation": spectrum.excitation, "speed_hz": band.speed_hz, "to_hz": band.to_hz,
                                  "hours": band.hours} for spectrum in case.speed_spectra for band in spectrum.bands],
        L.ROTORS.sheet: [_row_for_rotor(rotor) for rotor in case.rotors],
        L.TEST_RIG.sheet: _rows_for_test_rig(case.test_rig),
        L.CASING.sheet: _rows_for_casing(case.engine.casing),
        L.RUNS.sheet: [dataclasses.asdict(run) for run in runs],
        L.TEST_DATA.sheet: [dataclasses.asdict(point) for point in tests],
        L.OPTIMISE.sheet: [] if optimise is None else optimise_rows(optimise),
    }


def _column_unit(column: L.Column, values: list) -> tuple[str | None, float]:
    """Unit text and factor of a column: the display unit if every value reads back identically."""
    if not column.has_unit or column.kind != "number":
        return column.template_unit, 1.0
    factor = si_factor(column.template_unit, column.si_unit)
    if all(_display(v, factor) * factor == v for v in values if v is not None):
        return column.template_unit, factor
    return column.si_unit, 1.0


def _cell_value(column: L.Column, value, factor: float):
    if value is None:
        return None
    if column.kind == "yesno":
        return L.YES if value else L.NO
    if column.kind in ("modes", "fidelity") and isinstance(value, float):
        return f"{value:g} Hz"
    if column.kind == "number":
        return _display(value, factor)
    return value


def _write_table(ws, table: L.Table, rows: list[dict]) -> None:
    for col, column in enumerate(table.columns, start=1):
        values = [row.get(column.key) for row in rows]
        unit, factor = _column_unit(column, values)
        header = ws.cell(L.HEADER_ROW, col, column.header)
        header.font, header.fill = Font(bold=True), _HEADER_FILL
        unit_cell = ws.cell(L.UNIT_ROW, col, unit or None)
        unit_cell.font, unit_cell.fill = Font(italic=True, color="595959"), _UNIT_FILL
        for row, value in enumerate(values, start=L.FIRST_DATA_ROW):
            ws.cell(row, col, _cell_value(column, value, factor))
        ws.column_dimensions[get_column_letter(col)].width = max(10, len(column.header) + 3)
        if column.drop_down:
            letter = get_column_letter(col)
            validation = DataValidation(type="list", formula1='"' + ",".join(column.drop_down) + '"',
                                        allow_blank=True, showErrorMessage=True,
                                        errorTitle=column.header, error="Choose from the list")
            validation.add(f"{letter}{L.FIRST_DATA_ROW}:{letter}{_VALIDATED_ROWS}")
            ws.add_data_validation(validation)
    ws.freeze_panes = ws.cell(L.FIRST_DATA_ROW, 2)
    print_setup(ws, header_rows=L.UNIT_ROW, freeze=False)


def _write_instructions(ws) -> None:
    for row, line in enumerate(_INSTRUCTIONS, start=1):
        ws.cell(row, 1, line).font = Font(bold=row == 1, size=14 if row == 1 else 11)
    row = len(_INSTRUCTIONS) + 2
    for col, text in enumerate(("sheet", "column", "unit", "kind", "required", "meaning"), start=1):
        ws.cell(row, col, text).font = Font(bold=True)
    for table in L.TABLES:
        row += 1
        ws.cell(row, 1, table.sheet).font = Font(bold=True)
        ws.cell(row, 6, table.help + (" (optional sheet)" if table.optional else ""))
        for column in table.columns:
            row += 1
            kind = "/".join(column.drop_down) if column.drop_down else column.kind
            for col, text in enumerate((table.sheet, column.header, column.template_unit, kind,
                                        "yes" if column.required else "", column.help), start=1):
                ws.cell(row, col, text or None)
    for letter, width in zip("ABCDEF", (14, 22, 10, 22, 9, 90), strict=True):
        ws.column_dimensions[letter].width = width
    ws.cell(1, 1).alignment = Alignment(vertical="top")
    print_setup(ws)


def case_workbook(case: cm.Case, runs: Iterable[RunSpec], tests: Iterable[TestPoint] = (),
                  optimise: OptimiseSheet | None = None) -> Workbook:
    """A case workbook: Instructions plus one sheet per input table holding *case*.

    Parameters
    ----------
    case : Case
        Parametric links only.
    runs : iterable of RunSpec
    tests : iterable of TestPoint
    optimise : OptimiseSheet, optional
        The design optimisation its Optimise sheet holds (None: the sheet empty).

    Returns
    -------
    openpyxl.Workbook
    """
    rows = case_rows(case, runs, tests, optimise)
    workbook = Workbook()
    workbook.properties.created = _CREATED
    workbook.properties.creator = "mountwb"
    _write_instructions(workbook.active)
    workbook.active.title = L.INSTRUCTIONS_SHEET
    for table in L.TABLES:
        _write_table(workbook.create_sheet(table.sheet), table, rows[table.sheet])
    return workbook


def template_workbook() -> Workbook:
    """The case template: the reference mount as example rows, with example runs, the reference load cases and
    speed spectra."""
    from workbook.model.reference import reference_case
    from workbook.model.spectrum import reference_speed_spectra

    return case_workbook(dataclasses.replace(reference_case(sweep=True), load_cases=reference_load_cases(),
                                             speed_spectra=reference_speed_spectra()), TEMPLATE_RUNS)


def reference_workbook() -> Workbook:
    """cases/reference.xlsx: the reference mount with the seed study's runs."""
    from workbook.model.reference import reference_case

    return case_workbook(reference_case(sweep=True), REFERENCE_RUNS)


def write_workbook(workbook: Workbook, path: str | Path, replace: bool = False):
    """Save a generated workbook (atomically); an existing file is replaced only if *replace*.

    Returns
    -------
    (Path, str or None)
        The file written (*path*, or a new name beside an existing *path*)
        and the reason it is not *path* (None: it is).
    """
    target, reason = new_file_target(path, "template", lambda _: replace)
    return save_atomic(workbook, target), reason
