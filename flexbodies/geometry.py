"""Parametric connecting-link geometry: a shank with an eye at each end."""
from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import LinkModelError

__all__ = ["LinkGeometry", "SIGNIFICANT_DIGITS", "default_element_size"]

#: Significant digits a dimension keeps: 1e-12 relative, far below any mesh size, far above round-off.
SIGNIFICANT_DIGITS = 12


@dataclass(frozen=True)
class LinkGeometry:
    """Dimensions of a connecting link, all in m.

    Local frame: eye A's centre is at the origin and eye B's centre at
    ``(length, 0, 0)``; the link axis is local x. Both bore axes run along
    local z, and the eyes and the shank are centred on the plane z = 0.
    The shank is a rectangular bar from eye centre to eye centre, fused
    with the two eye discs; the bores are cut through everything.

    Parameters
    ----------
    length : float
        Distance between the two eye centres, m.
    eye_outer_radius : float
        Outer radius of each eye, m.
    bore_radius : float
        Radius of each bore (the spherical bearing's seat), m.
    thickness : float
        Eye thickness along the bore axis (local z), m.
    shank_width : float
        Shank width in the link plane, perpendicular to the link axis
        (local y), m.
    shank_thickness : float
        Shank thickness along the bore axis (local z), m; at most
        ``thickness``.

    Each dimension is kept to :data:`SIGNIFICANT_DIGITS` significant digits,
    so that two links whose lengths differ only by round-off (one computed
    from hinge points, one typed in) are the same link and share one
    reduction.

    Raises
    ------
    ValueError
        If a dimension is not positive or the parts do not fit together.
    """

    length: float
    eye_outer_radius: float
    bore_radius: float
    thickness: float
    shank_width: float
    shank_thickness: float

    def __post_init__(self):
        for field_name in ("length", "eye_outer_radius", "bore_radius", "thickness",
                           "shank_width", "shank_thickness"):
            value = getattr(self, field_name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise LinkModelError(f"link geometry: {field_name} must be a positive length in m, got {value!r}")
            object.__setattr__(self, field_name, float(f"{value:.{SIGNIFICANT_DIGITS}g}"))
        if self.bore_radius >= self.eye_outer_radius:
            raise LinkModelError(
                f"link geometry: the bore radius ({self.bore_radius} m) must be smaller than "
                f"the eye outer radius ({self.eye_outer_radius} m)"
            )
        if self.shank_width >= 2 * self.eye_outer_radius:
            raise LinkModelError(
                f"link geometry: the shank width ({self.shank_width} m) must be smaller than "
                f"the eye diameter ({2 * self.eye_outer_radius} m)"
            )
        if self.shank_thickness > self.thickness:
            raise LinkModelError(
                f"link geometry: the shank thickness ({self.shank_thickness} m) must not exceed "
                f"the eye thickness ({self.thickness} m)"
            )
        if self.length <= 2 * self.eye_outer_radius:
            raise LinkModelError(
                f"link geometry: the eyes overlap; the distance between eye centres "
                f"({self.length} m) must exceed twice the eye outer radius ({2 * self.eye_outer_radius} m)"
            )

    @property
    def volume(self) -> float:
        """Exact volume of the solid in m^3 (eye rings plus the shank between them)."""
        big_r, small_r = self.eye_outer_radius, self.bore_radius
        half_w = self.shank_width / 2
        rings = 2 * math.pi * (big_r**2 - small_r**2) * self.thickness
        # In-plane area of the shank strip that lies inside one eye disc (x > 0 half).
        inside_eye = half_w * math.sqrt(big_r**2 - half_w**2) + big_r**2 * math.asin(half_w / big_r)
        shank = self.shank_thickness * (self.shank_width * self.length - 2 * inside_eye)
        return rings + shank


def default_element_size(geometry: LinkGeometry) -> float:
    """Default element size of :func:`flexbodies.meshing.mesh_link`, m.

    Four tenths of the smallest cross-section dimension (eye thickness,
    shank width and thickness), but at most two thirds of the eye ring
    width ``eye_outer_radius - bore_radius``. For the reference link
    (25 mm thick, 15 mm ring) this is 10 mm, giving about 18k DOF with
    quadratic tetrahedra.

    Parameters
    ----------
    geometry : LinkGeometry

    Returns
    -------
    float
        Element size in m.
    """
    g = geometry
    return min(0.4 * min(g.thickness, g.shank_width, g.shank_thickness),
               2 / 3 * (g.eye_outer_radius - g.bore_radius))
