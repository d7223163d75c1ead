"""Bores of a meshed link: :class:`BoreSpec` (how to find one) and :class:`Bore` (found, as FE nodes).

Apart from :mod:`flexbodies.meshing` (whose names they also are) so that a
case naming its bores is read without loading meshio and scikit-fem.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import LinkModelError

__all__ = ["Bore", "BoreSpec"]


@dataclass(frozen=True)
class Bore:
    """A bore surface of a meshed link, resolved to finite element nodes.

    Parameters
    ----------
    name : str
        Bore name ("A" and "B" for :func:`mesh_link`).
    centre : ndarray, shape (3,)
        Centre of the bore in m: the area centroid of the bore surface
        (for a geometric search, projected onto the given axis).
    axis : ndarray, shape (3,)
        Unit vector along the bore axis (sign arbitrary).
    radius : float
        Bore radius in m.
    nodes : ndarray of int, shape (k,)
        Indices of the finite element nodes on the bore surface.
    weights : ndarray, shape (k,)
        Integral of each node's shape function over the bore surface, m^2:
        the nodal loads of a unit uniform traction. They sum to the surface
        area (2 pi r t for a full cylindrical bore). Corner nodes of 6-node
        triangles carry (nearly) zero weight; that is correct.
    """

    name: str
    centre: np.ndarray
    axis: np.ndarray
    radius: float
    nodes: np.ndarray
    weights: np.ndarray

    @property
    def area(self) -> float:
        """Area of the bore surface in m^2 (sum of the weights)."""
        return float(self.weights.sum())


@dataclass(frozen=True)
class BoreSpec:
    """How to find a bore in a mesh: geometrically or by a named node set.

    Give either ``centre``, ``axis`` and ``radius`` (geometric search) or
    ``node_set`` (a meshio point set, a gmsh physical group or an Abaqus NSET).

    Parameters
    ----------
    name : str
        Name given to the resolved :class:`Bore`.
    centre : sequence of 3 float, optional
        Any point on the bore axis, m (after the mesh's ``scale``).
    axis : sequence of 3 float, optional
        Direction of the bore axis (normalised here).
    radius : float, optional
        Bore radius, m.
    tolerance : float, optional
        Radial tolerance of the geometric search, m. Boundary faces whose
        corner nodes all lie within ``radius +- tolerance`` of the axis line
        form the bore. Default ``1e-3 * radius``.
    node_set : str, optional
        Name of a node set in the mesh file. Boundary faces whose corner
        nodes all belong to the set form the bore; its centre, axis and
        radius are fitted to that surface.
    """

    name: str
    centre: tuple | None = None
    axis: tuple | None = None
    radius: float | None = None
    tolerance: float | None = None
    node_set: str | None = None

    def __post_init__(self):
        geometric = [self.centre is not None, self.axis is not None, self.radius is not None]
        if self.node_set is not None:
            if any(geometric):
                raise LinkModelError(f"bore {self.name!r}: give either node_set or centre/axis/radius, not both")
            return
        if not all(geometric):
            raise LinkModelError(f"bore {self.name!r}: a geometric bore needs centre, axis and radius (or give node_set)")
        assert self.centre is not None and self.axis is not None and self.radius is not None
        if np.shape(self.centre) != (3,) or np.shape(self.axis) != (3,):
            raise LinkModelError(f"bore {self.name!r}: centre and axis must each have 3 components")
        if not np.linalg.norm(np.asarray(self.axis, dtype=float)) > 0:
            raise LinkModelError(f"bore {self.name!r}: the axis must be a non-zero vector")
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise LinkModelError(f"bore {self.name!r}: the radius must be a positive length in m, got {self.radius!r}")
        if self.tolerance is not None and not self.tolerance > 0:
            raise LinkModelError(f"bore {self.name!r}: the tolerance must be positive, got {self.tolerance!r}")
