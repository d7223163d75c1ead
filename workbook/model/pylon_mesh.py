"""The pylon as a user's finite-element mesh: the inputs.

A solid mesh of the pylon (any volume mesh meshio reads, as for a link) is
clamped where it meets the wing, on every node of its root plane, and
carries the pylon pins: each pin is a bore of the mesh found around the
pin's position (axis and radius given, as for a link's bore), tied to a
master node by a rigid (RBE2) coupling. The pin moves with that master node
through a rigid offset from the bore's centre to the pin. Its reduction and
its compliance at the pins come from :mod:`workbook.solve.pylon_mesh`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flexbodies.materials import Material
from workbook.errors import CaseError
from workbook.model.fields import positive_number, vector3

__all__ = ["MeshPylon"]


@dataclass(frozen=True)
class MeshPylon:
    """A pylon from a user's solid mesh, clamped on its root plane.

    Parameters
    ----------
    path : str
        Mesh file (``.msh``, ``.inp``, ``.vtu``, ...; quadratic tetrahedra
        preferred), coordinates in the case's axes times ``scale``.
    root_point, root_normal : 3 floats
        A point of the root plane (m) and its normal: every mesh node within
        ``root_tolerance`` of the plane is clamped.
    bore_axis : 3 floats
        Direction of the pin bores' axes.
    bore_radius : float
        Radius of the pin bores, m.
    material : flexbodies.Material
    loss_factor : float
        Structural loss factor of the pylon's material (stiffness ``K (1 + i eta)``).
    scale : float
        Factor from the file's units to m (1e-3 for a file in mm).
    root_tolerance : float
        Distance from the root plane within which a node is clamped, m.
    name : str
    """

    path: str
    root_point: tuple
    root_normal: tuple
    bore_axis: tuple
    bore_radius: float
    material: Material
    loss_factor: float = 0.02
    scale: float = 1.0
    root_tolerance: float = 1e-6
    name: str = "mesh pylon"

    def __post_init__(self):
        item = f"pylon mesh {self.name!r}"
        set_ = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        if not isinstance(self.path, (str, Path)) or not str(self.path):
            raise CaseError(item, "path", self.path, "the path of a mesh file")
        set_("path", str(self.path))
        for name in ("root_point", "root_normal", "bore_axis"):
            set_(name, vector3(item, name, getattr(self, name)))
        for name in ("root_normal", "bore_axis"):
            if not np.linalg.norm(getattr(self, name)) > 0:
                raise CaseError(item, name, getattr(self, name), "a non-zero direction")
        for name in ("bore_radius", "scale", "root_tolerance"):
            set_(name, positive_number(item, name, getattr(self, name)))
        if not isinstance(self.material, Material):
            raise CaseError(item, "material", self.material, "a Material")
        loss = float(self.loss_factor) if isinstance(self.loss_factor, (int, float)) and not isinstance(
            self.loss_factor, bool) else math.nan
        if not (math.isfinite(loss) and loss >= 0):
            raise CaseError(item, "loss_factor", self.loss_factor, "a number >= 0")
        set_("loss_factor", loss)

    def describe(self) -> str:
        """One line for the model card."""
        return (f"{self.name}: {self.material.name} mesh {Path(self.path).name}, clamped on its root plane, "
                f"pins on bores of radius {1e3 * self.bore_radius:.4g} mm, loss factor {self.loss_factor:g}")
