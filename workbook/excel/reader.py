"""Read a case workbook into a :class:`~workbook.model.case.Case`, its runs and test data.

Every problem found is collected and raised at once in one
:class:`~workbook.excel.sheets.WorkbookError`. Nothing here runs a simulation
or imports Exudyn: checking a workbook is fast.
"""
from __future__ import annotations

import dataclasses
import hashlib
import logging
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, cast

import numpy as np

import workbook.excel.layout as L
from workbook.answers.results import PYLON_SUM
from workbook.errors import WorkbookError
from workbook.excel.files import bounded_file_problem
from workbook.excel.impedance_sheet import SHEET as IMPEDANCE_SHEET
from workbook.excel.impedance_sheet import with_impedance_sheet
from workbook.excel.optimise_sheet import OptimiseSheet, read_optimise_sheet
from workbook.excel.runs import RunSpec, TestPoint, case_for_run
from workbook.excel.sheets import OpenedWorkbook, Record, SheetReader, open_workbook, read_workbook_bytes
from workbook.model import case as cm
from workbook.model.casing import DEFAULT_BEARING_STIFFNESS, CasingGeometry, EngineCasing, MountRing
from workbook.model.load_cases import LoadCase
from workbook.model.spectrum import SpeedBand, SpeedSpectrum, check_speed_spectra

__all__ = ["CaseBook", "read_workbook"]

log = logging.getLogger(__name__)

#: Largest mesh file read, bytes.
MAX_MESH_BYTES = 500_000_000


@dataclass(frozen=True)
class CaseBook:
    """What a case workbook holds.

    Attributes
    ----------
    path : Path
    case : Case
    runs : tuple of RunSpec
    tests : tuple of TestPoint
    sha256 : str
        Hash of the file's bytes.
    opened : OpenedWorkbook or None
        The workbook as read, for :func:`~workbook.excel.writer.write_results` (which then does not
        open the file again).
    optimise : OptimiseSheet or None
        The Optimise sheet's problem (None: no such sheet or no rows).
    """

    path: Path
    case: cm.Case
    runs: tuple
    tests: tuple
    sha256: str
    opened: OpenedWorkbook | None = dataclasses.field(default=None, compare=False, repr=False)
    optimise: OptimiseSheet | None = None

    def run_case(self, run: RunSpec) -> cm.Case:
        """The case of one run (see :func:`~workbook.excel.runs.case_for_run`)."""
        return case_for_run(self.case, run)


# -- items ----------------------------------------------------------------------------------------------------

_GEOMETRY_KEYS = ("eye_outer_radius", "bore_radius", "thickness", "shank_width", "shank_thickness")
#: Material columns overriding the preset (the strengths are in the Links sheet only).
_STRENGTH_KEYS = ("yield_strength", "ultimate_strength", "endurance_strength", "endurance_cycles", "fatigue_exponent")
_MATERIAL_KEYS = ("youngs_modulus", "poisson_ratio", "density", *_STRENGTH_KEYS)
#: A Load cases row's load factors when their cells are empty: 1 g level flight.
_LOAD_FACTORS = (0.0, 0.0, -1.0)
#: Columns of a parametric link's or casing's geometry, which a mesh file replaces (a mesh link's bores take
#: 'bore radius' too).
_LINK_SHAPE_KEYS = tuple(key for key in _GEOMETRY_KEYS if key != "bore_radius")
_CASING_SHAPE_KEYS = ("radius", "thickness", "x_start", "x_end",
                      *(f"{ring}_{part}" for ring in L.CASING_RINGS for part in ("x", "width", "radius")))
#: Case-model field -> columns, where the names differ.
_FIELD_COLUMNS: dict[str, dict[str, tuple[str, ...]]] = {
    "Engine": {"center_of_mass": ("cg_x", "cg_y", "cg_z"),
               "inertia": ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")},
    "Engine casing": {"geometry": ("radius", "thickness", "x_start", "x_end"), "geometry.radius": ("radius",),
                      "geometry.thickness": ("thickness",), "geometry.x_start": ("x_start",),
                      "geometry.x_end": ("x_start", "x_end"),
                      **{f"geometry.rings[{k}]": (f"{ring}_x", f"{ring}_width", f"{ring}_radius")
                         for k, ring in enumerate(L.CASING_RINGS)},
                      "bearing_planes": L.CASING_BEARINGS, "mesh": ("mesh_file",), "scale": ("mesh_unit",),
                      **{f"bearing_planes[{k}]": (key,) for k, key in enumerate(L.CASING_BEARINGS)},
                      "bearing_stiffness": ("bearing_radial", "bearing_axial")},
    "Excitations": {"frequency_hz": ("frequency",), "rpm": ("frequency",), "phase_deg": ("phase",),
                    "frequencies_hz": ("sweep_from", "sweep_to"), "spacing": ("sweep_spacing",),
                    "start": ("sweep_from",), "stop": ("sweep_to",), "points": ("sweep_points",),
                    "speed_unit": ("run_up",)},
    "Hinges": {**{f"{key}[{direction}]": (key if direction == cm.HINGE_DIRECTIONS[0] else
                                          f"{key}_{direction.replace(' ', '_')}",)
                  for key in ("stiffness", "damping", "loss_factor") for direction in cm.HINGE_DIRECTIONS},
               "frame": (*L.HINGES.vector_keys("frame_radial_1"), *L.HINGES.vector_keys("frame_axial"))},
    "Load cases": {"point": L.LOAD_CASES.vector_keys("force_point")},
    "Links": {f"material.{key}": (key,) for key in _STRENGTH_KEYS},
    "Runs": {"frequency_hz": ("frequency",), "rpm": ("frequency",), "radial_clearance": ("gap",),
             "stiffness": ("hinge_stiffness",), "damping": ("hinge_damping",), "modes": ("fidelity",)},
}
#: Item kind in a CaseError of the Case constructor -> its table.
_ITEM_TABLES = {"link": L.LINKS, "hinge": L.HINGES, "static load": L.STATIC_LOADS, "excitation": L.EXCITATIONS,
                "rotor": L.ROTORS, "load case": L.LOAD_CASES}
_ITEM = re.compile(rf"^({'|'.join(_ITEM_TABLES)}) '(.*)'$")
_SPECTRUM_ITEM = re.compile(r"^speed spectrum '(.*)'$")
#: Item of a CaseError about the engine's casing (the Engine casing sheet's one row).
_CASING_ITEM = "engine casing"


def _field_keys(table: L.Table, field: str) -> tuple:
    """Columns holding case-model *field* in *table*."""
    aliases = _FIELD_COLUMNS.get(table.sheet, {})
    if field in aliases:
        return aliases[field]
    keys = {c.key for c in table.columns}
    if field in keys:
        return (field,)
    vector = table.vector_keys(field)
    return vector if vector[0] in keys else ()


def _hinge_frame(record: Record) -> tuple | None:
    """A hinge's frame from its radial 1 and axial direction columns (radial 2 = axial x radial 1),
    None when both are empty; what cannot be a direction is passed on for the case to name."""
    radial, axial = record.vector("frame_radial_1"), record.vector("frame_axial")
    if radial is None and axial is None:
        return None
    empty = (None, None, None)
    try:
        middle = tuple(np.cross(np.asarray(axial, dtype=float), np.asarray(radial, dtype=float)))
    except (TypeError, ValueError):
        middle = empty
    return radial or empty, middle, axial or empty


class _CaseReader(SheetReader):
    """Builds the case, the runs and the test data from the tables."""

    def build(self, record: Record, make: Callable, fallback: tuple = ()) -> Any:
        """Call *make*; report its CaseError (at the field's cells) or ValueError (at *fallback*).

        A TypeError is not caught: a value of the wrong type is a defect of the reader, not of the input.
        """
        try:
            return make()
        except cm.CaseError as exc:
            keys = _field_keys(record.table, exc.field) or fallback
            self.record_problem(record, keys, record.typed(keys, exc.value), exc.expected)
        except ValueError as exc:    # flexbodies refuses a link geometry or material in words
            self.record_problem(record, fallback, record.typed(fallback, None), str(exc))
        return None

    def require(self, record: Record, keys: tuple, why: str) -> bool:
        """Report each of *keys* that is empty; True if all are given."""
        ok = True
        for key in keys:
            if key in record.cells and record.values.get(key) is None:
                self.record_problem(record, (key,), None, f"a value ({why})")
                ok = False
            elif key not in record.cells:
                self.problem(record.table.sheet, f"row {L.HEADER_ROW}", record.table.column(key).header, None,
                             f"a column headed '{record.table.column(key).header}' ({why})")
                ok = False
        return ok

    def one_shape(self, record: Record, geometry_keys: tuple) -> bool:
        """False (reported at the mesh file's cell) if *record* gives a mesh file and cells of a parametric
        geometry (*geometry_keys*): which of the two the user meant cannot be told."""
        given = [key for key in geometry_keys if record.values.get(key) is not None]
        if record.values.get("mesh_file") is None or not given:
            return True
        cells = ", ".join(f"'{record.table.column(key).header}' in {record.cells[key]}" for key in given)
        self.record_problem(record, ("mesh_file",), record.get("mesh_file"),
                            f"a mesh file or a parametric geometry, not both (row {record.row} also gives the "
                            f"geometry: {cells}; clear the geometry cells to use the mesh, or the mesh file to use "
                            "the geometry)")
        return False

    def unique(self, records: list[Record], key: str = "name") -> None:
        seen: dict[Any, int] = {}
        for record in records:
            name = record.values.get(key)
            if name is None:
                continue
            if name in seen:
                self.record_problem(record, (key,), name, f"a name not used before (row {seen[name]})")
            else:
                seen[name] = record.row

    # -- one item per row --------------------------------------------------------------------------------

    def engine(self, record: Record, casing: EngineCasing | None = None) -> cm.Engine | None:
        get = record.get
        inertia = ((get("ixx"), get("ixy", 0.0), get("ixz", 0.0)),
                   (get("ixy", 0.0), get("iyy"), get("iyz", 0.0)),
                   (get("ixz", 0.0), get("iyz", 0.0), get("izz")))
        return self.build(record, lambda: cm.Engine(get("mass"), record.vector("cg"), inertia, casing))

    def material(self, record: Record, preset: str = "steel"):
        import flexbodies

        base = flexbodies.material(record.get("material", preset))
        overrides = {key: record.get(key) for key in _MATERIAL_KEYS if record.get(key) is not None}
        if not overrides:
            return base
        return self.build(record, lambda: dataclasses.replace(base, name=f"{base.name} (modified)", **overrides),
                          tuple(overrides))

    def link_model(self, record: Record):
        import flexbodies

        material = self.material(record)
        if material is None:
            return None
        element_size = record.get("element_size")
        if element_size is not None and not element_size > 0:
            self.record_problem(record, ("element_size",), record.typed(("element_size",), element_size),
                                "a mesh size > 0 (empty: the default)")
            return None
        common = dict(material=material, element_size=element_size,
                      interface=record.get("interface", "RBE2"))
        if record.get("mesh_file") is not None:
            mesh = self.mesh(record)
            if not self.one_shape(record, _LINK_SHAPE_KEYS) or mesh is None:
                return None
            return flexbodies.LinkModel(mesh=mesh, **common)
        if not self.require(record, _GEOMETRY_KEYS, "a parametric link without a mesh file"):
            return None
        distance = math.dist(record.vector("end_a"), record.vector("end_b"))
        length = record.get("length", distance)
        if abs(length - distance) > 1e-6 * max(1.0, distance):
            self.record_problem(record, ("length",), record.typed(("length",), length),
                                f"the distance between end A and end B, {distance:.6g} m ({distance * 1e3:.6g} mm)")
            return None
        geometry = self.build(record, lambda: flexbodies.LinkGeometry(
            distance, *(record.get(key) for key in _GEOMETRY_KEYS)), _GEOMETRY_KEYS)
        return None if geometry is None else flexbodies.LinkModel(geometry=geometry, **common)

    def mesh(self, record: Record):
        import flexbodies

        path = self.path.parent / record.get("mesh_file")
        problem = bounded_file_problem(path, MAX_MESH_BYTES)
        if problem is not None:
            self.record_problem(record, ("mesh_file",), record.get("mesh_file"),
                                f"a mesh file (relative to the workbook's folder; {problem})")
            return None
        bores = []
        for eye in ("a", "b"):
            node_set = record.get(f"bore_{eye}_set")
            if node_set is not None:
                bores.append(flexbodies.BoreSpec(f"bore {eye.upper()}", node_set=node_set))
                continue
            keys = (*L.LINKS.vector_keys(f"mesh_bore_{eye}"), *L.LINKS.vector_keys("mesh_bore_axis"), "bore_radius")
            if not self.require(record, keys, f"bore {eye.upper()} of a mesh link without a node set"):
                return None
            bores.append(self.build(record, lambda eye=eye: flexbodies.BoreSpec(
                f"bore {eye.upper()}", centre=record.vector(f"mesh_bore_{eye}"),
                axis=record.vector("mesh_bore_axis"), radius=record.get("bore_radius")), keys))
        if None in bores:
            return None
        return flexbodies.MeshSource(str(path), tuple(bores), record.get("mesh_unit", 1.0))

    def link(self, record: Record) -> cm.Link | None:
        model = self.link_model(record)
        if model is None:
            return None
        get = record.get
        return self.build(record, lambda: cm.Link(
            get("name"), record.vector("end_a"), record.vector("end_b"), model, modes=get("modes", "auto"),
            flexible=get("flexible", True), stiffness_damping=get("stiffness_damping", 0.0),
            mass_damping=get("mass_damping", 0.0), spin_frequency_hz=get("spin_frequency_hz"),
            bore_axis=record.vector("bore_axis"), loss_factor=get("loss_factor", 0.0),
            modal_damping=get("modal_damping", 0.0)))

    def hinge(self, record: Record) -> cm.Hinge | None:
        get = record.get

        def body(key: str) -> str:
            name = get(key)
            return name.lower() if name.lower() in (cm.PYLON, cm.ENGINE) else name

        def per_direction(key: str, default: Any) -> Any:
            """One value, or three when a radial 2 or axial column is given (empty ones: as *key*)."""
            first = get(key, default)
            others = [get(f"{key}_radial_2"), get(f"{key}_axial")]
            if all(value is None for value in others):
                return first
            return (first, *(first if value is None else value for value in others))

        return self.build(record, lambda: cm.Hinge(
            get("name"), body("body_a"), body("body_b"), record.vector("position"), per_direction("stiffness", None),
            per_direction("damping", 0.0), get("radial_clearance", 0.0), get("contact_stiffness"),
            per_direction("loss_factor", 0.0), _hinge_frame(record)))

    def static_load(self, record: Record):
        kind, name, vector = record.get("type"), record.get("name"), record.vector
        needs = {"force": ("force", "point"), "moment": ("moment",), "gravity": ("acceleration",)}[kind]
        keys = tuple(k for vector_key in needs for k in L.STATIC_LOADS.vector_keys(vector_key))
        if not self.require(record, keys, f"a {kind} load"):
            return None
        make = {"force": lambda: cm.PointForce(name, vector("force"), vector("point")),
                "moment": lambda: cm.PointMoment(name, vector("moment")),
                "gravity": lambda: cm.Gravity(name, vector("acceleration"))}[kind]
        return self.build(record, make)

    def load_case(self, record: Record) -> LoadCase | None:
        """A Load cases row: at most one extra point force and one moment (named 'force' and 'moment')."""
        get, vector = record.get, record.vector
        forces: tuple = ()
        if vector("force") is not None:
            keys = L.LOAD_CASES.vector_keys("force_point")
            if not self.require(record, keys, "the point of the extra force"):
                return None
            forces = (self.build(record, lambda: cm.PointForce("force", vector("force"), vector("force_point"))),)
        moments = () if vector("moment") is None else (self.build(record, lambda: cm.PointMoment("moment", vector("moment"))),)
        if None in forces or None in moments:
            return None
        factors = tuple(get(key, default) for key, default in
                        zip(L.LOAD_CASES.vector_keys("load_factors"), _LOAD_FACTORS, strict=True))
        given = {key: get(key) for key in ("thrust", "torque", "factor_of_safety", "without_link")
                 if get(key) is not None}
        return self.build(record, lambda: LoadCase(get("name"), load_factors=factors, forces=forces, moments=moments,
                                                   thrust_point=vector("thrust_point"),
                                                   description=get("description", ""), **given))

    def speed_band(self, record: Record) -> SpeedBand | None:
        """A Speed spectrum row: hours at a speed, or in a band of speeds."""
        get = record.get
        return self.build(record, lambda: SpeedBand(get("hours"), get("speed_hz"), get("to_hz")))

    def speed_spectra(self, bands: list) -> tuple:
        """The ``(record, band)`` pairs of the Speed spectrum sheet as one spectrum per excitation."""
        groups: dict[str, list] = {}
        for record, band in bands:
            groups.setdefault(record.get("excitation"), []).append((record, band))
        return tuple(self.build(pairs[0][0], lambda name=name, pairs=pairs: SpeedSpectrum(
            name, tuple(band for _, band in pairs)), ("hours",)) for name, pairs in groups.items())

    def excitations(self, records: list[Record]) -> list:
        """``(record, excitation)`` per excitation: one per row, or one per group
        of ``imbalance plane`` rows of the same name (at its first row)."""
        groups: dict[str, list[Record]] = {}
        for record in records:
            if record.ok and record.get("type") == "imbalance plane":
                groups.setdefault(record.get("name"), []).append(record)
        pairs = []
        for record in records:
            if not record.ok:
                pairs.append((record, None))
            elif record.get("type") != "imbalance plane":
                pairs.append((record, self.excitation(record)))
            elif groups[record.get("name")][0] is record:
                pairs.append((record, self.imbalance(groups[record.get("name")])))
        return pairs

    def imbalance(self, records: list[Record]):
        """One :class:`~workbook.model.case.Imbalance` from its plane rows: each
        row a plane; speed, axis and any sweep or run-up on the first row."""
        first = records[0]
        for record in records[1:]:
            for key in ("frequency", "axis_x", "axis_y", "axis_z", "sweep_from", "sweep_to", "sweep_points",
                        "sweep_spacing", "run_up"):
                if record.get(key) is not None and record.get(key) != first.get(key):
                    self.record_problem(record, (key,), record.typed((key,), None),
                                        f"an empty cell (the planes of '{first.get('name')}' take it from the "
                                        f"first plane, row {first.row})")
        item = f"excitation {first.get('name')!r}"
        planes = [self.build(record, lambda r=record, k=k: cm.ImbalancePlane(
            r.vector("point"), unbalance=r.get("unbalance"), amplitude=r.get("amplitude"),
            phase_deg=r.get("phase", 0.0)).check(f"{item} plane {k}")) for k, record in enumerate(records, start=1)]
        if None in planes:
            return None
        return self.swept(first, lambda frequency: cm.Imbalance(
            first.get("name"), tuple(planes), frequency_hz=frequency, axis=first.vector("axis", (1.0, 0.0, 0.0))))

    def excitation(self, record: Record):
        get, vector = record.get, record.vector
        if get("type") == "rotating":
            return self.swept(record, lambda frequency: cm.RotatingForce(
                get("name"), vector("point"), frequency_hz=frequency, amplitude=get("amplitude"),
                unbalance=get("unbalance"), axis=vector("axis", (1.0, 0.0, 0.0)), phase_deg=get("phase", 0.0)))
        return self.swept(record, lambda frequency: cm.HarmonicForce(
            get("name"), vector("point"), vector("direction"), get("amplitude"), frequency_hz=frequency,
            phase_deg=get("phase", 0.0)))

    def swept(self, record: Record, make: Callable):
        """The excitation ``make(frequency)`` of *record*, or its sweep or run-up."""
        get = record.get
        sweep = get("sweep_from") is not None or get("sweep_to") is not None
        if get("run_up") is not None and not sweep:
            self.record_problem(record, ("sweep_from",), None, "a first speed (a run-up runs from 'sweep from' "
                                "to 'sweep to')")
            return None
        if sweep and not self.require(record, ("sweep_from", "sweep_to", "sweep_points"), "a sweep"):
            return None
        if sweep and get("frequency") is not None:
            self.record_problem(record, ("frequency",), record.typed(("frequency",), None),
                                "an empty cell (a sweep takes its frequencies from 'sweep from' and 'sweep to')")
            return None
        frequency = get("sweep_from") if sweep else get("frequency")
        template = self.build(record, lambda: make(frequency))
        if template is None or not sweep:
            return template
        unit = get("run_up")
        if unit is not None:
            factor = cm.SPEED_UNITS[unit]
            return self.build(record, lambda: cm.RunUp.speeds(get("name"), template, get("sweep_from") / factor,
                                                              get("sweep_to") / factor, get("sweep_points"), unit),
                              ("sweep_from", "sweep_to", "sweep_points"))
        return self.build(record, lambda: cm.Sweep.band(get("name"), template, get("sweep_from"), get("sweep_to"),
                                                        get("sweep_points"), get("sweep_spacing", "log")),
                          ("sweep_from", "sweep_to", "sweep_points"))

    def rotor(self, record: Record) -> cm.Rotor | None:
        """A Rotors row: spin axis x, y or z (empty: the Rotor default, x)."""
        get = record.get
        axis: dict[str, Any] = {} if get("axis") is None else {"axis": L.AXES[get("axis")]}
        return self.build(record, lambda: cm.Rotor(get("name"), get("polar_inertia"),
                                                   frequency_hz=get("frequency_hz"), **axis))

    def test_rig(self, record: Record) -> cm.ForceTransducers | None:
        """The Test rig row; empty mass and damping take the ForceTransducers defaults."""
        given = {key: value for key, value in (("mass", record.get("mass")), ("damping", record.vector("damping")))
                 if value is not None}
        return self.build(record, lambda: cm.ForceTransducers(record.vector("stiffness"), **given))

    def casing(self, record: Record) -> EngineCasing | None:
        """The Engine casing row: a parametric casing, or a mesh file relative to the workbook."""
        material = self.material(record, "titanium")
        if material is None:
            return None
        get = record.get
        shape = {}
        if get("mesh_file") is not None:
            path = self.path.parent / get("mesh_file")
            problem = bounded_file_problem(path, MAX_MESH_BYTES)
            if problem is not None:
                self.record_problem(record, ("mesh_file",), get("mesh_file"),
                                    f"a mesh file (relative to the workbook's folder; {problem})")
            if not self.one_shape(record, _CASING_SHAPE_KEYS) or problem is not None:
                return None
            shape = {"mesh": str(path), "scale": get("mesh_unit", 1.0)}
        else:
            rings = tuple(MountRing(get(f"{ring}_x"), get(f"{ring}_width"), get(f"{ring}_radius"))
                          for ring in L.CASING_RINGS if get(f"{ring}_x") is not None)
            shape = {"geometry": CasingGeometry(get("radius"), get("thickness"), get("x_start"), get("x_end"), rings)}
        given = {name: get(key) for name, key in (("element_size", "element_size"), ("spider_radius", "spider_radius"),
                                                  ("bearing_band", "bearing_band"), ("modal_damping", "modal_damping"),
                                                  ("modes", "modes")) if get(key) is not None}
        if get("bearing_radial") is not None or get("bearing_axial") is not None:
            radial, axial = DEFAULT_BEARING_STIFFNESS
            given["bearing_stiffness"] = (get("bearing_radial", radial), get("bearing_axial", axial))
        planes = tuple(get(key) for key in L.CASING_BEARINGS if get(key) is not None)
        return self.build(record, lambda: EngineCasing(planes, material=material, **shape, **given))

    def settings(self, record: Record):
        def given(cls):
            return {f.name: record.get(f.name) for f in dataclasses.fields(cls) if record.get(f.name) is not None}

        analysis = self.build(record, lambda: cm.AnalysisSettings(**given(cm.AnalysisSettings)))
        effects = self.build(record, lambda: cm.Effects(**given(cm.Effects)))
        return analysis, effects

    # -- the case ----------------------------------------------------------------------------------------

    def case(self, tables: dict) -> cm.Case | None:
        for key in ("Links", "Hinges", "Static loads", "Rotors", L.LOAD_CASES.sheet):
            self.unique(tables[key])
        planes: dict = {}
        for record in tables["Excitations"]:
            if record.get("type") == "imbalance plane":
                planes.setdefault(record.get("name"), record)
        # the plane rows of one imbalance share its name; its first row stands for it
        self.unique([r for r in tables["Excitations"] if r.get("type") != "imbalance plane" or planes[r.get("name")] is r])
        casing = [self.casing(r) for r in tables[L.CASING.sheet] if r.ok]
        engine = [self.engine(r, casing[0] if casing else None) for r in tables["Engine"] if r.ok]
        settings = [self.settings(r) for r in tables["Case"] if r.ok]
        test_rig = [self.test_rig(r) for r in tables["Test rig"] if r.ok]
        items = {key: [(r, make(r) if r.ok else None) for r in tables[key]] for key, make in
                 (("Links", self.link), ("Hinges", self.hinge), ("Static loads", self.static_load),
                  ("Rotors", self.rotor), (L.LOAD_CASES.sheet, self.load_case))}
        items["Excitations"] = self.excitations(tables["Excitations"])
        items[L.SPEED_SPECTRUM.sheet] = [(r, self.speed_band(r) if r.ok else None)
                                         for r in tables[L.SPEED_SPECTRUM.sheet]]
        first_links: dict[Any, Any] = {}
        for record, link in items["Links"]:
            first_links.setdefault(record.get("name"), link)
        self.hinge_bodies(items["Hinges"], tables["Links"], first_links)
        self.loose_eyes(items["Hinges"], items["Links"])
        if self.problems or not engine or None in engine or not settings or None in settings[0]:
            return None
        (analysis, effects), record = settings[0], tables["Case"][0]
        built: dict[str, tuple[Any, ...]] = {key: tuple(item for _, item in pairs) for key, pairs in items.items()}
        spectra = self.speed_spectra(items[L.SPEED_SPECTRUM.sheet])
        if None in spectra:
            return None
        try:
            case = cm.Case(record.get("name"), cast(cm.Engine, engine[0]), built["Links"], built["Hinges"], built["Static loads"],
                           built["Excitations"], analysis=analysis, effects=effects,
                           description=record.get("description", ""), test_rig=test_rig[0] if test_rig else None,
                           rotors=built["Rotors"], load_cases=built[L.LOAD_CASES.sheet], speed_spectra=spectra)
            check_speed_spectra(case)
            return case
        except cm.CaseError as exc:
            self.case_error(exc, items, tables[L.CASING.sheet])
        return None

    def hinge_bodies(self, hinges: list, link_records: list, links: dict) -> None:
        """Report hinges naming an unknown body or placed away from their link's eyes."""
        names = list(dict.fromkeys(r.get("name") for r in link_records if r.get("name") is not None))
        for record, hinge in hinges:
            if hinge is None:
                continue
            for key in ("body_a", "body_b"):
                body = getattr(hinge, key)
                if body in (cm.PYLON, cm.ENGINE):
                    continue
                if body not in names:
                    self.record_problem(record, (key,), body, f"pylon, engine or a link name ({', '.join(names)})")
                elif links.get(body) is not None and links[body].eye_at(hinge.position) is None:
                    link = links[body]
                    gap = min(math.dist(hinge.position, link.end_a), math.dist(hinge.position, link.end_b))
                    self.record_problem(record, L.HINGES.vector_keys("position"),
                                        record.typed(L.HINGES.vector_keys("position"), None),
                                        f"an eye centre of link '{body}' (the nearest is {gap * 1e3:.4g} mm away)")

    def loose_eyes(self, hinges: list, links: list) -> None:
        """Report each link eye no hinge holds, and a mount with no hinge to the engine or the pylon.

        A link eye without a hinge swings free: the mount is a mechanism,
        which the run would find only after building the model.
        """
        if any(hinge is None for _, hinge in hinges) or any(p.sheet == L.HINGES.sheet for p in self.problems):
            return    # a bad or misplaced hinge is reported already
        built = [hinge for _, hinge in hinges]
        for record, link in links:
            if link is None:
                continue
            held = {link.eye_at(h.position) for h in built if link.name in (h.body_a, h.body_b)}
            for eye in ("a", "b"):
                if eye not in held:
                    keys = L.LINKS.vector_keys(f"end_{eye}")
                    self.record_problem(record, keys, record.typed(keys, None),
                                        f"a hinge at end {eye.upper()} of link '{link.name}' (no row of the Hinges "
                                        "sheet joins the link there: it would swing free, a mechanism)")
        for body in (cm.ENGINE, cm.PYLON):
            if hinges and not any(body in (h.body_a, h.body_b) for h in built):
                self.problem(L.HINGES.sheet, None, "body A", None,
                             f"at least one hinge to the {body} (body A or body B '{body}')")

    def case_error(self, exc: cm.CaseError, items: dict, casing: list[Record]) -> None:
        """Report a CaseError of the Case constructor at the row of the item it names (*items*: the
        ``(record, item)`` pairs of each sheet; *casing*: the Engine casing rows)."""
        if exc.item == _CASING_ITEM and casing:
            keys = _field_keys(L.CASING, exc.field)
            self.record_problem(casing[0], keys, casing[0].typed(keys, exc.value), exc.expected)
            return
        spectrum = _SPECTRUM_ITEM.match(exc.item)
        if spectrum:
            rows = [record for record, _ in items[L.SPEED_SPECTRUM.sheet] if record.get("excitation") == spectrum.group(1)]
            band = re.match(r"bands\[(\d+)\]\.?(.*)$", exc.field)
            record = rows[int(band.group(1))] if band else rows[0]
            keys = (band.group(2) or "hours",) if band else ("excitation",)
            self.record_problem(record, keys, record.typed(keys, exc.value), exc.expected)
            return
        match = _ITEM.match(exc.item)
        if match:
            table = _ITEM_TABLES[match.group(1)]
            for record, _ in items[table.sheet]:
                if record.get("name") == match.group(2):
                    keys = _field_keys(table, exc.field)
                    self.record_problem(record, keys, record.typed(keys, exc.value), exc.expected)
                    return
        self.problem(None, None, exc.field, exc.value, f"{exc.expected} ({exc.item})")

    # -- runs and test data ------------------------------------------------------------------------------

    def runs(self, case: cm.Case, records: list[Record]) -> list[tuple[Record, RunSpec]]:
        self.unique(records)
        if not records:
            self.problem(L.RUNS.sheet, f"row {L.FIRST_DATA_ROW}", None, None, "at least one run")
        excitations = {e.name: e for e in case.excitations}
        runs = []
        fields = {f.name for f in dataclasses.fields(RunSpec)}
        for record in records:
            if not record.ok:
                continue
            excitation = excitations.get(record.get("excitation"))
            if excitation is None:
                self.record_problem(record, ("excitation",), record.get("excitation"),
                                    f"an excitation name ({', '.join(excitations)})")
                continue
            if isinstance(excitation, cm.Sweep) and record.get("frequency") is not None:
                self.record_problem(record, ("frequency",), record.typed(("frequency",), None),
                                    f"an empty cell ('{excitation.name}' is a sweep)")
                continue
            template = excitation.template if isinstance(excitation, cm.Sweep) else excitation
            if isinstance(template, cm.Imbalance) and record.get("amplitude") is not None:
                self.record_problem(record, ("amplitude",), record.typed(("amplitude",), None),
                                    f"an empty cell ('{excitation.name}' is an imbalance: its planes carry their "
                                    f"own unbalance or force)")
                continue
            run = RunSpec(**{k: v for k, v in record.values.items() if k in fields})
            run_case = self.build(record, lambda run=run: case_for_run(case, run))
            if run_case is not None and self.pylon_fits(record, run_case):
                runs.append((record, run))
        return runs

    def pylon_fits(self, record: Record, run_case: cm.Case) -> bool:
        """False (reported at the run's excitation cell) if the run cannot be answered on the case's flexible
        pylon: its excitation takes the time domain, which has none, or its frequencies leave the pylon
        impedance table's range. The run would stop there, after the runs before it."""
        if not run_case.flexible_pylon:
            return True
        from workbook.solve.flexible_pylon import refuse_time_domain
        from workbook.solve.method import TIME, choose_method

        for item in run_case.excitations:
            chosen = choose_method(run_case, sweep=isinstance(item, cm.Sweep))
            if chosen.method != TIME:
                continue
            try:
                refuse_time_domain(run_case, chosen.reason)
            except cm.CaseError as error:
                self.record_problem(record, ("excitation",), record.get("excitation"),
                                    f"{error.expected} (run '{record.get('name')}')")
                return False
        pylon = run_case.pylon
        covered = None if pylon is None else pylon.covered_hz()
        if pylon is None or covered is None:
            return True
        try:
            pylon.check_covers([x.frequency for x in run_case.single_frequency_excitations()])
        except cm.CaseError as error:
            low, high = covered
            self.record_problem(record, ("excitation",), record.get("excitation"),
                                f"an excitation within the {pylon.noun} table: run '{record.get('name')}' "
                                f"excites {error.value}, the table ({pylon.label}) covers "
                                f"{low:g} to {high:g} Hz (it is "
                                "not extrapolated: extend the table or narrow the excitation's frequencies)")
            return False
        return True

    def tests(self, runs: list, records: list[Record], case: cm.Case) -> list[TestPoint]:
        by_name = {run.name: (record, run) for record, run in runs}
        locations = [PYLON_SUM] + [h.name for h in case.hinges]
        points = []
        for record in records:
            if not record.ok:
                continue
            name = record.get("run")
            if name not in by_name:
                self.record_problem(record, ("run",), name, f"a run name ({', '.join(by_name)})")
                continue
            if record.get("record") is not None:
                points.extend(self.record_points(record, by_name[name][1], case))
                continue
            missing = [key for key in ("direction", "amplitude") if record.get(key) is None]
            if missing:
                self.record_problem(record, (missing[0],), None, f"a {missing[0]} (or a rig record)")
                continue
            location = record.get("location", PYLON_SUM)
            if location not in locations:
                self.record_problem(record, ("location",), location, "'pylon sum' or a hinge name")
                continue
            frequencies = [e.frequency for e in case_for_run(case, by_name[name][1]).single_frequency_excitations()]
            frequency = record.get("frequency")
            if frequency is None and len(frequencies) > 1:
                self.record_problem(record, ("frequency",), None, f"the frequency measured (run '{name}' is a sweep)")
                continue
            if frequency is not None and not any(abs(frequency - f) <= 1e-3 * f for f in frequencies):
                self.record_problem(record, ("frequency",), record.typed(("frequency",), frequency),
                                    "a frequency of the run: " + ", ".join(f"{f:.6g} Hz" for f in frequencies))
                continue
            points.append(TestPoint(name, location, record.get("direction"), frequency, record.get("amplitude")))
        return points

    def record_points(self, record: Record, run: RunSpec, case: cm.Case) -> list[TestPoint]:
        """The pylon-sum test points of a Test data row naming a rig record."""
        from workbook.errors import RecordError
        from workbook.excel.rig_points import record_test_points

        extra = [key for key in ("location", "direction", "amplitude", "frequency") if record.get(key) is not None]
        if extra:
            self.record_problem(record, (extra[0],), record.typed((extra[0],), None),
                                "an empty cell (a rig record gives the pylon sum in every direction)")
            return []
        run_case = case_for_run(case, run)
        if record.get("periods") is not None:
            try:
                analysis = dataclasses.replace(run_case.analysis, measured_periods=record.get("periods"))
            except cm.CaseError as error:
                self.record_problem(record, ("periods",), record.typed(("periods",), None), error.expected)
                return []
            run_case = dataclasses.replace(run_case, analysis=analysis)
        try:
            return record_test_points(self.path.parent / record.get("record"), run.name, run_case)
        except RecordError as error:
            self.record_problem(record, ("record",), record.get("record"), f"a usable rig record: {error}")
            return []


def read_workbook(path: str | Path) -> CaseBook:
    """Read and check a case workbook.

    Parameters
    ----------
    path : str or Path
        The .xlsx file.

    Returns
    -------
    CaseBook

    Raises
    ------
    WorkbookError
        With every problem found.
    """
    path = Path(path)
    data = read_workbook_bytes(path)
    sha256 = hashlib.sha256(data).hexdigest()
    formulas, values = open_workbook(path, data)
    try:
        reader = _CaseReader(path, formulas, values)
        tables = {table.sheet: reader.table(table) for table in L.TABLES}
        reader.sheet_title(IMPEDANCE_SHEET)
        reader.misspelt_sheets((*(table.sheet for table in L.TABLES), IMPEDANCE_SHEET),
                               (L.INSTRUCTIONS_SHEET,))
        if reader.merged_found:
            raise WorkbookError(reader.problems)
        case = reader.case(tables)
        if case is None:
            reader.unique(tables["Runs"])
            raise WorkbookError(reader.problems)
        case = with_impedance_sheet(case, path, values)
        runs = reader.runs(case, tables["Runs"])
        tests = reader.tests(runs, tables["Test data"], case)
        optimise = read_optimise_sheet(reader, tables[L.OPTIMISE.sheet], case)
        if reader.problems:
            raise WorkbookError(reader.problems)
        values.keep_formula_values()     # for the writer
    finally:
        values.close()
    log.info("read %s: %d links, %d hinges, %d runs", path.name, len(case.links), len(case.hinges), len(runs))
    return CaseBook(path, case, tuple(run for _, run in runs), tuple(tests), sha256,
                    OpenedWorkbook(sha256, formulas, values), optimise)
