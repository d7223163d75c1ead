"""The pylon as a parametric box beam: the inputs.

A straight thin-walled rectangular box beam, clamped at its root (the wing
attachment) and free at its tip, carries the pylon pins: each pin hangs on
the beam axis's nearest point by a rigid offset (a fitting), so pins at one
station move together with the beam's cross-section there. Its point
dynamic stiffness at the pins, coupled through the beam, comes from
:mod:`workbook.solve.pylon_beam`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from flexbodies.materials import Material
from workbook.errors import CaseError
from workbook.model.fields import positive_number, vector3

__all__ = ["BoxBeamPylon", "SectionProperties"]


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


@dataclass(frozen=True)
class BoxBeamPylon:
    """A box-beam pylon clamped at its root.

    Parameters
    ----------
    root, tip : 3 floats
        Ends of the beam axis, m; clamped at *root*.
    width, height : float
        Outer dimensions of the box, m; *height* along *up* (made
        normal to the axis), *width* normal to both.
    wall : float
        Wall thickness, m (less than half of width and height).
    material : flexbodies.Material
    loss_factor : float
        Structural loss factor eta: stiffness ``K (1 + i eta)``, >= 0.
    up : 3 floats
        Direction of the height, not along the axis (default +z).
    elements : int
        Beam elements over the length, at least; stations at the pins are
        added.
    name : str
    """

    root: tuple
    tip: tuple
    width: float
    height: float
    wall: float
    material: Material
    loss_factor: float = 0.02
    up: tuple = (0.0, 0.0, 1.0)
    elements: int = 40
    name: str = "box-beam pylon"

    def __post_init__(self):
        item = f"pylon beam {self.name!r}"
        set_ = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        for name in ("root", "tip", "up"):
            set_(name, vector3(item, name, getattr(self, name)))
        for name in ("width", "height", "wall"):
            set_(name, positive_number(item, name, getattr(self, name)))
        if self.wall >= min(self.width, self.height) / 2:
            raise CaseError(item, "wall", self.wall, f"less than half the width and height "
                                                     f"({min(self.width, self.height) / 2:g} m)")
        if not isinstance(self.material, Material):
            raise CaseError(item, "material", self.material, "a Material")
        loss = float(self.loss_factor) if not isinstance(self.loss_factor, bool) else math.nan
        if not (math.isfinite(loss) and loss >= 0):
            raise CaseError(item, "loss_factor", self.loss_factor, "a number >= 0")
        set_("loss_factor", loss)
        if isinstance(self.elements, bool) or int(self.elements) != self.elements or self.elements < 1:
            raise CaseError(item, "elements", self.elements, "a whole number >= 1")
        set_("elements", int(self.elements))
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
