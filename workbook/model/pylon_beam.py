"""The pylon as a parametric box beam: its inputs and its compliance at the pins.

A straight thin-walled rectangular box beam, clamped at its root (the wing
attachment) and free at its tip, carries the pylon pins: each pin hangs on
the beam axis's nearest point by a rigid offset (a fitting), so pins at one
station move together with the beam's cross-section there.

Its finite-element model (:func:`beam_model`): Euler-Bernoulli beam
elements (two nodes, six DOF each: three translations, three rotations)
with the box's section constants (:meth:`BoxBeamPylon.section`), consistent
mass (translation and the section's polar inertia), clamped at the root.
Stations are placed at each pin's foot on the axis and at least
``elements`` intervals over the length; a pin moves with its station's
cross-section through a rigid offset r, ``x_pin = u + theta x r``. The
compliance at the pins follows
(:class:`workbook.model.pylon.PylonStructure`). Pins at one station are
rigidly joined by their fitting, so G need not be invertible: the
four-pole set closes it in its compliance form
(:meth:`workbook.solve.four_pole.FourPole.respond`).
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from flexbodies.materials import Material
from workbook.errors import CaseError
from workbook.model.field_spec import check_fields, documented, spec
from workbook.model.pylon import Pin, PinDynamics, PylonModel, PylonStructure
from workbook.model.units import DIMENSIONLESS

__all__ = ["BoxBeamPylon", "SectionProperties", "BeamModel", "beam_model"]

#: Relative distance (of the length) within which a pin's foot counts as on the beam.
STATION_TOLERANCE = 1e-9


@dataclass(frozen=True)
class SectionProperties:
    """Section constants of the box, in its own axes (2: width, 3: height).

    Attributes
    ----------
    area : float
        m^2.
    second_moment_2, second_moment_3 : float
        About the width axis (bending in the height direction) and about
        the height axis (bending in the width direction), m^4.
    torsion_constant : float
        Bredt's thin-walled closed section, ``4 A_m^2 t / p_m``, m^4.
    """

    area: float
    second_moment_2: float
    second_moment_3: float
    torsion_constant: float


@documented
@dataclass(frozen=True)
class BoxBeamPylon(PylonModel):
    """A box-beam pylon clamped at its root (a :class:`~workbook.model.pylon.PylonModel`)."""

    effect: ClassVar[str] = "flexible pylon (box beam)"
    noun: ClassVar[str] = "pylon beam"
    legacy_field: ClassVar[str] = "pylon_beam"
    time_domain_note: ClassVar[str] = "the box beam is built as the pylon's compliance in the frequency domain"

    root: tuple = field(metadata=spec("End of the beam axis where it is clamped", type="3 floats", check="vector3",
                                      unit="m"))
    tip: tuple = field(metadata=spec("Free end of the beam axis, other than *root*", type="3 floats",
                                     check="vector3", unit="m"))
    width: float = field(metadata=spec("Outer width of the box, normal to the axis and to *up*", unit="m",
                                       minimum=0.0, strictly=True))
    height: float = field(metadata=spec("Outer height of the box, along *up* (made normal to the axis)", unit="m",
                                        minimum=0.0, strictly=True))
    wall: float = field(metadata=spec("Wall thickness, less than half of *width* and *height*", unit="m",
                                      minimum=0.0, strictly=True))
    material: Material = field(metadata=spec("Material of the box", type="flexbodies.Material", check="own"))
    loss_factor: float = field(default=0.02, metadata=spec(
        "Structural loss factor eta: stiffness ``K (1 + i eta)``", unit=DIMENSIONLESS, minimum=0.0))
    up: tuple = field(default=(0.0, 0.0, 1.0), metadata=spec(
        "Direction of the height, not along the axis (default +z)", type="3 floats", check="vector3"))
    elements: int = field(default=40, metadata=spec(
        "Beam elements over the length, at least (stations at the pins are added)", type="int", check="own",
        minimum=1.0))
    name: str = field(default="box-beam pylon", metadata=spec("Its name in messages", type="str", check="own"))

    def __post_init__(self):
        item = f"pylon beam {self.name!r}"
        check_fields(self, item)
        if self.wall >= min(self.width, self.height) / 2:
            raise CaseError(item, "wall", self.wall, f"less than half the width and height "
                                                     f"({min(self.width, self.height) / 2:g} m)")
        if not isinstance(self.material, Material):
            raise CaseError(item, "material", self.material, "a Material")
        if isinstance(self.elements, bool) or int(self.elements) != self.elements or self.elements < 1:
            raise CaseError(item, "elements", self.elements, "a whole number >= 1")
        object.__setattr__(self, "elements", int(self.elements))
        if self.length == 0:
            raise CaseError(item, "tip", self.tip, "a point other than the root")
        axis = np.subtract(self.tip, self.root) / self.length
        norm = np.linalg.norm(self.up)
        if norm == 0 or abs(axis @ np.asarray(self.up)) / norm > 1 - 1e-9:
            raise CaseError(item, "up", self.up, "a direction not along the beam axis")

    @property
    def length(self) -> float:
        """Root to tip, m."""
        return float(np.linalg.norm(np.subtract(self.tip, self.root)))

    def frame(self) -> np.ndarray:
        """Rows: the axis (root to tip), the width and the height directions (unit vectors)."""
        axis = np.subtract(self.tip, self.root) / self.length
        height = np.asarray(self.up, dtype=float) - (np.asarray(self.up) @ axis) * axis
        height /= np.linalg.norm(height)
        return np.array([axis, np.cross(height, axis), height])

    def section(self) -> SectionProperties:
        """The box's section constants."""
        b, h, t = self.width, self.height, self.wall
        inner_b, inner_h = b - 2 * t, h - 2 * t
        middle_b, middle_h = b - t, h - t
        return SectionProperties(
            area=b * h - inner_b * inner_h,
            second_moment_2=(b * h ** 3 - inner_b * inner_h ** 3) / 12,
            second_moment_3=(h * b ** 3 - inner_h * inner_b ** 3) / 12,
            torsion_constant=4 * (middle_b * middle_h) ** 2 * t / (2 * (middle_b + middle_h)))

    def describe(self) -> str:
        """One line for the model card."""
        return (f"{self.name}: {self.material.name} box {1e3 * self.width:.0f} x {1e3 * self.height:.0f} mm, "
                f"wall {1e3 * self.wall:.0f} mm, {self.length:.2f} m from its clamped root, loss factor "
                f"{self.loss_factor:g}")

    @property
    def label(self) -> str:
        """Its name."""
        return self.name

    def pins_at(self, pins: Sequence[Pin], frequencies_hz: Sequence[float], highest_hz: float) -> PinDynamics:
        """The beam's compliance at *pins* (:func:`beam_model`) at *frequencies_hz*."""
        model = beam_model(self, [position for position, _ in pins])
        return PinDynamics(None, model.compliance(frequencies_hz),
                           f"{self.describe()}; {len(model.stations) - 1} Euler-Bernoulli elements, "
                           f"{model.stiffness.shape[0]} DOF, pins on rigid offsets, compliance at the pins")


def _element(beam: BoxBeamPylon, length: float) -> tuple[np.ndarray, np.ndarray]:
    """Local stiffness and consistent mass of one element, (12, 12), DOF order per node
    u (axial), v (width), w (height), rx, ry, rz."""
    section, material = beam.section(), beam.material
    e, rho = material.youngs_modulus, material.density
    g = e / (2 * (1 + material.poisson_ratio))
    k, m = np.zeros((12, 12)), np.zeros((12, 12))
    a, L = section.area, length

    def put(target, dofs, block):
        target[np.ix_(dofs, dofs)] += block

    bar = np.array([[1.0, -1.0], [-1.0, 1.0]])
    pair = np.array([[2.0, 1.0], [1.0, 2.0]])
    put(k, [0, 6], e * a / L * bar)
    put(m, [0, 6], rho * a * L / 6 * pair)
    put(k, [3, 9], g * section.torsion_constant / L * bar)
    put(m, [3, 9], rho * (section.second_moment_2 + section.second_moment_3) * L / 6 * pair)
    bending = np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L ** 2, -6 * L, 2 * L ** 2],
                        [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L ** 2, -6 * L, 4 * L ** 2]]) / L ** 3
    inertia = rho * a * L / 420 * np.array([[156, 22 * L, 54, -13 * L], [22 * L, 4 * L ** 2, 13 * L, -3 * L ** 2],
                                            [54, 13 * L, 156, -22 * L], [-13 * L, -3 * L ** 2, -22 * L, 4 * L ** 2]])
    flip = np.diag([1.0, -1.0, 1.0, -1.0])         # rotation about the width axis is -dw/dx
    put(k, [1, 5, 7, 11], e * section.second_moment_3 * bending)
    put(m, [1, 5, 7, 11], inertia)
    put(k, [2, 4, 8, 10], e * section.second_moment_2 * flip @ bending @ flip)
    put(m, [2, 4, 8, 10], flip @ inertia @ flip)
    return k, m


@dataclass(frozen=True)
class BeamModel(PylonStructure):
    """The clamped beam's matrices and its pin map (:class:`PylonStructure`) and its stations.

    Attributes
    ----------
    stations : ndarray
        Node positions along the axis from the root, m.
    """

    stations: np.ndarray


def beam_model(beam: BoxBeamPylon, pins) -> BeamModel:
    """The finite-element model of *beam* carrying *pins*.

    Parameters
    ----------
    beam : BoxBeamPylon
    pins : sequence of 3 floats
        Pin positions, m (``Case.pylon_pins()`` order).

    Raises
    ------
    workbook.errors.CaseError
        A pin whose foot on the axis lies beyond the root or the tip.
    """
    frame = beam.frame()
    axis, root, length = frame[0], np.asarray(beam.root), beam.length
    feet = []
    for position in pins:
        station = float((np.asarray(position) - root) @ axis)
        if not -STATION_TOLERANCE * length <= station <= (1 + STATION_TOLERANCE) * length:
            raise CaseError(f"pylon beam {beam.name!r}", "tip", beam.tip,
                            f"a beam whose axis reaches the foot of the pin at {tuple(position)} "
                            f"({station:.4g} m from the root; the beam is {length:.4g} m long)")
        feet.append(min(max(station, 0.0), length))
    grid = np.linspace(0.0, length, beam.elements + 1)
    stations = np.unique(np.concatenate([grid, feet]))
    stations = stations[np.concatenate([[True], np.diff(stations) > STATION_TOLERANCE * length])]
    nodes = len(stations)
    rotate = np.kron(np.eye(4), frame)              # local = rotate @ global, per element
    stiffness, mass = np.zeros((6 * nodes, 6 * nodes)), np.zeros((6 * nodes, 6 * nodes))
    for n in range(nodes - 1):
        k, m = _element(beam, stations[n + 1] - stations[n])
        dofs = slice(6 * n, 6 * n + 12)
        stiffness[dofs, dofs] += rotate.T @ k @ rotate
        mass[dofs, dofs] += rotate.T @ m @ rotate
    pin_map = np.zeros((3 * len(feet), 6 * nodes))
    for p, (position, foot) in enumerate(zip(pins, feet, strict=True)):
        node = int(np.argmin(np.abs(stations - foot)))
        offset = np.asarray(position) - (root + stations[node] * axis)
        cross = np.array([[0, -offset[2], offset[1]], [offset[2], 0, -offset[0]], [-offset[1], offset[0], 0]])
        pin_map[3 * p:3 * p + 3, 6 * node:6 * node + 3] = np.eye(3)
        pin_map[3 * p:3 * p + 3, 6 * node + 3:6 * node + 6] = -cross      # theta x r = -r x theta
    free = slice(6, None)                           # the root clamped
    return BeamModel(stiffness[free, free], mass[free, free], pin_map[:, free], beam.loss_factor, stations)
