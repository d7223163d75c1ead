"""The case model: everything one mount study case needs, as plain frozen data.

A :class:`Case` holds the engine, the connecting links, the hinges between
bodies, the static loads, the excitations, the analysis settings and the
physical effects asked for. Every class is a frozen dataclass that validates
its fields on construction and raises :class:`CaseError` naming the item and
field at fault, so that a workbook reader can point at the offending cell.
Cases pickle (parameter studies send them to worker processes) and convert
to and from JSON-ready dictionaries (:mod:`workbook.model.codec`).

Units are SI throughout: m, kg, s, N, Hz. Axes (docs/physics.md, section 1): x
heading (along the engine axis), y lateral, z vertical (up).

Bodies are named: ``"pylon"`` (ground), ``"engine"`` (the rigid engine) or
the name of a link. A hinge joins two named bodies at one point; on a link
that point must be one of the link's two eye centres.
"""
from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass, field
from typing import Any, Literal, get_args

import numpy as np

from workbook.errors import CaseError
from workbook.model import fields
from workbook.model.casing import CASING, EngineCasing
from workbook.model.field_spec import check_fields, documented, spec
from workbook.model.fields import HINGE_DIRECTIONS, MAX_MODE_COUNT, MAX_SWEEP_POINTS, bounded_count
from workbook.model.load_cases import LoadCase
from workbook.model.pylon import PylonModel
from workbook.model.pylon_beam import BoxBeamPylon
from workbook.model.pylon_impedance import PylonImpedance
from workbook.model.pylon_legacy import accept_legacy_pylons, legacy_pylon
from workbook.model.pylon_mesh import MeshPylon
from workbook.model.spectrum import SpeedSpectrum
from workbook.model.units import DIMENSIONLESS

__all__ = ["PYLON", "ENGINE", "DIRECTIONS", "HINGE_DIRECTIONS", "Engine", "Link", "Hinge",
    "PointForce", "PointMoment", "Gravity", "RotatingForce", "HarmonicForce",
    "Sweep", "AnalysisSettings", "Effects", "Case", "StaticLoad", "Excitation",
    "SingleFrequencyExcitation", "ImbalancePlane", "Imbalance", "RunUp", "SPEED_UNITS",
    "Simultaneous", "ForceTransducers", "Rotor", "ModeCutoff", "ModeRequest", "mode_request",
    "TRANSDUCER_PREFIX", "transducer_name"]

PYLON = "pylon"
ENGINE = "engine"
DIRECTIONS = ("x", "y", "z")
AnalysisMethod = Literal["time", "frequency", "auto"]
#: Analysis methods a case may ask for (AnalysisSettings.method).
ANALYSIS_METHODS: tuple[AnalysisMethod, ...] = get_args(AnalysisMethod)
TimeStart = Literal["auto", "steady", "rest"]
#: Starts a time-domain run may take (AnalysisSettings.start).
TIME_STARTS: tuple[TimeStart, ...] = get_args(TimeStart)
StressStiffening = Literal["auto", "on", "off"]
#: Settings of ``Effects.stress_stiffening``.
STRESS_STIFFENING: tuple[StressStiffening, ...] = get_args(StressStiffening)
_RESERVED = (PYLON, ENGINE)
# Two points closer than this (m) are the same point (a hinge on a link eye).
POINT_TOLERANCE = 1e-6

Vector3 = tuple[float, float, float]


class ModeCutoff(float):
    """A cut-off frequency of a link's fixed-interface modes, Hz.

    A mode count is a whole number (``modes=12`` keeps 12 modes); a cut-off
    is this type or a text with its unit (``modes=ModeCutoff(500.0)`` or
    ``modes="500 Hz"`` keeps the modes up to 500 Hz). A plain float is
    refused, so ``modes=12.0`` cannot silently mean 12 Hz. It is a float for
    :mod:`flexbodies` (which reads a float as a cut-off) and for JSON (where
    a number with a fraction in a link's ``modes`` is a cut-off).
    """

    def __repr__(self) -> str:
        return f"ModeCutoff({float(self)!r})"

    def __str__(self) -> str:
        return f"{float(self):g} Hz"


#: What a link's reduction keeps: ``"auto"`` (the low-frequency rule),
#: ``"static"`` (static modes only), a mode count or a cut-off frequency.
ModeRequest = str | int | ModeCutoff

_CUTOFF_TEXT = re.compile(r"^\s*(?:up to\s+)?([0-9]*\.?[0-9]+(?:e[+-]?[0-9]+)?)\s*hz\s*$", re.IGNORECASE)


def mode_request(value: Any, item: str = "link") -> ModeRequest:
    """*value* as a :data:`ModeRequest`, or raise CaseError.

    Accepts ``"auto"``, ``"static"``, a whole number >= 0 (a count), a
    :class:`ModeCutoff` > 0 or a text ``"<f> Hz"`` / ``"up to <f> Hz"`` (a
    cut-off); refuses a plain float (count or cut-off? say which).
    """
    expected = "'auto', 'static', a whole mode count such as 12 or a cut-off such as '500 Hz'"
    if isinstance(value, ModeCutoff):
        if not (value > 0 and math.isfinite(value)):
            raise CaseError(item, "modes", value, "a cut-off frequency > 0 Hz")
        return value
    if isinstance(value, str):
        word = value.strip().lower()
        if word in ("auto", "static"):
            return word
        match = _CUTOFF_TEXT.match(word)
        if match:
            return mode_request(ModeCutoff(float(match.group(1))), item)
        raise CaseError(item, "modes", value, expected)
    if isinstance(value, int) and not isinstance(value, bool) and value >= 0:
        return bounded_count(item, "modes", value, 0, MAX_MODE_COUNT, "the most modes a reduction keeps by count")
    if isinstance(value, float):
        raise CaseError(item, "modes", value, f"{expected} (a plain float is ambiguous: "
                        f"write {int(value) if value.is_integer() and value >= 0 else 'a whole number'} for a count "
                        f"or '{value:g} Hz' for a cut-off)")
    raise CaseError(item, "modes", value, expected)


def _set(obj: Any, name: str, value: Any) -> None:
    """Normalise a field of a frozen dataclass in ``__post_init__``."""
    object.__setattr__(obj, name, value)


@documented
@dataclass(frozen=True)
class Engine:
    """The engine: one rigid body, or a flexible casing and a rigid core."""

    mass: float = field(metadata=spec("Mass of the engine", unit="kg", minimum=0.0, strictly=True,
                                      help="engine mass (t accepted)"))
    center_of_mass: Vector3 = field(metadata=spec(
        "Centre of gravity in the global frame", type="3 floats", check="vector3", unit="m", column="cg",
        help="centre of gravity"))
    inertia: tuple[Vector3, Vector3, Vector3] = field(metadata=spec(
        "Inertia tensor about the centre of gravity, global axes: symmetric, positive definite, its principal "
        "moments obeying the triangle inequality", type="3x3 floats", check="own", unit="kg*m^2"))
    casing: EngineCasing | None = field(default=None, metadata=spec(
        "The casing as a flexible body (None: the engine is one rigid body); see :mod:`workbook.model.casing`",
        type="EngineCasing", check="own", optional=True))

    def __post_init__(self):
        item = "engine"
        check_fields(self, item)
        try:
            rows = tuple(fields.vector3(item, "inertia", row) for row in self.inertia)
        except TypeError:
            raise CaseError(item, "inertia", self.inertia, "a 3x3 tensor") from None
        if len(rows) != 3:
            raise CaseError(item, "inertia", self.inertia, "a 3x3 tensor")
        tensor = np.array(rows)
        if not np.allclose(tensor, tensor.T, rtol=1e-9, atol=1e-9 * np.abs(tensor).max()):
            raise CaseError(item, "inertia", self.inertia, "a symmetric tensor")
        principal = np.linalg.eigvalsh(tensor)
        if principal[0] <= 0 or 2 * principal.max() > principal.sum() * (1 + 1e-9):
            raise CaseError(item, "inertia", self.inertia,
                            "a positive definite tensor whose principal moments obey the "
                            "triangle inequality")
        _set(self, "inertia", rows)
        if self.casing is not None and not isinstance(self.casing, EngineCasing):
            raise CaseError(item, "casing", self.casing, "an EngineCasing or None")

    @property
    def inertia_matrix(self) -> np.ndarray:
        """Inertia tensor about the centre of gravity as a 3x3 array, kg m^2."""
        return np.array(self.inertia)


@documented
@dataclass(frozen=True)
class Link:
    """A connecting link with a ball hinge eye at each end."""

    name: str = field(metadata=spec('Unique name, e.g. ``"front-left"``', type="str", check="own"))
    end_a: Vector3 = field(metadata=spec(
        "Global position of the centre of eye A", type="3 floats", check="vector3", unit="m",
        help="centre of eye A"))
    end_b: Vector3 = field(metadata=spec(
        "Global position of the centre of eye B: as far from *end_a* as the link model's eye distance",
        type="3 floats", check="vector3", unit="m", help="centre of eye B"))
    model: Any = field(metadata=spec("Geometry or mesh, material, meshing and interface choices",
                                     type="flexbodies.LinkModel", check="own"))
    modes: ModeRequest = field(default="auto", metadata=spec(
        "Craig-Bampton fixed-interface modes kept: the low-frequency rule, none, a count, or a cut-off frequency "
        '(:class:`ModeCutoff` or ``"500 Hz"``); see :func:`mode_request`',
        type='{"auto", "static"} or int or ModeCutoff or str', check="own"))
    flexible: bool = field(default=True, metadata=spec(
        "False models the link as a rigid body with the same mass properties", type="bool", check="flag"))
    stiffness_damping: float = field(default=0.0, metadata=spec(
        "Rayleigh stiffness-proportional damping of the link", unit="s", minimum=0.0,
        help="Rayleigh stiffness-proportional damping"))
    mass_damping: float = field(default=0.0, metadata=spec(
        "Rayleigh mass-proportional damping of the link", unit="1/s", minimum=0.0,
        help="Rayleigh mass-proportional damping"))
    spin_frequency_hz: float | None = field(default=None, metadata=spec(
        "Frequency of the torsional restraint of the free spin about the link axis (None: the flexbodies "
        "default)", unit="Hz", minimum=0.0, strictly=True, optional=True,
        help="torsional restraint about the link axis"))
    bore_axis: Vector3 | None = field(default=None, metadata=spec(
        "Global direction of the bore axes (None: the flexbodies default)", type="3 floats", check="vector3",
        unit=DIMENSIONLESS, optional=True, help="global direction of the bore axes (empty: default)"))
    loss_factor: float = field(default=0.0, metadata=spec(
        "Material loss factor eta of the link (complex modulus: the link's elastic stiffness acts as "
        "K (1 + i eta))", unit=DIMENSIONLESS, minimum=0.0,
        help="material loss factor eta: complex modulus E (1 + i eta) (empty: 0)"))
    modal_damping: float = field(default=0.0, metadata=spec(
        "Damping ratio zeta of each of the link's elastic modes (the free-free modes of its reduced model, "
        "the coordinates of its flexible body): a modal damper ``2 zeta w_i`` per mass-normalised mode, in "
        "both domains; below 1", unit=DIMENSIONLESS, minimum=0.0,
        help="damping ratio zeta of each elastic mode of the link (empty: 0)"))

    def __post_init__(self):
        item = f"link {self.name!r}"
        fields.nonempty_name("link", self.name)
        if self.name in _RESERVED:
            raise CaseError(item, "name", self.name, f"a name other than {_RESERVED}")
        check_fields(self, item)
        if self.length <= POINT_TOLERANCE:
            raise CaseError(item, "end_b", self.end_b, "a point apart from end_a")
        geometry = getattr(self.model, "geometry", None)
        if geometry is not None and abs(geometry.length - self.length) > 1e-6 * max(1.0, self.length):
            raise CaseError(item, "end_b", self.end_b,
                            f"a point {geometry.length:g} m from end_a (the link's eye distance); "
                            f"the ends are {self.length:g} m apart")
        _set(self, "modes", mode_request(self.modes, item))
        if self.modal_damping >= 1.0:
            raise CaseError(item, "modal_damping", self.modal_damping, "a damping ratio >= 0 and < 1")

    @property
    def length(self) -> float:
        """Distance between the eye centres, m."""
        return float(np.linalg.norm(np.subtract(self.end_b, self.end_a)))

    def eye_at(self, point: Vector3) -> str | None:
        """Return ``"a"`` or ``"b"`` if *point* is that eye's centre, else None."""
        for eye, end in (("a", self.end_a), ("b", self.end_b)):
            if math.dist(point, end) <= POINT_TOLERANCE:
                return eye
        return None


def _frame(value: Any, item: str) -> tuple[Vector3, Vector3, Vector3]:
    """*value* as three orthonormal rows (a hinge frame) or raise CaseError."""
    try:
        rows = tuple(fields.vector3(item, "frame", row) for row in value)
    except TypeError:
        raise CaseError(item, "frame", value, "three directions of three numbers each") from None
    if len(rows) != 3:
        raise CaseError(item, "frame", value, f"three directions ({', '.join(HINGE_DIRECTIONS)}); "
                                              f"{len(rows)} given")
    matrix = np.array(rows)
    if not np.allclose(matrix @ matrix.T, np.eye(3), rtol=0.0, atol=1e-6):
        raise CaseError(item, "frame", value, "three orthonormal directions (unit length, at right angles "
                                              "to each other, within 1e-6)")
    return rows


@documented
@dataclass(frozen=True)
class Hinge:
    """A ball hinge: a translational spring-damper between two bodies.

    Stiffness, damping and loss factor are either one value (the same in
    every direction: isotropic, the default) or three, one per direction of
    the hinge's frame (:data:`HINGE_DIRECTIONS`): two radial and one along
    the bore (pin) axis, as a spherical bearing in a link eye is stiffer
    radially than along its pin.
    """

    name: str = field(metadata=spec('Unique name, e.g. ``"front-up-left"``', type="str", check="own"))
    body_a: str = field(metadata=spec('A body joined: ``"pylon"``, ``"engine"`` or a link name', type="str",
                                      check="own"))
    body_b: str = field(metadata=spec("The other body joined, likewise", type="str", check="own"))
    position: Vector3 = field(metadata=spec(
        "Hinge centre; on a link it must be one of the link's eye centres", type="3 floats", check="vector3",
        unit="m", help="hinge centre: an eye centre of its links"))
    stiffness: float | Vector3 = field(metadata=spec(
        "Translational stiffness: in every direction, or per direction of the frame", type="float or 3 floats",
        check="per_direction", unit="N/m", minimum=0.0, strictly=True,
        help="translational stiffness (with the radial 2 or axial columns: radial 1)"))
    damping: float | Vector3 = field(default=0.0, metadata=spec(
        "Translational (viscous) damping, likewise", type="float or 3 floats", check="per_direction",
        unit="N*s/m", minimum=0.0, help="translational damping (empty: 0)"))
    radial_clearance: float = field(default=0.0, metadata=spec(
        "Gap of the spherical bearing (0: no clearance law is built)", unit="m", minimum=0.0,
        help="bearing gap (empty: 0)"))
    contact_stiffness: float | None = field(default=None, metadata=spec(
        "Stiffness once the gap is closed (None: *stiffness*)", unit="N/m", minimum=0.0, strictly=True,
        optional=True, help="stiffness once the gap closes"))
    loss_factor: float | Vector3 = field(default=0.0, metadata=spec(
        "Structural (hysteretic) loss factor eta: the hinge's stiffness acts as k (1 + i eta), a damping force "
        "in phase with the velocity whose size does not grow with the frequency (docs/physics.md, hinge "
        "damping); likewise one or three values", type="float or 3 floats", check="per_direction",
        unit=DIMENSIONLESS, minimum=0.0, help="structural loss factor eta, k (1 + i eta) (empty: 0)"))
    frame: tuple[Vector3, Vector3, Vector3] | None = field(default=None, metadata=spec(
        "The hinge's directions radial 1, radial 2, axial as rows, in global coordinates (orthonormal). None: "
        "the frame of the link the hinge sits on (radial 1 along the link towards eye B, axial along its bore "
        "axis), or the global axes x, y, z for a hinge between the pylon and the engine. Only per-direction "
        "values use it", type="3x3 floats", check="own", optional=True))

    def __post_init__(self):
        item = f"hinge {self.name!r}"
        fields.nonempty_name("hinge", self.name)
        for name in ("body_a", "body_b"):
            if not isinstance(getattr(self, name), str) or not getattr(self, name):
                raise CaseError(item, name, getattr(self, name), "a body name")
        if self.body_a == self.body_b:
            raise CaseError(item, "body_b", self.body_b, "a body other than body_a")
        check_fields(self, item)
        if self.frame is not None:
            _set(self, "frame", _frame(self.frame, item))
        if self.radial_clearance > 0 and not self.isotropic:
            raise CaseError(item, "stiffness", self.stiffness, "one value (the same in every direction) for a "
                            "hinge with a radial clearance: the clearance law is isotropic")

    @property
    def isotropic(self) -> bool:
        """True if stiffness, damping and loss factor are each the same in every direction."""
        return all(isinstance(value, float) or len(set(value)) == 1
                   for value in (self.stiffness, self.damping, self.loss_factor))

    def values(self, name: str) -> np.ndarray:
        """*name* (``"stiffness"``, ``"damping"`` or ``"loss_factor"``) per hinge direction, shape (3,)."""
        value = getattr(self, name)
        return np.full(3, value) if isinstance(value, float) else np.broadcast_to(
            np.asarray(value, dtype=float), (3,)).copy()

    @property
    def largest_stiffness(self) -> float:
        """The largest of the stiffness and contact stiffness, N/m (for scaling)."""
        return float(max(self.values("stiffness").max(), self.gap_contact_stiffness))

    @property
    def bodies(self) -> tuple[str, str]:
        return self.body_a, self.body_b

    @property
    def on_pylon(self) -> bool:
        """True for a pylon-side hinge (one of its bodies is the pylon)."""
        return PYLON in self.bodies

    @property
    def gap_contact_stiffness(self) -> float:
        """Stiffness beyond the gap, N/m (the largest stiffness for a hinge with three)."""
        if self.contact_stiffness is not None:
            return self.contact_stiffness
        return float(self.values("stiffness").max())


_LOAD_NAME = spec("Unique name of the static load", type="str", check="own")


@documented
@dataclass(frozen=True)
class PointForce:
    """A constant force on the engine at a point (thrust, a static load)."""

    name: str = field(metadata=_LOAD_NAME)
    force: Vector3 = field(metadata=spec("The force, global axes", type="3 floats", check="vector3", unit="N",
                                         help="force"))
    point: Vector3 = field(metadata=spec("Where it acts, global frame", type="3 floats", check="vector3", unit="m",
                                         help="point of the force"))

    def __post_init__(self):
        fields.nonempty_name("static load", self.name)
        check_fields(self, f"static load {self.name!r}")


@documented
@dataclass(frozen=True)
class PointMoment:
    """A constant moment on the engine."""

    name: str = field(metadata=_LOAD_NAME)
    moment: Vector3 = field(metadata=spec("The moment, global axes", type="3 floats", check="vector3", unit="N*m",
                                          help="moment"))

    def __post_init__(self):
        fields.nonempty_name("static load", self.name)
        check_fields(self, f"static load {self.name!r}")


@documented
@dataclass(frozen=True)
class Gravity:
    """Gravitational acceleration acting on every body (engine and links)."""

    name: str = field(default="gravity", metadata=_LOAD_NAME)
    acceleration: Vector3 = field(default=(0.0, 0.0, -9.81), metadata=spec(
        "The acceleration of gravity, global axes (z up: 1 g level flight is (0, 0, -9.81))", type="3 floats",
        check="vector3", unit="m/s^2", help="gravitational acceleration ('g' = 9.80665 m/s^2)"))

    def __post_init__(self):
        fields.nonempty_name("static load", self.name)
        check_fields(self, f"static load {self.name!r}")


StaticLoad = PointForce | PointMoment | Gravity


@documented
@dataclass(frozen=True)
class ForceTransducers:
    """The test rig's three-way force transducers between the pylon pins and the rigid ground.

    On the rig the pylon-side hinges do not sit on rigid ground: each pylon
    pin is carried by a three-component force transducer bolted to the rig
    floor, and that transducer is a stiff spring. The scene then gets one
    transducer per pylon pin (pylon-side hinges at the same point share
    one): a point mass at the pin on a spring-damper to ground, and the pin's
    hinges attach to that mass. The transducer forces are what the rig
    measures, so they make the pylon force.
    """

    stiffness: Vector3 = field(metadata=spec(
        "Stiffness of each transducer with its fixture in the global x, y, z directions (a three-component "
        "piezoelectric force link with its mounting is of order 1e8 to 1e9 N/m)", type="3 floats",
        check="vector3", unit="N/m", minimum=0.0, strictly=True, help="stiffness of each transducer with its fixture"))
    mass: float = field(default=1.0, metadata=spec(
        "Moving half of each transducer plus the fitting bolted to it. The default 1 kg is a force link of this "
        "load range (a few hundred grams, half of it moving) with the clevis block of the pin on it; the mass "
        "only has to be there (a node between two springs needs one in Exudyn): at 1e8 N/m it resonates at "
        "1.6 kHz, far above the rotor frequencies. It carries no weight in the scene: a rig zeroes its "
        "transducers with the fitting mounted, before the engine is hung", unit="kg", minimum=0.0,
        strictly=True, help="moving mass of each transducer with its fitting (empty: 1 kg)"))
    damping: Vector3 = field(default=(0.0, 0.0, 0.0), metadata=spec(
        "Viscous damping of each transducer in x, y, z (piezoelectric force links are very lightly damped: "
        "default 0)", type="3 floats", check="vector3", unit="N*s/m", minimum=0.0,
        help="damping of each transducer (empty: 0)"))

    def __post_init__(self):
        check_fields(self, "test-rig force transducers")


#: A test-rig transducer is named by this prefix and the pylon-side hinges it carries.
TRANSDUCER_PREFIX = "transducer "


def _points_of(hinges) -> list[tuple[Vector3, list[str]]]:
    """The distinct positions of *hinges* (m), each with the names of the hinges
    on it (hinges closer than the point tolerance share a point)."""
    points: list[tuple[Vector3, list[str]]] = []
    for hinge in hinges:
        point = next((point for point in points
                      if np.linalg.norm(np.subtract(point[0], hinge.position)) <= POINT_TOLERANCE), None)
        if point is None:
            points.append((hinge.position, [hinge.name]))
        else:
            point[1].append(hinge.name)
    return points


def transducer_name(carried) -> str:
    """Name of the test-rig transducer under the pylon pin of the hinges *carried* (their names)."""
    return TRANSDUCER_PREFIX + " + ".join(carried)


def _frequency(item: str, frequency_hz: Any, rpm: Any) -> float:
    """Validate that exactly one of frequency_hz and rpm is given; return Hz."""
    if (frequency_hz is None) == (rpm is None):
        raise CaseError(item, "frequency_hz", frequency_hz, "either frequency_hz or rpm, not both")
    if frequency_hz is not None:
        return fields.positive_number(item, "frequency_hz", frequency_hz)
    return fields.positive_number(item, "rpm", rpm) / 60.0


class _OneFrequency:
    """The frequency of an excitation given as ``frequency_hz`` or ``rpm``."""

    frequency_hz: float | None
    rpm: float | None

    @property
    def frequency(self) -> float:
        """Excitation frequency, Hz."""
        return _frequency("", self.frequency_hz, self.rpm)


_EXCITATION_NAME = spec('Unique name, e.g. ``"LP rotor"``', type="str", check="own")
_SPEED = spec("Frequency; give exactly one of *frequency_hz* and *rpm*", check="own", unit="Hz", minimum=0.0,
              strictly=True, optional=True, column="frequency", help="frequency (rpm accepted); empty for a sweep")
_RPM = spec("Frequency in revolutions per minute, instead of *frequency_hz*; > 0", check="own", optional=True)
_PHASE = spec("Phase at t = 0", unit="deg", column="phase", help="phase at t = 0 (empty: 0)")
_IMBALANCE_POINT = spec("The rotor's imbalance plane on the engine axis", type="3 floats", check="vector3", unit="m",
                        help="point of application on the engine")
_AMPLITUDE = spec("Force amplitude A; give exactly one of *amplitude* and *unbalance*", unit="N", minimum=0.0,
                  strictly=True, optional=True, help="force amplitude")
_UNBALANCE = spec("The unbalance m*e (then A = m e w^2)", unit="kg*m", minimum=0.0, strictly=True, optional=True,
                  help="rotating: unbalance m e instead of the amplitude ('g' = gram)")
_SPIN_AXIS = spec("Spin axis (not necessarily unit length)", type="3 floats", check="direction", unit=DIMENSIONLESS,
                  help="rotating: spin axis (empty: x)")


@documented
@dataclass(frozen=True)
class RotatingForce(_OneFrequency):
    """A rotating imbalance force on the engine.

    The force of magnitude A turns in the plane normal to *axis*, right-handed
    about it: ``F(t) = A (u cos(wt + phase) + v sin(wt + phase))`` with
    ``(u, v, axis)`` a right-handed orthonormal triad (for axis x: u = y,
    v = z, i.e. lateral plus vertical).
    """

    name: str = field(metadata=_EXCITATION_NAME)
    point: Vector3 = field(metadata=_IMBALANCE_POINT)
    frequency_hz: float | None = field(default=None, metadata=_SPEED)
    rpm: float | None = field(default=None, metadata=_RPM)
    amplitude: float | None = field(default=None, metadata=_AMPLITUDE)
    unbalance: float | None = field(default=None, metadata=_UNBALANCE)
    axis: Vector3 = field(default=(1.0, 0.0, 0.0), metadata=_SPIN_AXIS)
    phase_deg: float = field(default=0.0, metadata=_PHASE)

    def __post_init__(self):
        item = f"excitation {self.name!r}"
        fields.nonempty_name("excitation", self.name)
        check_fields(self, item)
        _frequency(item, self.frequency_hz, self.rpm)
        if (self.amplitude is None) == (self.unbalance is None):
            raise CaseError(item, "amplitude", self.amplitude, "either amplitude or unbalance, not both")

    @property
    def force_amplitude(self) -> float:
        """Force amplitude, N."""
        if self.amplitude is not None:
            return self.amplitude
        assert self.unbalance is not None
        return self.unbalance * (2 * math.pi * self.frequency) ** 2

    def force_coefficients(self) -> tuple[np.ndarray, np.ndarray]:
        """Return (C, S) with ``F(t) = C cos(wt) + S sin(wt)``, N."""
        axis = np.asarray(self.axis) / np.linalg.norm(self.axis)
        # u: the global axis least aligned with the spin axis, made normal to
        # it (for an x spin axis u = y and v = +-z).
        helper = np.eye(3)[np.argmin(np.abs(axis))]
        u = helper - axis * (helper @ axis)
        u /= np.linalg.norm(u)
        v = np.cross(axis, u)
        phase = math.radians(self.phase_deg)
        amplitude = self.force_amplitude
        cos_part = amplitude * (u * math.cos(phase) + v * math.sin(phase))
        sin_part = amplitude * (v * math.cos(phase) - u * math.sin(phase))
        return cos_part, sin_part

    def point_forces(self) -> tuple[tuple[Vector3, np.ndarray, np.ndarray], ...]:
        """The forces at their points: ``((point, C, S),)`` (see :meth:`force_coefficients`)."""
        return ((self.point, *self.force_coefficients()),)


@documented
@dataclass(frozen=True)
class HarmonicForce(_OneFrequency):
    """A fixed-direction harmonic force on the engine: ``F(t) = A d cos(wt + phase)``."""

    name: str = field(metadata=_EXCITATION_NAME)
    point: Vector3 = field(metadata=spec("Point of application on the engine", type="3 floats", check="vector3",
                                         unit="m", help="point of application on the engine"))
    direction: Vector3 = field(metadata=spec("Direction d (normalised where it is used)", type="3 floats",
                                             check="direction", unit=DIMENSIONLESS, help="harmonic: force direction"))
    amplitude: float = field(metadata=spec("Force amplitude A", unit="N", minimum=0.0, strictly=True,
                                           help="force amplitude"))
    frequency_hz: float | None = field(default=None, metadata=_SPEED)
    rpm: float | None = field(default=None, metadata=_RPM)
    phase_deg: float = field(default=0.0, metadata=_PHASE)

    def __post_init__(self):
        item = f"excitation {self.name!r}"
        fields.nonempty_name("excitation", self.name)
        check_fields(self, item)
        _frequency(item, self.frequency_hz, self.rpm)

    @property
    def force_amplitude(self) -> float:
        """Force amplitude, N."""
        return self.amplitude

    def force_coefficients(self) -> tuple[np.ndarray, np.ndarray]:
        """Return (C, S) with ``F(t) = C cos(wt) + S sin(wt)``, N."""
        d = np.asarray(self.direction) / np.linalg.norm(self.direction)
        phase = math.radians(self.phase_deg)
        return self.amplitude * math.cos(phase) * d, -self.amplitude * math.sin(phase) * d

    def point_forces(self) -> tuple[tuple[Vector3, np.ndarray, np.ndarray], ...]:
        """The forces at their points: ``((point, C, S),)`` (see :meth:`force_coefficients`)."""
        return ((self.point, *self.force_coefficients()),)


@documented
@dataclass(frozen=True)
class ImbalancePlane:
    """One imbalance plane of a rotor: an eccentric mass at a point on the spin axis.

    The unbalance gives a force growing with the speed (U w^2), the amplitude
    a force of its own; the phase is the angular position of the eccentric
    mass. The :class:`Imbalance` holding the plane checks it (:meth:`check`).
    """

    point: Vector3 = field(metadata=_IMBALANCE_POINT)
    unbalance: float | None = field(default=None, metadata=_UNBALANCE)
    amplitude: float | None = field(default=None, metadata=_AMPLITUDE)
    phase_deg: float = field(default=0.0, metadata=_PHASE)

    def check(self, item: str) -> "ImbalancePlane":
        """The plane with validated fields; *item* names it in a CaseError."""
        plane = dataclasses.replace(self)
        check_fields(plane, item)
        if (plane.amplitude is None) == (plane.unbalance is None):
            raise CaseError(item, "unbalance", plane.unbalance, "either unbalance or amplitude, not both")
        return plane


@documented
@dataclass(frozen=True)
class Imbalance(_OneFrequency):
    """Several imbalance planes of one rotor at one speed, as a rig's rotary
    exciter applies them (eccentric masses at the front support, the centre of
    gravity and the rear support, say).

    Plane k exerts the rotating force of a :class:`RotatingForce` at its
    point, with its own unbalance (or amplitude) and phase; all turn at the
    same speed about the same axis. The transmissibility refers to the sum
    of the plane force amplitudes (:attr:`force_amplitude`): the force of
    planes in phase, and never zero, also when the planes form a couple.
    """

    name: str = field(metadata=_EXCITATION_NAME)
    planes: tuple[ImbalancePlane, ...] = field(metadata=spec(
        "At least one plane (plane k is named ``\"<name> plane <k>\"``)", type="tuple of ImbalancePlane",
        check="own"))
    frequency_hz: float | None = field(default=None, metadata=_SPEED)
    rpm: float | None = field(default=None, metadata=_RPM)
    axis: Vector3 = field(default=(1.0, 0.0, 0.0), metadata=_SPIN_AXIS)

    def __post_init__(self):
        item = f"excitation {self.name!r}"
        fields.nonempty_name("excitation", self.name)
        _frequency(item, self.frequency_hz, self.rpm)
        check_fields(self, item)
        try:
            planes = tuple(self.planes)
        except TypeError:
            raise CaseError(item, "planes", self.planes, "a list of imbalance planes") from None
        if not planes or not all(isinstance(p, ImbalancePlane) for p in planes):
            raise CaseError(item, "planes", self.planes, "one or more ImbalancePlane")
        _set(self, "planes", tuple(p.check(f"{item} plane {k}") for k, p in enumerate(planes, start=1)))

    def plane_forces(self) -> tuple[RotatingForce, ...]:
        """Each plane as the rotating force it exerts, named ``"<name> plane <k>"``."""
        return tuple(RotatingForce(f"{self.name} plane {k}", plane.point, frequency_hz=self.frequency,
                                   amplitude=plane.amplitude, unbalance=plane.unbalance, axis=self.axis,
                                   phase_deg=plane.phase_deg)
                     for k, plane in enumerate(self.planes, start=1))

    @property
    def force_amplitude(self) -> float:
        """Sum of the plane force amplitudes, N (the reference of the transmissibility)."""
        return sum(force.force_amplitude for force in self.plane_forces())

    def point_forces(self) -> tuple[tuple[Vector3, np.ndarray, np.ndarray], ...]:
        """The plane forces at their points: ``(point, C, S)`` per plane."""
        return tuple(part for force in self.plane_forces() for part in force.point_forces())


SingleFrequencyExcitation = RotatingForce | HarmonicForce | Imbalance
SINGLE_FREQUENCY_KINDS = (RotatingForce, HarmonicForce, Imbalance)


@documented
@dataclass(frozen=True)
class Rotor(_OneFrequency):
    """A rotor spinning at constant speed in the engine: its gyroscopic moment.

    A rotor of polar moment of inertia Ip spinning at the constant rate
    Omega = 2 pi f about the engine-fixed unit axis a carries the angular
    momentum ``h = Ip Omega a``. When the engine turns with angular velocity
    omega (global), a turns with it and the rotor exerts on the engine the
    moment ``M = -dh/dt = -Ip Omega (omega x a)``. The rotor's mass and
    transverse inertia stay lumped in the rigid engine (``Case.engine``);
    only this moment is added (``Effects.gyroscopics``).
    """

    name: str = field(metadata=spec('Unique name, e.g. ``"LP spool"``', type="str", check="own"))
    polar_inertia: float = field(metadata=spec(
        "Polar moment of inertia Ip about the spin axis", unit="kg*m^2", minimum=0.0, strictly=True,
        help="polar moment of inertia about the spin axis"))
    frequency_hz: float | None = field(default=None, metadata=spec(
        "Spin speed; give exactly one of *frequency_hz* and *rpm*", check="own", unit="Hz", minimum=0.0,
        strictly=True, optional=True, help="spin speed (rpm accepted)"))
    rpm: float | None = field(default=None, metadata=spec(
        "Spin speed in revolutions per minute, instead of *frequency_hz*; > 0", check="own", optional=True))
    axis: Vector3 = field(default=(1.0, 0.0, 0.0), metadata=spec(
        "Spin axis in engine coordinates (the global axes at the reference state); normalised here. The rotor "
        "spins right-handed about it", type="3 floats", check="direction", unit=DIMENSIONLESS))

    def __post_init__(self):
        item = f"rotor {self.name!r}"
        fields.nonempty_name("rotor", self.name)
        check_fields(self, item)
        _frequency(item, self.frequency_hz, self.rpm)
        axis = np.asarray(self.axis)
        _set(self, "axis", tuple(float(v) for v in axis / np.linalg.norm(axis)))

    @property
    def angular_momentum(self) -> np.ndarray:
        """Spin angular momentum ``h = Ip Omega a`` in engine coordinates, kg m^2/s, shape (3,)."""
        return self.polar_inertia * 2 * math.pi * self.frequency * np.asarray(self.axis)


#: Spacings of the frequencies of :meth:`Sweep.band`.
SweepSpacing = Literal["log", "linear"]


@documented
@dataclass(frozen=True)
class Sweep:
    """A stepped sweep: one excitation template run at each of several frequencies.

    A workbook row gives it by its band (:meth:`band`): first and last
    frequency, number of points and spacing.
    """

    name: str = field(metadata=_EXCITATION_NAME)
    template: SingleFrequencyExcitation = field(metadata=spec(
        "The excitation; its own frequency is replaced by each sweep frequency (an unbalance given as m*e gives "
        "a force growing with frequency^2)", type="RotatingForce, HarmonicForce or Imbalance", check="own"))
    frequencies_hz: tuple[float, ...] = field(metadata=spec(
        f"The frequencies, ascending; at most {MAX_SWEEP_POINTS:,}", type="floats", check="own", unit="Hz",
        minimum=0.0, strictly=True))

    def __post_init__(self):
        item = f"excitation {self.name!r}"
        fields.nonempty_name("excitation", self.name)
        if not isinstance(self.template, SINGLE_FREQUENCY_KINDS):
            raise CaseError(item, "template", self.template, "a RotatingForce, HarmonicForce or Imbalance")
        try:
            if len(self.frequencies_hz) > MAX_SWEEP_POINTS:
                raise CaseError(item, "frequencies_hz", f"{len(self.frequencies_hz):,} frequencies",
                                f"at most {MAX_SWEEP_POINTS:,} frequencies (the most points a sweep takes)")
            frequencies = tuple(fields.positive_number(item, "frequencies_hz", f)
                                for f in self.frequencies_hz)
        except TypeError:
            raise CaseError(item, "frequencies_hz", self.frequencies_hz, "a list of frequencies") from None
        if not frequencies or any(b <= a for a, b in zip(frequencies, frequencies[1:], strict=False)):
            raise CaseError(item, "frequencies_hz", self.frequencies_hz, "ascending frequencies")
        _set(self, "frequencies_hz", frequencies)

    @classmethod
    def band(cls, name: str, template: SingleFrequencyExcitation, start_hz: float, stop_hz: float,
             points: int, spacing: SweepSpacing = "log") -> "Sweep":
        """A sweep of *points* frequencies from *start_hz* to *stop_hz* (``"log"`` or ``"linear"``)."""
        if spacing not in ("log", "linear"):
            raise CaseError(f"excitation {name!r}", "spacing", spacing, "'log' or 'linear'")
        item = f"excitation {name!r}"
        start_hz = fields.positive_number(item, "start", start_hz)
        stop_hz = fields.positive_number(item, "stop", stop_hz)
        points = bounded_count(item, "points", points, 1, MAX_SWEEP_POINTS, "the most points a sweep takes")
        space = np.geomspace if spacing == "log" else np.linspace
        return cls(name, template, tuple(float(f) for f in space(start_hz, stop_hz, points)))

    @property
    def frequency(self) -> float:
        """Highest frequency of the sweep, Hz."""
        return self.frequencies_hz[-1]

    def expand(self) -> tuple[SingleFrequencyExcitation, ...]:
        """The single-frequency excitations of the sweep, named ``"<name> @ <f> Hz"``."""
        return tuple(dataclasses.replace(self.template, name=f"{self.name} @ {f:.6g} Hz",
                                         frequency_hz=f, rpm=None)
                     for f in self.frequencies_hz)


#: Speed units of a run-up and their factor to Hz.
SPEED_UNITS = {"rpm": 1.0 / 60.0, "Hz": 1.0}
#: The keys of :data:`SPEED_UNITS`.
SpeedUnit = Literal["rpm", "Hz"]


@documented
@dataclass(frozen=True)
class RunUp(Sweep):
    """A run-up: a rotor imbalance at evenly spaced speeds, its force growing as U w^2.

    A :class:`Sweep` whose template is an unbalance (a :class:`RotatingForce`
    given by ``unbalance``, or an :class:`Imbalance` whose planes all are),
    so that the force amplitude grows with the square of the speed, and
    whose speeds are kept in the unit they were given in.
    """

    template: SingleFrequencyExcitation = field(metadata=spec(
        "The imbalance, given by its unbalance; its own speed is replaced by each run-up speed",
        type="RotatingForce or Imbalance", check="own"))
    speed_unit: SpeedUnit = field(default="rpm", metadata=spec(
        "The unit the speeds are tabulated and plotted in", type="str", check="choice", choices=tuple(SPEED_UNITS),
        column="run_up", help="run-up: the sweep's speeds evenly spaced, tabulated in this unit; the force grows "
                              "as U w^2 (give the unbalance)"))

    def __post_init__(self):
        super().__post_init__()
        item = f"excitation {self.name!r}"
        check_fields(self, item)
        planes = (self.template.planes if isinstance(self.template, Imbalance)
                  else (self.template,) if isinstance(self.template, RotatingForce) else ())
        if not planes or any(plane.unbalance is None for plane in planes):
            raise CaseError(item, "unbalance", None, "an unbalance on every imbalance plane (a run-up's force "
                            "grows as U w^2; a rotating force or imbalance given by its unbalance)")

    @classmethod
    def speeds(cls, name: str, template: SingleFrequencyExcitation, start: float, stop: float, points: int,
               unit: SpeedUnit = "rpm") -> "RunUp":
        """A run-up over *points* evenly spaced speeds from *start* to *stop*, in *unit* (rpm or Hz)."""
        item = f"excitation {name!r}"
        if unit not in SPEED_UNITS:
            raise CaseError(item, "speed_unit", unit, " or ".join(repr(u) for u in SPEED_UNITS))
        start = fields.positive_number(item, "start", start)
        stop = fields.positive_number(item, "stop", stop)
        if stop <= start:
            raise CaseError(item, "stop", stop, f"a speed above the start ({start:g} {unit})")
        points = bounded_count(item, "points", points, 2, MAX_SWEEP_POINTS, "the most speeds a run-up takes")
        factor = SPEED_UNITS[unit]
        return cls(name, template, tuple(float(s) * factor for s in np.linspace(start, stop, points)), unit)

    @property
    def speed_values(self) -> np.ndarray:
        """The speeds in :attr:`speed_unit`."""
        return np.asarray(self.frequencies_hz) / SPEED_UNITS[self.speed_unit]

    def expand(self) -> tuple[SingleFrequencyExcitation, ...]:
        """The single-speed excitations of the run-up, named ``"<name> @ <speed> <unit>"``."""
        return tuple(dataclasses.replace(point, name=f"{self.name} @ {speed:.6g} {self.speed_unit}")
                     for point, speed in zip(super().expand(), self.speed_values, strict=True))


@documented
@dataclass(frozen=True)
class Simultaneous:
    """Several single-frequency excitations acting at once, each at its own
    frequency: both rotors of a two-spool engine (LP and HP) together.

    The scene is linear about the preload (or is treated so in the
    frequency domain), so the frequency domain answers each part on its own
    at its frequency and the response is their sum (superposition). The
    time domain runs all parts in one run and extracts the amplitude at each
    frequency from the same histories. Either way the answers are one
    result per part, named ``"<name> / <part name>"``, whose T refers to that
    part's force.
    """

    name: str = field(metadata=spec('Unique name, e.g. ``"both spools"``', type="str", check="own"))
    parts: tuple[SingleFrequencyExcitation, ...] = field(metadata=spec(
        "At least two, at different frequencies, with different names",
        type="tuple of RotatingForce, HarmonicForce or Imbalance", check="own"))

    def __post_init__(self):
        item = f"excitation {self.name!r}"
        fields.nonempty_name("excitation", self.name)
        try:
            parts = tuple(self.parts)
        except TypeError:
            raise CaseError(item, "parts", self.parts, "a list of excitations") from None
        if len(parts) < 2 or not all(isinstance(p, SINGLE_FREQUENCY_KINDS) for p in parts):
            raise CaseError(item, "parts", self.parts, "two or more RotatingForce, HarmonicForce or Imbalance")
        frequencies = [p.frequency for p in parts]
        if len(set(frequencies)) < len(frequencies) or len({p.name for p in parts}) < len(parts):
            raise CaseError(item, "parts", ", ".join(f"{p.name} at {p.frequency:g} Hz" for p in parts),
                            "parts of different names at different frequencies (parts at one speed are the "
                            "planes of one Imbalance)")
        _set(self, "parts", parts)

    @property
    def frequency(self) -> float:
        """Highest frequency of the parts, Hz."""
        return max(p.frequency for p in self.parts)

    @property
    def force_amplitude(self) -> float:
        """Sum of the parts' force amplitudes, N (the load scale of the run)."""
        return sum(p.force_amplitude for p in self.parts)

    def expand(self) -> tuple[SingleFrequencyExcitation, ...]:
        """The parts as single-frequency excitations, named ``"<name> / <part name>"``."""
        return tuple(dataclasses.replace(p, name=f"{self.name} / {p.name}") for p in self.parts)


Excitation = RotatingForce | HarmonicForce | Imbalance | Sweep | Simultaneous


@documented
@dataclass(frozen=True)
class AnalysisSettings:
    """How a time-domain run is set up and checked."""

    steps_per_period: int = field(default=40, metadata=spec(
        "Time steps per period of the excitation (at least 8; 40 recommended: 20 gave amplitudes about 1 % low; "
        "the error is about (2 pi / n)^2 / 6)", type="int", check="own"))
    ramp_periods: float = field(default=10.0, metadata=spec(
        "The excitation rises smoothly (raised cosine) over this many periods, which keeps the mounted modes "
        "from being excited by the start", unit=DIMENSIONLESS, minimum=0.0,
        help="periods over which the excitation rises"))
    settle_time_constants: float = field(default=1.0, metadata=spec(
        "Settle time after the ramp, in decay time constants 1/(zeta w) of the least damped mounted mode (one "
        "is ample after the smooth start: on the reference mount even none changed T by less than 0.05 %)",
        unit=DIMENSIONLESS, minimum=0.0,
        help="settle time after the ramp in decay time constants of the least damped mounted mode"))
    settle_time: float | None = field(default=None, metadata=spec(
        "Fixed settle time after the ramp (None: from the damping)", unit="s", minimum=0.0, optional=True,
        help="fixed settle time (empty: from the damping)"))
    measured_periods: int = field(default=20, metadata=spec(
        "Periods per measured window; two consecutive windows are compared", type="int", check="own"))
    steady_tolerance: float = field(default=0.005, metadata=spec(
        "Largest relative change of the pylon-force amplitudes between the two windows for the run to count "
        "as steady", unit=DIMENSIONLESS, minimum=0.0, strictly=True,
        help="largest change between the two last windows"))
    spectral_radius: float = field(default=0.9, metadata=spec(
        "Generalized-alpha spectral radius at infinite frequency (1: no numerical damping), at most 1",
        unit=DIMENSIONLESS, minimum=0.0, help="generalized-alpha spectral radius (0 to 1)"))
    newton_tolerance: float = field(default=1e-6, metadata=spec(
        "Newton absolute tolerance relative to the load scale (largest of the static load and the excitation "
        "amplitude)", unit=DIMENSIONLESS, minimum=0.0, strictly=True,
        help="Newton tolerance relative to the load scale"))
    equilibrium_tolerance: float = field(default=1e-6, metadata=spec(
        "Largest relative mismatch between the pylon-side hinge forces and the applied static loads",
        unit=DIMENSIONLESS, minimum=0.0, strictly=True, help="largest relative mismatch of the static equilibrium"))
    method: AnalysisMethod = field(default="auto", metadata=spec(
        'The analysis answering the case: ``"auto"`` (the default: frequency domain when the scene is linear, '
        "time domain when a clearance law makes it nonlinear, see :mod:`workbook.solve.method`), time domain, "
        "or frequency domain (harmonic solution of the scene linearised about the preload). A sweep on a "
        "linear scene always takes one linearisation for all its frequencies", check="choice",
        choices=ANALYSIS_METHODS,
        help="time: time domain; frequency: frequency domain about the preload; auto: frequency domain "
             "unless a clearance makes the scene nonlinear"))
    step_halvings: int = field(default=4, metadata=spec(
        "When Newton's method fails in a segment of the time integration, the segment is run again with the "
        "step halved, at most this many times (0: no retry; at most 20) before the run stops with the time "
        "and the cause", type="int", check="own"))
    time_budget: float | None = field(default=None, metadata=spec(
        "Wall time one run (one excitation) may take; checked between segments of the integration (None: no "
        "limit)", unit="s", minimum=0.0, strictly=True, optional=True,
        help="wall time one run may take (empty: no limit)"))
    divergence_displacement: float = field(default=0.05, metadata=spec(
        "Engine centre-of-gravity displacement from the preloaded position above which the run stops as "
        "diverging", unit="m", minimum=0.0, strictly=True,
        help="engine displacement from the preloaded position that stops a run as diverging"))
    start: TimeStart = field(default="auto", metadata=spec(
        "Where a time-domain run starts (:mod:`workbook.solve.steady_start`): in the steady state of its "
        'linearised scene, the excitation in full from the first step (``"steady"``); at rest, the excitation '
        'rising over ``ramp_periods`` and the settle time after it (``"rest"``); ``"auto"`` (the default): '
        "steady when the scene is linear, at rest when a hinge clearance makes it nonlinear", check="choice",
        choices=TIME_STARTS,
        help="where a time-domain run starts: steady: in the steady state of its linearised scene (two windows "
             "suffice); rest: from rest with the smooth start and the settle time; auto: steady unless a "
             "clearance makes the scene nonlinear"))

    def __post_init__(self):
        item = "analysis settings"
        if isinstance(self.step_halvings, bool) or not isinstance(self.step_halvings, int) \
                or not 0 <= self.step_halvings <= 20:
            raise CaseError(item, "step_halvings", self.step_halvings, "a whole number from 0 to 20")
        for name in ("steps_per_period", "measured_periods"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise CaseError(item, name, value, "a positive whole number")
        if self.steps_per_period < 8:
            raise CaseError(item, "steps_per_period", self.steps_per_period, "at least 8")
        check_fields(self, item)
        if self.spectral_radius > 1:
            raise CaseError(item, "spectral_radius", self.spectral_radius, "a number from 0 to 1")


@documented
@dataclass(frozen=True)
class Effects:
    """The physical effects a case asks for; what is off is not built."""

    flexible_links: bool = field(default=True, metadata=spec(
        "Links as reduced flexible bodies where the link asks for it; False makes every link rigid", type="bool",
        check="flag", help="no: every link rigid"))
    preload: bool = field(default=True, metadata=spec(
        "Apply the static loads and solve the preloaded equilibrium first", type="bool", check="flag",
        help="solve the static loads first"))
    hinge_damping: bool = field(default=True, metadata=spec(
        "Hinge damping as given; False sets it to zero", type="bool", check="flag",
        help="no: hinge damping set to zero"))
    link_damping: bool = field(default=True, metadata=spec(
        "Rayleigh damping of the flexible links as given; False sets it to zero", type="bool", check="flag",
        help="no: link Rayleigh damping set to zero"))
    clearance: bool = field(default=True, metadata=spec(
        "Hinge clearance laws where a gap > 0 is given; False ignores the gaps", type="bool", check="flag",
        help="no: hinge gaps ignored"))
    rig_sensors: bool = field(default=True, metadata=spec(
        "The test rig's force transducers where the case gives them (``Case.test_rig``); False mounts the "
        "pylon pins on rigid ground", type="bool", check="flag",
        help="no: the pylon pins sit on rigid ground even when the Test rig sheet gives transducers"))
    gyroscopics: bool = field(default=True, metadata=spec(
        "Build the rotors' gyroscopic moments when the case gives rotors (``Case.rotors``); False leaves the "
        "rotors as inertia lumped in the engine", type="bool", check="flag",
        help="no: the rotors' gyroscopic moments are not built (their inertia stays lumped in the engine)"))
    stress_stiffening: StressStiffening = field(default="auto", metadata=spec(
        "The geometric stiffness of each flexible link's axial preload (:mod:`workbook.solve.stress_stiffening`): "
        '"on" for every flexible link, "auto" for the links whose preload moves their first pinned-pinned mode '
        'by more than :data:`~workbook.solve.stress_stiffening.AUTO_SHIFT`, "off" for none (and no buckling '
        "check of the links)", check="choice", choices=STRESS_STIFFENING,
        help="the flexible links' geometric stiffness of their axial preload, with a buckling check: on; off; "
             "auto: on for a link whose preload moves its first pinned-pinned mode by more than 0.5 %"))

    def __post_init__(self):
        check_fields(self, "effects")


@documented
@dataclass(frozen=True)
class Case:
    """One mount study case."""

    name: str = field(metadata=spec("Case name", type="str", check="own"))
    engine: Engine = field(metadata=spec("The rigid engine", type="Engine", check="own"))
    links: tuple[Link, ...] = field(metadata=spec("The connecting links", type="tuple of Link", check="own"))
    hinges: tuple[Hinge, ...] = field(metadata=spec(
        "The ball hinges; a hinge may join any two bodies", type="tuple of Hinge", check="own"))
    static_loads: tuple[StaticLoad, ...] = field(default=(), metadata=spec(
        "Constant loads solved for first (the preload)", type="tuple of PointForce, PointMoment, Gravity",
        check="own"))
    excitations: tuple[Excitation, ...] = field(default=(), metadata=spec(
        "Each excitation (each sweep frequency) is one run; a Simultaneous excitation is one run with a result "
        "per part", type="tuple of RotatingForce, HarmonicForce, Imbalance, Sweep, RunUp, Simultaneous",
        check="own"))
    analysis: AnalysisSettings = field(default_factory=AnalysisSettings, metadata=spec(
        "Time step, settle and steady-state settings", type="AnalysisSettings", check="own"))
    effects: Effects = field(default_factory=Effects, metadata=spec(
        "The physical effects asked for", type="Effects", check="own"))
    description: str = field(default="", metadata=spec("Free text", type="str", check="own"))
    test_rig: ForceTransducers | None = field(default=None, metadata=spec(
        "The rig's force transducers under the pylon pins (None: the pylon pins sit on rigid ground)",
        type="ForceTransducers", check="own", optional=True))
    rotors: tuple[Rotor, ...] = field(default=(), metadata=spec(
        "Spinning rotors whose gyroscopic moments act on the engine (their mass and inertia are part of "
        "``engine``)", type="tuple of Rotor", check="own"))
    pylon: PylonModel | None = field(default=None, metadata=spec(
        "The flexible pylon carrying the pins (None: a rigid pylon), frequency domain only: a "
        ":class:`PylonImpedance` (point dynamic stiffness at the pins against frequency), a "
        ":class:`BoxBeamPylon` (a clamped box beam) or a :class:`MeshPylon` (a user's solid mesh clamped on its "
        "root plane). The keywords ``pylon_impedance``, ``pylon_beam`` and ``pylon_mesh`` of earlier versions "
        "are deprecated aliases", type="PylonModel", check="own", optional=True))
    load_cases: tuple[LoadCase, ...] = field(default=(), metadata=spec(
        "Named static limit load cases for the links' strength (:mod:`workbook.model.load_cases`, solved by "
        ":mod:`workbook.solve.load_cases`); the runs do not use them", type="tuple of LoadCase", check="own"))
    speed_spectra: tuple[SpeedSpectrum, ...] = field(default=(), metadata=spec(
        "The hours each rotor excitation runs at each speed, for the links' Miner damage sums "
        "(:mod:`workbook.model.spectrum`, solved by :mod:`workbook.solve.fatigue`); one per excitation; the runs "
        "do not use them", type="tuple of SpeedSpectrum", check="own"))

    def __post_init__(self):
        fields.nonempty_name("case", self.name)
        checks = (("engine", Engine), ("analysis", AnalysisSettings), ("effects", Effects))
        for name, kind in checks:
            if not isinstance(getattr(self, name), kind):
                raise CaseError("case", name, getattr(self, name), f"a {kind.__name__}")
        if self.test_rig is not None and not isinstance(self.test_rig, ForceTransducers):
            raise CaseError("case", "test_rig", self.test_rig, "a ForceTransducers or None")
        groups = (("links", (Link,)), ("hinges", (Hinge,)),
                  ("static_loads", (PointForce, PointMoment, Gravity)),
                  ("excitations", (*SINGLE_FREQUENCY_KINDS, Sweep, Simultaneous)), ("rotors", (Rotor,)),
                  ("load_cases", (LoadCase,)))
        for name, kinds in groups:
            items = tuple(getattr(self, name))
            for item in items:
                if not isinstance(item, kinds):
                    raise CaseError("case", name, item, " or ".join(k.__name__ for k in kinds))
            _set(self, name, items)
        owners = self._check_names(groups)
        spectra = tuple(self.speed_spectra)
        seen: set = set()
        for spectrum in spectra:
            if not isinstance(spectrum, SpeedSpectrum):
                raise CaseError("case", "speed_spectra", spectrum, "a SpeedSpectrum")
            if spectrum.excitation in seen:
                raise CaseError(f"speed spectrum {spectrum.excitation!r}", "excitation", spectrum.excitation,
                                "one speed spectrum per excitation")
            seen.add(spectrum.excitation)
        _set(self, "speed_spectra", spectra)
        if self.pylon is not None:
            if not isinstance(self.pylon, PylonModel):
                raise CaseError("case", "pylon", self.pylon, "a PylonImpedance, BoxBeamPylon, MeshPylon or None")
            self.pylon.check(self.pylon_pins())
        links = self.link_map
        for load_case in self.load_cases:
            load_case.check(links)
        for hinge in self.hinges:
            for name in ("body_a", "body_b"):
                body = getattr(hinge, name)
                if body in _RESERVED:
                    continue
                if body not in links:
                    raise CaseError(f"hinge {hinge.name!r}", name, body,
                                    f"'pylon', 'engine' or a link name ({', '.join(links)})")
                if links[body].eye_at(hinge.position) is None:
                    raise CaseError(f"hinge {hinge.name!r}", "position", hinge.position,
                                    f"an eye centre of link {body!r}: {links[body].end_a} or "
                                    f"{links[body].end_b}")
        if self.engine.casing is not None:
            if CASING in links:
                raise CaseError(f"link {CASING!r}", "name", CASING, "a name other than the flexible engine's casing")
            self.engine.casing.check(self.engine.mass, self.engine.center_of_mass,
                                     [(h.name, h.position) for h in self.hinges if ENGINE in h.bodies])
        if self.test_rig is not None:
            for _, carried in self.pylon_pins():
                name = transducer_name(carried)
                if name in owners:
                    raise CaseError(f"{owners[name]}", "name", name, "a name that is not the test-rig transducer "
                                    f"under the pylon pin of {' + '.join(carried)} (rename the item)")

    def _check_names(self, groups) -> dict[str, str]:
        """Every item's name unique across all kinds of items (links, hinges,
        static loads, excitations and the points of each sweep, rotors), and
        none of them ``"pylon"`` or ``"engine"``.

        Returns
        -------
        dict of str to str
            What each name names (e.g. ``"hinge 'front-up-left'"``).
        """
        owners = {reserved: f"the scene's own {reserved}" for reserved in _RESERVED}
        for group, _ in groups:
            kind = group[:-1].replace("_", " ")
            for item in getattr(self, group):
                names = [item.name] + ([point.name for point in item.expand()]
                                       if isinstance(item, (Sweep, Simultaneous)) else [])
                for name in names:
                    if name in owners:
                        raise CaseError(f"{kind} {item.name!r}", "name", name,
                                        f"a name not used before (it already names {owners[name]})")
                    owners[name] = f"{kind} {item.name!r}"
        return owners

    @property
    def link_map(self) -> dict[str, Link]:
        """Links by name."""
        return {link.name: link for link in self.links}

    def link_is_flexible(self, name: str) -> bool:
        """True if link *name* is built as a flexible body (the link asks for it
        and the case's effects allow flexible links)."""
        return self.effects.flexible_links and self.link_map[name].flexible

    def link_modes(self, name: str) -> ModeRequest:
        """The link mode rule: the modes the reduction of link *name* keeps.

        A flexible link keeps what its ``modes`` field asks for; a rigid link
        needs only its mass properties and takes the static reduction.
        """
        return self.link_map[name].modes if self.link_is_flexible(name) else "static"

    @property
    def rig_sensors_built(self) -> bool:
        """True if the case gives test-rig force transducers and asks for them."""
        return self.test_rig is not None and self.effects.rig_sensors

    @property
    def flexible_pylon(self) -> bool:
        """True if the case gives a flexible pylon (an impedance table, a box beam or a mesh)."""
        return self.pylon is not None

    @property
    def pylon_impedance(self) -> PylonImpedance | None:
        """Deprecated: ``pylon`` when it is a :class:`PylonImpedance`, else None."""
        return legacy_pylon(self.pylon, "pylon_impedance")

    @property
    def pylon_beam(self) -> BoxBeamPylon | None:
        """Deprecated: ``pylon`` when it is a :class:`BoxBeamPylon`, else None."""
        return legacy_pylon(self.pylon, "pylon_beam")

    @property
    def pylon_mesh(self) -> MeshPylon | None:
        """Deprecated: ``pylon`` when it is a :class:`MeshPylon`, else None."""
        return legacy_pylon(self.pylon, "pylon_mesh")

    @property
    def pylon_hinges(self) -> tuple[Hinge, ...]:
        """The pylon-side hinges, whose forces sum to the pylon force."""
        return tuple(h for h in self.hinges if h.on_pylon)

    def engine_eyes(self) -> list[tuple[Vector3, list[str]]]:
        """The mount eyes on the engine: each position (m) with the names of the
        engine-side hinges on it (hinges closer than the point tolerance share an eye)."""
        return _points_of([h for h in self.hinges if ENGINE in h.bodies])

    def pylon_pins(self) -> list[tuple[Vector3, list[str]]]:
        """The pylon pins: each position (m) with the names of the pylon-side
        hinges on it (hinges closer than the point tolerance share a pin)."""
        return _points_of(self.pylon_hinges)

    def single_frequency_excitations(self) -> tuple[SingleFrequencyExcitation, ...]:
        """Every run of the case: single excitations, expanded sweeps and the
        parts of simultaneous excitations."""
        runs: list[SingleFrequencyExcitation] = []
        for excitation in self.excitations:
            runs.extend(excitation.expand() if isinstance(excitation, (Sweep, Simultaneous)) else (excitation,))
        return tuple(runs)

    def without_link(self, name: str) -> "Case":
        """The case with link *name* and every hinge attached to it removed."""
        if name not in self.link_map:
            raise CaseError("case", "links", name, f"one of {', '.join(self.link_map)}")
        return dataclasses.replace(
            self, name=f"{self.name} without {name}",
            links=tuple(link for link in self.links if link.name != name),
            hinges=tuple(h for h in self.hinges if name not in h.bodies),
            load_cases=tuple(c for c in self.load_cases if c.without_link != name))

    def with_rigid_links(self) -> "Case":
        """The case with every link rigid."""
        return dataclasses.replace(self, effects=dataclasses.replace(self.effects, flexible_links=False))


Case.__init__ = accept_legacy_pylons(Case.__init__)  # type: ignore[method-assign]
