"""The pylon as a user's finite-element mesh: its inputs and its compliance at the pins.

A solid mesh of the pylon (any volume mesh meshio reads, as for a link) is
clamped where it meets the wing, on every node of its root plane, and
carries the pylon pins: each pin is a bore of the mesh found around the
pin's position (axis and radius given, as for a link's bore), tied to a
master node by a rigid (RBE2) coupling. The pin moves with that master node
through a rigid offset from the bore's centre to the pin.

Its reduction by Craig-Bampton on the pins is
:func:`flexbodies.pylon_reduction.reduce_pylon`, kept in the cache of every
reduced body. Its reduced matrices and pin map are a
:class:`~workbook.model.pylon.PylonStructure` (:func:`mesh_pylon_model`),
whose compliance closes the four-pole set as the box beam's does.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

from flexbodies.materials import Material
from flexbodies.pylon_reduction import PylonMeshModel, reduce_pylon
from workbook.errors import CaseError
from workbook.model.field_spec import check_fields, documented, spec
from workbook.model.pylon import Pin, PinDynamics, PylonModel, PylonStructure
from workbook.model.units import DIMENSIONLESS

__all__ = ["MeshPylon", "mesh_pylon_model"]


@documented
@dataclass(frozen=True)
class MeshPylon(PylonModel):
    """A pylon from a user's solid mesh, clamped on its root plane (a :class:`~workbook.model.pylon.PylonModel`)."""

    effect: ClassVar[str] = "flexible pylon (mesh)"
    noun: ClassVar[str] = "pylon mesh"
    legacy_field: ClassVar[str] = "pylon_mesh"
    time_domain_note: ClassVar[str] = "the mesh is reduced to the pylon's compliance in the frequency domain"

    path: str = field(metadata=spec(
        "Mesh file (``.msh``, ``.inp``, ``.vtu``, ...; quadratic tetrahedra preferred), coordinates in the case's "
        "axes times *scale*", type="str", check="own"))
    root_point: tuple = field(metadata=spec("A point of the root plane", type="3 floats", check="vector3", unit="m"))
    root_normal: tuple = field(metadata=spec(
        "Normal of the root plane: every mesh node within *root_tolerance* of the plane is clamped",
        type="3 floats", check="direction"))
    bore_axis: tuple = field(metadata=spec("Direction of the pin bores' axes", type="3 floats", check="direction"))
    bore_radius: float = field(metadata=spec("Radius of the pin bores", unit="m", minimum=0.0, strictly=True))
    material: Material = field(metadata=spec("Material of the pylon", type="flexbodies.Material", check="own"))
    loss_factor: float = field(default=0.02, metadata=spec(
        "Structural loss factor of the pylon's material (stiffness ``K (1 + i eta)``)", unit=DIMENSIONLESS,
        minimum=0.0))
    scale: float = field(default=1.0, metadata=spec(
        "Factor from the file's units to m (1e-3 for a file in mm)", unit=DIMENSIONLESS, minimum=0.0, strictly=True))
    root_tolerance: float = field(default=1e-6, metadata=spec(
        "Distance from the root plane within which a node is clamped", unit="m", minimum=0.0, strictly=True))
    name: str = field(default="mesh pylon", metadata=spec("Its name in messages", type="str", check="own"))

    def __post_init__(self):
        item = f"pylon mesh {self.name!r}"
        if not isinstance(self.path, (str, Path)) or not str(self.path):
            raise CaseError(item, "path", self.path, "the path of a mesh file")
        object.__setattr__(self, "path", str(self.path))
        check_fields(self, item)
        if not isinstance(self.material, Material):
            raise CaseError(item, "material", self.material, "a Material")

    def describe(self) -> str:
        """One line for the model card."""
        return (f"{self.name}: {self.material.name} mesh {Path(self.path).name}, clamped on its root plane, "
                f"pins on bores of radius {1e3 * self.bore_radius:.4g} mm, loss factor {self.loss_factor:g}")

    @property
    def label(self) -> str:
        """Its name."""
        return self.name

    def model(self, pins) -> PylonMeshModel:
        """What its reduction with the pins at *pins* (m, ``Case.pylon_pins()`` order) depends on."""
        return PylonMeshModel(self.path, tuple(tuple(float(v) for v in p) for p in pins), self.root_point,
                              self.root_normal, self.bore_axis, self.bore_radius, self.material, self.scale,
                              self.root_tolerance, self.name)

    def pins_at(self, pins: Sequence[Pin], frequencies_hz: Sequence[float], highest_hz: float) -> PinDynamics:
        """The reduced mesh's compliance at *pins* (:func:`mesh_pylon_model`, reduced for *highest_hz*)."""
        structure, facts = mesh_pylon_model(self, [position for position, _ in pins], highest_hz)
        modes = (f"{facts['modes']} fixed-interface modes up to {facts['highest_mode_hz']:.0f} Hz"
                 if facts["modes"] else "static modes only")
        return PinDynamics(None, structure.compliance(frequencies_hz),
                           f"{self.describe()}; {facts['fe_dof']} FE DOF reduced to {facts['reduced_dof']} "
                           f"(Craig-Bampton on the pins, {modes}) in {facts['seconds']:.2f} s"
                           f"{' (from the cache)' if facts['cache_hit'] else ''}, compliance at the pins")


def mesh_pylon_model(pylon: MeshPylon, pins, highest_hz: float) -> tuple[PylonStructure, dict]:
    """The reduced pylon of a user's mesh and what it cost, from the cache of the reduced bodies
    (:class:`flexbodies.cache.BodyCache`) when its inputs are unchanged.

    Parameters
    ----------
    pylon : MeshPylon
    pins : sequence of 3 floats
        Pin positions, m (``Case.pylon_pins()`` order).
    highest_hz : float
        Highest frequency the compliance is asked at, Hz.

    Returns
    -------
    structure : PylonStructure
    facts : dict
        ``fe_dof``, ``reduced_dof``, ``modes`` (fixed-interface modes kept),
        ``highest_mode_hz``, ``seconds`` (of the reduction) and ``cache_hit``.

    Raises
    ------
    workbook.errors.CaseError
        The mesh file missing or unreadable, a pin bore not found, a root
        plane through no node or through a bore.
    """
    reduced = reduce_pylon(pylon.model(pins), highest_hz)
    modes = len(reduced.fixed_interface_hz)
    structure = PylonStructure(reduced.stiffness, reduced.mass, reduced.point_map, pylon.loss_factor)
    return structure, {"fe_dof": int(reduced.info["fe_dof"]), "reduced_dof": int(reduced.stiffness.shape[0]), "modes": modes,
                       "highest_mode_hz": float(reduced.fixed_interface_hz[-1]) if modes else None,
                       "seconds": float(reduced.info["seconds"]), "cache_hit": reduced.cache_hit}
