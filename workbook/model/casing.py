"""A flexible engine: the casing as a reduced FE body, the rest a rigid core.

:class:`EngineCasing` is the optional ``Engine.casing``. Given, the engine is
built as two bodies whose sum keeps the case's mass, centre of gravity and
inertia exactly:

- the *casing*: a parametric tube with mount frame rings
  (:class:`~flexbodies.casing.CasingGeometry`) or a user's mesh file, reduced
  by Craig-Bampton; the engine-side hinges attach to it at the mount eyes;
- the *core* (rotors and everything else): a rigid body carrying the
  remainder (:func:`split_engine`), joined to the casing at each bearing
  plane by a stiff spring-damper; the imbalance forces, thrust, moments and
  gyroscopic moments act on it, as on the rigid engine.

The casing frame is the case frame shifted onto the engine axis through the
centre of gravity: its x axis runs through the CG parallel to x, and a
position x in the casing frame is the case's x.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from flexbodies.casing import CasingGeometry, CasingInterface, MountRing, default_casing_element_size
from flexbodies.casing_reduction import CasingModel
from flexbodies.materials import TITANIUM, Material
from workbook.errors import CaseError
from workbook.model.field_spec import check_fields, documented, spec
from workbook.model.fields import MAX_MODE_COUNT, bounded_count, positive_number
from workbook.model.units import DIMENSIONLESS

__all__ = ["EngineCasing", "CoreBody", "split_engine", "CASING", "MountRing", "CasingGeometry",
           "DEFAULT_BEARING_STIFFNESS", "parallel_axis", "casing_origin", "bearing_name",
           "DEFAULT_CASING_DAMPING", "DEFAULT_SPIDER_RADIUS", "DEFAULT_CORE_SPIN_HZ"]

#: Body name of the casing in the scene (the core keeps the name "engine").
CASING = "engine casing"
#: Radial and axial stiffness of each bearing connector, N/m: stiff enough that the
#: core's modes on the casing lie above the rotor excitations of a turbofan
#: (the reference engine's core, 2474 kg, translates on its two bearings at sqrt(2e10 / 2474) / 2 pi = 450 Hz).
DEFAULT_BEARING_STIFFNESS = (1.0e10, 1.0e10)
#: Radius of the spider that ties a mount eye to the casing surface, m.
DEFAULT_SPIDER_RADIUS = 0.08
#: Frequency of the core's spin about the engine axis on the casing, Hz (the
#: torsional restraint between them; the links' spin restraints use the same).
DEFAULT_CORE_SPIN_HZ = 2000.0
#: Damping ratio of each of the casing's elastic modes: a bolted, flanged
#: casing dissipates about 1-2 % of critical; 0.02 is its upper end.
DEFAULT_CASING_DAMPING = 0.02
_ITEM = "engine casing"


@documented
@dataclass(frozen=True)
class EngineCasing:
    """The engine's casing as a flexible body (``Engine.casing``)."""

    bearing_planes: tuple = field(metadata=spec(
        "x of the planes where the rotors sit on the casing (two or more, within the casing)", type="tuple of float",
        check="own", unit="m"))
    geometry: CasingGeometry | None = field(default=None, metadata=spec(
        "A parametric casing in the casing frame (exactly one of ``geometry`` and ``mesh``)", type="CasingGeometry",
        check="own", optional=True))
    mesh: str | None = field(default=None, metadata=spec(
        "A mesh file (meshio: .msh, .inp, .vtu, ...) in the casing frame", type="str", check="own", optional=True))
    scale: float = field(default=1.0, metadata=spec(
        "Factor from the mesh file's units to m, > 0 (checked for a mesh file only)", check="own"))
    material: Material = field(default=TITANIUM, metadata=spec("The casing's material", type="flexbodies.Material",
                                                               check="own"))
    element_size: float | None = field(default=None, metadata=spec(
        "Mesh size of a parametric casing", unit="m", minimum=0.0, strictly=True, optional=True,
        help="mesh size (empty: default)"))
    spider_radius: float = field(default=DEFAULT_SPIDER_RADIUS, metadata=spec(
        "Each mount eye is tied (RBE2) to the casing surface within this distance of the eye point", unit="m",
        minimum=0.0, strictly=True, help="casing surface tied to each mount eye (empty: 80 mm)"))
    bearing_band: float | None = field(default=None, metadata=spec(
        "Each bearing plane is tied to the casing surface within this distance of the plane (None: the element "
        "size; 0.05 m for a mesh file)", unit="m", minimum=0.0, strictly=True, optional=True,
        help="casing surface tied to each bearing plane"))
    bearing_stiffness: tuple = field(default=DEFAULT_BEARING_STIFFNESS, metadata=spec(
        "Radial and axial stiffness of each bearing connector", type="2 floats", check="pair", unit="N/m",
        minimum=0.0, strictly=True))
    bearing_damping: tuple = field(default=(0.0, 0.0), metadata=spec(
        "Radial and axial damping of each bearing connector", type="2 floats", check="pair", unit="N*s/m",
        minimum=0.0))
    core_spin_hz: float = field(default=DEFAULT_CORE_SPIN_HZ, metadata=spec(
        "Frequency of the core's spin about the axis on the casing (sets the torsional restraint between them)",
        unit="Hz", minimum=0.0, strictly=True))
    modal_damping: float = field(default=DEFAULT_CASING_DAMPING, metadata=spec(
        "Damping ratio zeta of each elastic mode of the casing (a modal damper ``2 zeta w_i`` per "
        "mass-normalised mode), below 1", unit=DIMENSIONLESS, minimum=0.0,
        help="damping ratio of each elastic casing mode (empty: 0.02)"))
    modes: str | int = field(default="auto", metadata=spec(
        "Fixed-interface modes of the casing: the low-frequency rule on its first free-free frequency, none, or "
        "a count", type='{"auto", "static"} or int', check="own"))

    def __post_init__(self):
        if (self.geometry is None) == (self.mesh is None):
            raise CaseError(_ITEM, "geometry", self.geometry, "exactly one of geometry and mesh")
        if self.geometry is not None:
            if not isinstance(self.geometry, CasingGeometry):
                raise CaseError(_ITEM, "geometry", self.geometry, "a CasingGeometry")
            for name, value, expected in self.geometry.problems():
                raise CaseError(_ITEM, f"geometry.{name}", value, expected)
        else:
            if not Path(str(self.mesh)).is_file():
                raise CaseError(_ITEM, "mesh", self.mesh, "an existing mesh file (meshio: .msh, .inp, .vtu, ...)")
            object.__setattr__(self, "scale", positive_number(_ITEM, "scale", self.scale))
        if not isinstance(self.material, Material):
            raise CaseError(_ITEM, "material", self.material, "a flexbodies Material")
        check_fields(self, _ITEM)
        if self.modal_damping >= 1.0:
            raise CaseError(_ITEM, "modal_damping", self.modal_damping, "a damping ratio >= 0 and < 1")
        if not (self.modes in ("auto", "static") or (isinstance(self.modes, int) and not isinstance(self.modes, bool)
                                                       and self.modes >= 0)):
            raise CaseError(_ITEM, "modes", self.modes, "'auto', 'static' or a count >= 0")
        if isinstance(self.modes, int):
            bounded_count(_ITEM, "modes", self.modes, 0, MAX_MODE_COUNT, "the most modes a reduction keeps by count")
        try:
            planes = tuple(float(x) for x in self.bearing_planes)
        except (TypeError, ValueError):
            raise CaseError(_ITEM, "bearing_planes", self.bearing_planes, "x positions, m") from None
        if len(planes) < 2 or not all(math.isfinite(x) for x in planes) or len(set(planes)) != len(planes):
            raise CaseError(_ITEM, "bearing_planes", self.bearing_planes, "two or more distinct x positions, m")
        if self.geometry is not None:
            g = self.geometry
            for k, x in enumerate(planes):
                if not g.x_start <= x <= g.x_end:
                    raise CaseError(_ITEM, f"bearing_planes[{k}]", x, f"a plane within the casing, x {g.x_start:g} to "
                                                               f"{g.x_end:g} m")
        object.__setattr__(self, "bearing_planes", planes)

    @property
    def band(self) -> float:
        """Half-width of the band of casing surface tied to each bearing plane, m."""
        if self.bearing_band is not None:
            return self.bearing_band
        if self.geometry is None:
            return 0.05
        return self.element_size if self.element_size is not None else default_casing_element_size(self.geometry)

    def check(self, mass: float, centre_of_mass, eyes) -> None:
        """Check the casing against its engine: each mount eye within the spider radius of the
        casing's solid, a parametric casing lighter than the engine.

        Parameters
        ----------
        mass : float
            The engine's mass, kg.
        centre_of_mass : 3 floats
            The engine's centre of gravity, m.
        eyes : sequence of (str, 3 floats)
            The engine-side hinges: name and position, m.

        Raises
        ------
        CaseError
        """
        if self.geometry is None:
            return  # a mesh file's surface is known once it is read (the reduction checks it)
        origin = casing_origin(centre_of_mass)
        for name, point in eyes:
            distance = self.geometry.distance(np.subtract(point, origin))
            if distance > self.spider_radius:
                raise CaseError(f"hinge {name!r}", "position", tuple(point),
                                f"a mount eye on the engine casing (within its spider_radius {self.spider_radius:g} m; "
                                f"the point is {distance:.4g} m from the casing)")
        casing_mass = self.geometry.volume() * self.material.density
        if casing_mass >= mass:
            raise CaseError(_ITEM, "geometry", f"a casing of {casing_mass:.1f} kg",
                            f"a casing lighter than the engine ({mass:g} kg)")

    def model(self, centre_of_mass, eyes) -> CasingModel:
        """The casing's reduction inputs, its interfaces (the eyes by the names given, then the
        bearing planes) in the casing frame.

        Parameters
        ----------
        centre_of_mass : 3 floats
            The engine's centre of gravity, m.
        eyes : sequence of (str, 3 floats)
            Interface name and position of each mount eye, m.
        """
        origin = casing_origin(centre_of_mass)
        interfaces = tuple(CasingInterface(name, tuple(np.subtract(point, origin).tolist()), "eye", self.spider_radius)
                           for name, point in eyes)
        interfaces += tuple(CasingInterface(bearing_name(x), (x, 0.0, 0.0), "bearing", self.band)
                            for x in self.bearing_planes)
        return CasingModel(interfaces, geometry=self.geometry, mesh_file=self.mesh, scale=self.scale,
                           material=self.material, element_size=self.element_size)


def bearing_name(x: float) -> str:
    """Name of the bearing plane at *x* (m)."""
    return f"bearing x={x:g} m"


def casing_origin(centre_of_mass) -> np.ndarray:
    """Origin of the casing frame in the case frame: on the engine axis through the CG, at x = 0, m."""
    return np.array([0.0, float(centre_of_mass[1]), float(centre_of_mass[2])])


@dataclass(frozen=True)
class CoreBody:
    """The rigid core: the engine less its casing.

    Attributes
    ----------
    mass : float
        kg.
    centre_of_mass : ndarray, shape (3,)
        Case frame, m.
    inertia : ndarray, shape (3, 3)
        About its own centre of mass, case axes, kg m^2.
    """

    mass: float
    centre_of_mass: np.ndarray
    inertia: np.ndarray


def parallel_axis(mass: float, offset) -> np.ndarray:
    """Parallel-axis term ``m (|d|^2 I - d d^T)``, kg m^2."""
    d = np.asarray(offset, dtype=float)
    return mass * (d @ d * np.eye(3) - np.outer(d, d))


def split_engine(mass: float, centre_of_mass, inertia, casing_mass: float, casing_centre, casing_inertia) -> CoreBody:
    """The core that, with the casing, makes the engine's mass properties.

    Parameters
    ----------
    mass, centre_of_mass, inertia
        The engine: kg, m (case frame), kg m^2 about its CG.
    casing_mass, casing_centre, casing_inertia
        The casing: kg, m (case frame), kg m^2 about its own centre of mass.

    Returns
    -------
    CoreBody

    Raises
    ------
    CaseError
        The casing is at least as heavy as the engine, or the remaining inertia
        is not positive definite.
    """
    core_mass = mass - casing_mass
    if core_mass <= 0:
        raise CaseError(_ITEM, "geometry", f"a casing of {casing_mass:.1f} kg",
                        f"a casing lighter than the engine ({mass:g} kg)")
    cg = np.asarray(centre_of_mass, dtype=float)
    core_centre = (mass * cg - casing_mass * np.asarray(casing_centre, dtype=float)) / core_mass
    about_cg = np.asarray(inertia, dtype=float) - np.asarray(casing_inertia, dtype=float) \
        - parallel_axis(casing_mass, np.subtract(casing_centre, cg))
    core_inertia = about_cg - parallel_axis(core_mass, core_centre - cg)
    principal = np.linalg.eigvalsh(0.5 * (core_inertia + core_inertia.T))
    if principal[0] <= 0:
        raise CaseError(_ITEM, "geometry", f"a casing of {casing_mass:.1f} kg whose inertia leaves the core "
                        f"principal moments {', '.join(f'{p:.4g}' for p in principal)} kg m^2",
                        "a casing whose inertia is less than the engine's (a positive definite remainder)")
    return CoreBody(core_mass, core_centre, core_inertia)
