"""The sheets of a case workbook: one source of truth for template, reader and writer.

Every input sheet is a table with the same layout:

- row 1 (:data:`HEADER_ROW`): column headers;
- row 2 (:data:`UNIT_ROW`): the unit of each column (``-`` for numbers
  without dimension, empty for text and choices);
- rows 3 on (:data:`FIRST_DATA_ROW`): one item per row; empty rows are
  skipped. The Case and Engine sheets hold exactly one row, the Test rig
  sheet at most one.

A vector (position, force, direction) takes three columns ``<name> x``,
``<name> y``, ``<name> z``, each with its own unit cell. Axes (docs/physics.md,
section 1): x heading, y lateral, z vertical (up). Columns whose header
starts with ``#`` are the user's notes and are ignored.
"""
from __future__ import annotations

from dataclasses import dataclass

from workbook.model.case import (
    DIRECTIONS,
    AnalysisSettings,
    Effects,
    Engine,
    ForceTransducers,
    Gravity,
    HarmonicForce,
    Hinge,
    Link,
    PointForce,
    PointMoment,
    RotatingForce,
    Rotor,
    RunUp,
)
from workbook.model.casing import EngineCasing
from workbook.model.field_spec import field_spec
from workbook.model.load_cases import LoadCase
from workbook.model.spectrum import SpeedBand
from workbook.model.units import DIMENSIONLESS

__all__ = ["Column", "Table", "TABLES", "CASE", "ENGINE", "LINKS", "HINGES", "STATIC_LOADS",
           "EXCITATIONS", "LOAD_CASES", "SPEED_SPECTRUM", "ROTORS", "TEST_RIG", "CASING", "RUNS", "TEST_DATA",
           "OPTIMISE", "HEADER_ROW", "UNIT_ROW",
           "FIRST_DATA_ROW", "INSTRUCTIONS_SHEET", "RESULT_PREFIX", "YES", "NO", "AXES", "MAGNITUDE_LIMITS"]

HEADER_ROW, UNIT_ROW, FIRST_DATA_ROW = 1, 2, 3
INSTRUCTIONS_SHEET = "Instructions"
#: Result sheets written back by a run start with this prefix.
RESULT_PREFIX = "Result "
YES, NO = "yes", "no"

#: Unit vector of each axis letter (the Rotors sheet's spin axis).
AXES = {axis: tuple(float(axis == other) for other in DIRECTIONS) for axis in DIRECTIONS}

#: Largest magnitude a number of each SI unit may have in a case workbook. A larger value is a
#: typing or unit mistake (1e300 N/m, a length in metres typed in millimetres twice) that the
#: solver would meet only as a failed run; the limits are orders of magnitude beyond any mount.
MAGNITUDE_LIMITS = {"m": 1e3, "kg": 1e7, "N": 1e10, "N/m": 1e14, "N*s/m": 1e10, "Hz": 1e6, "s": 1e6,
                    "kg*m^2": 1e8, "Pa": 1e14, "kg/m^3": 1e6, "m/s^2": 1e5, "N*m": 1e11, "kg*m": 1e4, "h": 1e7}

#: Column kinds: how a cell is read.
KINDS = ("number", "integer", "text", "choice", "yesno", "modes", "fidelity", "unit")


@dataclass(frozen=True)
class Column:
    """One column of an input table.

    Attributes
    ----------
    key : str
        Name the reader uses, e.g. ``"end_a_x"``.
    header : str
        Text of the header cell, e.g. ``"end A x"``.
    kind : str
        One of :data:`KINDS`: ``number``, ``integer``, ``text``, ``choice``
        (one of *choices*), ``yesno``, ``modes`` (auto, static, a count or a
        cut-off such as ``500 Hz``), ``fidelity`` (rigid or a ``modes``
        value), ``unit`` (a length unit as text, e.g. for a mesh file).
    si_unit : str or None
        SI unit of a number column (:data:`~workbook.model.units.DIMENSIONLESS`
        for no dimension); None for the other kinds.
    unit : str or None
        Unit shown in the template's unit cell (default: *si_unit*).
    required : bool
        The cell must not be empty.
    choices : tuple of str
        Allowed values of a ``choice`` column (a drop-down list in the template).
    help : str
        One line for the Instructions sheet.
    """

    key: str
    header: str
    kind: str = "number"
    si_unit: str | None = None
    unit: str | None = None
    required: bool = False
    choices: tuple = ()
    help: str = ""

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"column {self.header!r}: kind {self.kind!r} is not one of {', '.join(KINDS)}")
        if (self.kind == "choice") != bool(self.choices):
            raise ValueError(f"column {self.header!r}: choices go with kind 'choice' only")

    @property
    def has_unit(self) -> bool:
        """True if the unit cell is read (number columns)."""
        return self.si_unit is not None

    @property
    def template_unit(self) -> str:
        """Text of the template's unit cell."""
        if not self.has_unit:
            return ""
        return self.unit or self.si_unit or ""

    @property
    def drop_down(self) -> tuple:
        """Values of the template's drop-down list (empty: none)."""
        if self.kind == "yesno":
            return (YES, NO)
        return self.choices


def _xyz(key: str, header: str, si_unit: str, *, unit: str | None = None, required: bool = False,
         help: str = "") -> tuple[Column, ...]:
    """Three columns ``<header> x/y/z`` of a vector."""
    return tuple(Column(f"{key}_{axis}", f"{header} {axis}", "number", si_unit, unit, required,
                        help=f"{help} ({axis})" if help else "")
                 for axis in "xyz")


def _num(key, header, si_unit=DIMENSIONLESS, *, unit=None, required=False, help=""):
    return Column(key, header, "number", si_unit, unit, required, help=help)


def _field(cls: type, name: str, header: str, *, unit: str | None = None,
           required: bool = False) -> tuple[Column, ...]:
    """The column of field *name* of the case dataclass *cls* (three of a vector): key, SI unit, choices and
    help line from the field's spec (:mod:`workbook.model.field_spec`); *unit* is the template's display unit."""
    described = field_spec(cls, name)
    key = described.column or name
    if described.check == "choice":
        return (Column(key, header, "choice", required=required, choices=described.choices, help=described.help),)
    if described.check == "flag":
        return (Column(key, header, "yesno", required=required, help=described.help),)
    if described.check in ("vector3", "direction"):
        return _xyz(key, header, described.unit or DIMENSIONLESS, unit=unit, required=required, help=described.help)
    return (_num(key, header, described.unit or DIMENSIONLESS, unit=unit, required=required, help=described.help),)


def _material_columns(preset_help: str) -> tuple:
    """The material columns of a sheet: a preset, and E, nu and density overriding it."""
    return (Column("material", "material", "choice", choices=("steel", "titanium"), help=preset_help),
            _num("youngs_modulus", "E", "Pa", unit="GPa", help="Young's modulus overriding the preset"),
            _num("poisson_ratio", "nu", help="Poisson's ratio overriding the preset"),
            _num("density", "density", "kg/m^3", help="density overriding the preset"))


@dataclass(frozen=True)
class Table:
    """An input sheet.

    Attributes
    ----------
    sheet : str
        Sheet name.
    columns : tuple of Column
    single_row : bool
        The sheet holds exactly one row (Case, Engine); an optional one holds
        at most one (Test rig).
    optional : bool
        The sheet may be missing (Rotors, Test rig, Test data).
    help : str
        What the sheet is for (Instructions sheet).
    """

    sheet: str
    columns: tuple
    single_row: bool = False
    optional: bool = False
    help: str = ""

    def column(self, key: str) -> Column:
        """The column with *key*."""
        for column in self.columns:
            if column.key == key:
                return column
        raise KeyError(key)

    def vector_keys(self, key: str) -> tuple[str, ...]:
        """Keys of the three columns of vector *key*."""
        return tuple(f"{key}_{axis}" for axis in "xyz")


CASE = Table("Case", single_row=True, help="case name, analysis settings and the physical effects asked for", columns=(
    Column("name", "name", "text", required=True, help="case name"),
    Column("description", "description", "text", help="free text"),
    Column("steps_per_period", "steps per period", "integer", DIMENSIONLESS,
           help="time steps per excitation period (at least 8; 40 recommended)"),
    *_field(AnalysisSettings, "ramp_periods", "ramp periods"),
    *_field(AnalysisSettings, "settle_time_constants", "settle time constants"),
    *_field(AnalysisSettings, "settle_time", "settle time"),
    Column("measured_periods", "measured periods", "integer", DIMENSIONLESS,
           help="periods per measured window"),
    *_field(AnalysisSettings, "steady_tolerance", "steady tolerance"),
    *_field(AnalysisSettings, "spectral_radius", "spectral radius"),
    *_field(AnalysisSettings, "newton_tolerance", "newton tolerance"),
    *_field(AnalysisSettings, "equilibrium_tolerance", "equilibrium tolerance"),
    Column("step_halvings", "step halvings", "integer", DIMENSIONLESS,
           help="a segment whose Newton iteration fails is run again with the step halved, at most this often"),
    *_field(AnalysisSettings, "time_budget", "time budget"),
    *_field(AnalysisSettings, "divergence_displacement", "divergence limit", unit="mm"),
    *_field(AnalysisSettings, "method", "method"),
    *_field(Effects, "flexible_links", "flexible links"),
    *_field(Effects, "preload", "preload"),
    *_field(Effects, "hinge_damping", "hinge damping"),
    *_field(Effects, "link_damping", "link damping"),
    *_field(Effects, "clearance", "clearance"),
    *_field(Effects, "gyroscopics", "gyroscopics"),
    *_field(Effects, "rig_sensors", "rig sensors"),
    *_field(Effects, "stress_stiffening", "stress stiffening"),
    *_field(AnalysisSettings, "start", "start"),
))

ENGINE = Table("Engine", single_row=True, help="the rigid engine", columns=(
    *_field(Engine, "mass", "mass", required=True),
    *_field(Engine, "center_of_mass", "CG", required=True),
    *(_num(f"i{ij}", f"I{ij}", field_spec(Engine, "inertia").unit, required=ij in ("xx", "yy", "zz"),
           help=f"inertia tensor component {ij} about the CG (off-diagonal: empty = 0)")
      for ij in ("xx", "yy", "zz", "xy", "xz", "yz")),
))

LINKS = Table("Links", help="connecting links: a parametric geometry or a mesh file", columns=(
    Column("name", "name", "text", required=True, help="unique link name"),
    *_field(Link, "end_a", "end A", required=True),
    *_field(Link, "end_b", "end B", required=True),
    _num("length", "length", "m", help="eye distance; empty: from the ends, given: checked against them"),
    *_material_columns("preset material"),
    _num("eye_outer_radius", "eye outer radius", "m", unit="mm", help="parametric link: eye outer radius"),
    _num("bore_radius", "bore radius", "m", unit="mm", help="bore radius (parametric link or mesh bores)"),
    _num("thickness", "eye thickness", "m", unit="mm", help="parametric link: eye thickness"),
    _num("shank_width", "shank width", "m", unit="mm", help="parametric link: shank width"),
    _num("shank_thickness", "shank thickness", "m", unit="mm", help="parametric link: shank thickness"),
    _num("element_size", "element size", "m", unit="mm", help="mesh size (empty: default)"),
    Column("interface", "interface", "choice", choices=("RBE2", "RBE3"), help="bore coupling"),
    Column("modes", "modes", "modes", help="auto, static, a mode count or a cut-off such as '2000 Hz'"),
    Column("flexible", "flexible", "yesno", help="no: rigid link"),
    *_field(Link, "stiffness_damping", "stiffness damping"),
    *_field(Link, "mass_damping", "mass damping"),
    *_field(Link, "spin_frequency_hz", "spin frequency"),
    *_field(Link, "bore_axis", "bore axis"),
    Column("mesh_file", "mesh file", "text", help="mesh file, relative to the workbook (instead of a geometry)"),
    Column("mesh_unit", "mesh unit", "unit", help="length unit of the mesh file (e.g. mm)"),
    Column("bore_a_set", "bore A node set", "text", help="mesh: node set of bore A"),
    Column("bore_b_set", "bore B node set", "text", help="mesh: node set of bore B"),
    *_xyz("mesh_bore_a", "mesh bore A", "m", unit="mm", help="mesh: a point on bore A's axis, mesh frame"),
    *_xyz("mesh_bore_b", "mesh bore B", "m", unit="mm", help="mesh: a point on bore B's axis, mesh frame"),
    *_xyz("mesh_bore_axis", "mesh bore axis", DIMENSIONLESS, help="mesh: bore axis direction, mesh frame"),
    *_field(Link, "loss_factor", "loss factor"),
    *_field(Link, "modal_damping", "modal damping"),
    *(_num(key, key.replace("_", " "), "Pa", unit="MPa", help=f"{what} overriding the preset's (load cases, fatigue)")
      for key, what in (("yield_strength", "tensile yield strength (0.2 % proof)"),
                        ("ultimate_strength", "tensile ultimate strength"),
                        ("endurance_strength", "fully reversed endurance strength"))),
    _num("endurance_cycles", "endurance cycles",
         help="cycles at the S-N curve's knee, where the endurance strength is reached, overriding the preset's"),
    _num("fatigue_exponent", "fatigue exponent",
         help="Basquin exponent b < 0 of the S-N curve sigma_a = S_e (N/N_e)^b, overriding the preset's"),
))

HINGES = Table("Hinges", help="ball hinges: spring-dampers between two bodies", columns=(
    Column("name", "name", "text", required=True, help="unique hinge name"),
    Column("body_a", "body A", "text", required=True, help="pylon, engine or a link name"),
    Column("body_b", "body B", "text", required=True, help="pylon, engine or a link name"),
    *_field(Hinge, "position", "position", required=True),
    *_field(Hinge, "stiffness", "stiffness", required=True),
    *_field(Hinge, "damping", "damping"),
    *_field(Hinge, "radial_clearance", "radial clearance", unit="mm"),
    *_field(Hinge, "contact_stiffness", "contact stiffness"),
    *_field(Hinge, "loss_factor", "loss factor"),
    *(_num(f"{key}_{suffix}", f"{header} {direction}", field_spec(Hinge, key).unit,
           help=f"{header} along the hinge frame's {direction} direction (empty: as '{header}')")
      for key, header in (("stiffness", "stiffness"), ("damping", "damping"), ("loss_factor", "loss factor"))
      for suffix, direction in (("radial_2", "radial 2"), ("axial", "axial"))),
    *_xyz("frame_radial_1", "frame radial 1", DIMENSIONLESS,
          help="hinge frame: radial 1 direction, unit length (empty: the link's frame)"),
    *_xyz("frame_axial", "frame axial", DIMENSIONLESS,
          help="hinge frame: axial (pin) direction, at right angles to radial 1 (empty: the link's frame)"),
))

STATIC_LOADS = Table("Static loads", help="constant loads solved first (the preload)", columns=(
    Column("name", "name", "text", required=True, help="unique load name"),
    Column("type", "type", "choice", required=True, choices=("force", "moment", "gravity"),
           help="force at a point, moment, or gravity on every body"),
    *_field(PointForce, "force", "force"),
    *_field(PointForce, "point", "point"),
    *_field(PointMoment, "moment", "moment"),
    *_field(Gravity, "acceleration", "acceleration"),
))

EXCITATIONS = Table("Excitations", help="rotor imbalances and harmonic forces; a sweep runs one at many frequencies",
                    columns=(
    Column("name", "name", "text", required=True, help="unique excitation name"),
    Column("type", "type", "choice", required=True, choices=("rotating", "harmonic", "imbalance plane"),
           help="rotating imbalance force, fixed-direction harmonic force, or one plane of a several-plane "
                "imbalance (rows of the same name are the planes of one rotor: speed and axis on the first)"),
    *_field(HarmonicForce, "point", "point", required=True),
    *_field(HarmonicForce, "frequency_hz", "frequency"),
    *_field(HarmonicForce, "amplitude", "amplitude"),
    *_field(RotatingForce, "unbalance", "unbalance"),
    *_field(RotatingForce, "axis", "axis"),
    *_field(HarmonicForce, "direction", "direction"),
    *_field(HarmonicForce, "phase_deg", "phase"),
    _num("sweep_from", "sweep from", "Hz", help="sweep: first frequency"),
    _num("sweep_to", "sweep to", "Hz", help="sweep: last frequency"),
    Column("sweep_points", "sweep points", "integer", DIMENSIONLESS, help="sweep: number of frequencies"),
    Column("sweep_spacing", "sweep spacing", "choice", choices=("log", "linear"), help="sweep: spacing"),
    *_field(RunUp, "speed_unit", "run-up"),
))

LOAD_CASES = Table("Load cases", optional=True,
                   help="limit load cases for mountwb loads and the Result loads sheet of a run (docs/stresses.md); "
                        "a row holds one extra point force and one moment, more are given in Python or JSON",
                   columns=(
    Column("name", "name", "text", required=True, help="unique load case name"),
    Column("description", "description", "text", help="free text: where the numbers come from"),
    *_field(LoadCase, "thrust", "thrust", unit="kN"),
    *_field(LoadCase, "thrust_point", "thrust point"),
    *_field(LoadCase, "load_factors", "load factor"),
    *_field(LoadCase, "torque", "torque", unit="kN*m"),
    *_xyz("force", "force", "N", help="an extra point force on the engine"),
    *_xyz("force_point", "force point", "m", help="point of the extra force"),
    *_xyz("moment", "moment", "N*m", help="an extra moment on the engine"),
    *_field(LoadCase, "factor_of_safety", "factor of safety"),
    Column("without_link", "fail-safe link", "text", help="fail-safe: the link removed for this load case"),
))

SPEED_SPECTRUM = Table("Speed spectrum", optional=True,
                       help="hours each rotor excitation runs at each speed, for the links' Miner damage sums in "
                            "the Result fatigue sheet (docs/stresses.md); one row per speed or band of speeds",
                       columns=(
    Column("excitation", "excitation", "text", required=True,
           help="a rotor excitation (rows of the same excitation make its spectrum)"),
    *_field(SpeedBand, "speed_hz", "speed", unit="rpm", required=True),
    *_field(SpeedBand, "to_hz", "to speed", unit="rpm"),
    *_field(SpeedBand, "hours", "hours", required=True),
))

ROTORS = Table("Rotors", optional=True,
               help="spinning rotors whose gyroscopic moments act on the engine (their mass and inertia are "
                    "in the Engine sheet)", columns=(
    Column("name", "name", "text", required=True, help="unique rotor name"),
    *_field(Rotor, "polar_inertia", "polar inertia", required=True),
    *_field(Rotor, "frequency_hz", "speed", required=True),
    Column("axis", "spin axis", "choice", choices=DIRECTIONS,
           help="spin axis in engine coordinates, spinning right-handed about it (empty: x)"),
))

TEST_RIG = Table("Test rig", single_row=True, optional=True,
                 help="the rig's three-way force transducers under the pylon pins (empty: rigid ground)", columns=(
    *_field(ForceTransducers, "stiffness", "stiffness", required=True),
    *_field(ForceTransducers, "mass", "mass"),
    *_field(ForceTransducers, "damping", "damping"),
))

CASING_RINGS = ("front_ring", "rear_ring")
CASING_BEARINGS = ("bearing_1", "bearing_2", "bearing_3")

CASING = Table("Engine casing", single_row=True, optional=True,
               help="the engine's casing as a flexible body, the rest a rigid core on bearings (empty: a rigid "
                    "engine); positions x along the engine axis, see docs/flexible-engine.md", columns=(
    _num("radius", "radius", "m", unit="mm", help="parametric casing: outer radius of the tube"),
    _num("thickness", "wall thickness", "m", unit="mm", help="parametric casing: wall thickness"),
    _num("x_start", "x start", "m", help="parametric casing: aft end"),
    _num("x_end", "x end", "m", help="parametric casing: front end"),
    *(column for ring in CASING_RINGS for column in (
        _num(f"{ring}_x", f"{ring.replace('_', ' ')} x", "m", help="mount ring: mid-plane (empty: no ring)"),
        _num(f"{ring}_width", f"{ring.replace('_', ' ')} width", "m", unit="mm", help="mount ring: axial width"),
        _num(f"{ring}_radius", f"{ring.replace('_', ' ')} radius", "m", unit="mm",
             help="mount ring: outer radius"))),
    *(_num(key, f"bearing {k} x", field_spec(EngineCasing, "bearing_planes").unit, required=k <= 2, help="a bearing plane (the rotors' seat)")
      for k, key in enumerate(CASING_BEARINGS, start=1)),
    *_material_columns("preset material (empty: titanium)"),
    *_field(EngineCasing, "element_size", "element size", unit="mm"),
    *_field(EngineCasing, "spider_radius", "spider radius", unit="mm"),
    *_field(EngineCasing, "bearing_band", "bearing band", unit="mm"),
    *(_num(f"bearing_{direction}", f"bearing {direction} stiffness", field_spec(EngineCasing, "bearing_stiffness").unit,
           help="each bearing (empty: 1e10 N/m)") for direction in ("axial", "radial")),
    *_field(EngineCasing, "modal_damping", "modal damping"),
    Column("modes", "modes", "modes", help="auto, static or a mode count"),
    Column("mesh_file", "mesh file", "text", help="mesh file, relative to the workbook (instead of a geometry)"),
    Column("mesh_unit", "mesh unit", "unit", help="length unit of the mesh file (e.g. mm)"),
))

RUNS = Table("Runs", help="one run per row: an excitation and optional overrides", columns=(
    Column("name", "run", "text", required=True, help="unique run name"),
    Column("excitation", "excitation", "text", required=True, help="an excitation name"),
    _num("frequency", "frequency", "Hz", help="override: frequency (not for sweeps)"),
    _num("amplitude", "amplitude", "N", help="override: force amplitude"),
    Column("fidelity", "fidelity", "fidelity",
           help="override: rigid, static, auto, a mode count or a cut-off such as '2000 Hz'"),
    _num("gap", "gap", "m", unit="mm", help="override: radial clearance of every hinge"),
    _num("hinge_stiffness", "hinge stiffness", "N/m", help="override: stiffness of every hinge"),
    _num("hinge_damping", "hinge damping", "N*s/m", help="override: damping of every hinge"),
    Column("preload", "preload", "yesno", help="override: solve the static loads first"),
    Column("steps_per_period", "steps per period", "integer", DIMENSIONLESS, help="override"),
    _num("settle_time", "settle time", "s", help="override: fixed settle time"),
    Column("measured_periods", "measured periods", "integer", DIMENSIONLESS, help="override"),
))

TEST_DATA = Table("Test data", optional=True, help="measured force amplitudes, or rig records, to compare with",
                  columns=(
    Column("run", "run", "text", required=True, help="a run name"),
    Column("location", "location", "text", help="'pylon sum' (empty) or a hinge name"),
    Column("direction", "direction", "choice", choices=("x", "y", "z"), help="direction (not with a rig record)"),
    _num("frequency", "frequency", "Hz", help="sweep runs: the frequency measured"),
    _num("amplitude", "amplitude", "N", help="measured force amplitude (not with a rig record)"),
    Column("record", "rig record", "text",
           help="instead of direction and amplitude: a rig record (CSV, relative to the workbook); its measured "
                "pylon T per direction times the run's excitation amplitude"),
    Column("periods", "record periods", "integer", DIMENSIONLESS,
           help="rig record: whole periods per window (empty: the run's measured periods)"),
))

OPTIMISE = Table("Optimise", optional=True,
                 help="the design optimisation mountwb optimise CASE.xlsx runs without --vary "
                      "(docs/optimisation.md); one row per variable, constraint, band, objective or starts",
                 columns=(
    Column("kind", "kind", "choice", choices=("variable", "constraint", "band", "objective", "starts"),
           required=True, help="what the row gives"),
    Column("name", "name", "text",
           help="variable: a study parameter (e.g. hinge_stiffness/front); constraint: displacement, sag, rotation, "
                "fatigue, margin or modes_outside; band: a rotor excitation; objective: worst or weighted"),
    _num("low", "low", help="variable, band or modes_outside: the range's lower end, SI units (N/m, Hz)"),
    _num("high", "high", help="variable, band or modes_outside: the range's upper end, SI units"),
    _num("value", "value", help="constraint: its limit (m, rad, the fatigue factor or the margin of safety); "
                                "starts: SLSQP starts"),
))

#: The input tables in sheet order.
TABLES = (CASE, ENGINE, LINKS, HINGES, STATIC_LOADS, EXCITATIONS, LOAD_CASES, SPEED_SPECTRUM, ROTORS, TEST_RIG, CASING, RUNS, TEST_DATA,
          OPTIMISE)
