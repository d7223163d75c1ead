"""An engine casing as a flexible body: its geometry, its mesh and its interfaces.

The casing lives in its own frame: the x axis is the casing (engine) axis,
the origin on it. A parametric :class:`CasingGeometry` is a circular tube
(outer radius, wall thickness, from ``x_start`` to ``x_end``) with mount
frame rings (:class:`MountRing`: thicker, wider bands at given x), meshed
with gmsh in quadratic tetrahedra like the links; a user's mesh file is read
by :func:`flexbodies.meshing.load_mesh`.

Interfaces (each tied to one master node by RBE2 or RBE3, as a link's bores):

- an *eye* (a mount hinge on the casing): the casing surface faces whose
  centroids lie within a spider radius of the eye point, its master node at
  the eye point;
- a *bearing plane* (where the rotors sit): the faces whose centroids lie
  within a band of the plane's x, its master node on the axis in that plane.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .errors import LinkModelError

if TYPE_CHECKING:  # meshing loads gmsh, meshio and scikit-fem: imported where a casing is meshed
    from .meshing import BodyMesh

__all__ = ["MountRing", "CasingGeometry", "CasingInterface", "mesh_casing", "casing_interfaces",
           "default_casing_element_size", "ElementSizeTooLarge", "element_size_error"]


#: Elements at least round a full circle: 12 (a 30 degree arc per quadratic
#: element) unless the element size asks for more.
_CURVATURE_POINTS = 12


def _real(value) -> bool:
    """True for a finite real number (not a bool, not None)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


@dataclass(frozen=True)
class MountRing:
    """A mount frame ring around the casing.

    Attributes
    ----------
    x : float
        Position of the ring's mid-plane along the casing axis, m.
    width : float
        Axial width, m.
    outer_radius : float
        Outer radius (the ring runs from the casing's inner radius to it), m.
    """

    x: float
    width: float
    outer_radius: float


@dataclass(frozen=True)
class CasingGeometry:
    """A parametric casing: a tube with mount frame rings, in the casing frame.

    Attributes
    ----------
    radius : float
        Outer radius of the tube wall, m.
    thickness : float
        Wall thickness, m.
    x_start, x_end : float
        Ends of the tube along the axis, m (``x_start < x_end``).
    rings : tuple of MountRing
        Mount frame rings (each within the tube's length, wider than the wall).
    """

    radius: float
    thickness: float
    x_start: float
    x_end: float
    rings: tuple = ()

    @property
    def inner_radius(self) -> float:
        """Inner radius of the wall, m."""
        return self.radius - self.thickness

    @property
    def length(self) -> float:
        """Length of the tube, m."""
        return self.x_end - self.x_start

    def problems(self) -> list[tuple[str, object, str]]:
        """What is wrong with the numbers: (field, value, what was expected) per problem."""
        found = [(name, getattr(self, name), "a length > 0, m") for name in ("radius", "thickness")
                 if not (_real(getattr(self, name)) and getattr(self, name) > 0)]
        found += [(name, getattr(self, name), "a position, m") for name in ("x_start", "x_end")
                  if not _real(getattr(self, name))]
        if found:
            return found
        if self.thickness >= self.radius:
            found.append(("thickness", self.thickness, f"less than the radius {self.radius:g} m"))
        if not self.x_end > self.x_start:
            found.append(("x_end", self.x_end, f"a position beyond x_start {self.x_start:g} m"))
            return found
        for k, ring in enumerate(self.rings):
            if not all(_real(value) for value in (ring.x, ring.width, ring.outer_radius)):
                found.append((f"rings[{k}]", ring, "a ring's mid-plane x, width and outer radius, m"))
            elif not (ring.width > 0 and ring.outer_radius > self.radius):
                found.append((f"rings[{k}]", ring, f"a width > 0 and an outer radius > the casing radius "
                                                   f"{self.radius:g} m"))
            elif ring.x - ring.width / 2 < self.x_start or ring.x + ring.width / 2 > self.x_end:
                found.append((f"rings[{k}]", ring, f"a ring within the casing, x {self.x_start:g} to {self.x_end:g} m"))
        return found

    def distance(self, point) -> float:
        """Distance of a point (casing frame, m) from the casing's solid, m (0 inside it).

        The solid is axisymmetric, so the nearest point lies in the point's
        meridian plane: the distance in (x, r) to the union of the wall's and
        the rings' rectangles.
        """
        x, r = float(point[0]), float(np.hypot(point[1], point[2]))
        boxes = [(self.x_start, self.x_end, self.inner_radius, self.radius)]
        boxes += [(ring.x - ring.width / 2, ring.x + ring.width / 2, self.inner_radius, ring.outer_radius)
                  for ring in self.rings]
        return min(float(np.hypot(max(x0 - x, 0.0, x - x1), max(r0 - r, 0.0, r - r1))) for x0, x1, r0, r1 in boxes)

    def volume(self) -> float:
        """Volume of the solid, m^3."""
        wall = math.pi * (self.radius ** 2 - self.inner_radius ** 2) * self.length
        return wall + sum(math.pi * (ring.outer_radius ** 2 - self.radius ** 2) * ring.width for ring in self.rings)


def default_casing_element_size(geometry: CasingGeometry) -> float:
    """Default element size of :func:`mesh_casing`, m.

    Quadratic tetrahedra follow the wall's bending with one element through
    its thickness; 2 t keeps their aspect ratio moderate. The size is kept at
    most ``radius / 4`` (at least 25 elements round the circumference).
    """
    return min(2.0 * geometry.thickness, geometry.radius / 4.0)


def mesh_casing(geometry: CasingGeometry, element_size: float | None = None) -> BodyMesh:
    """Mesh a parametric casing with quadratic tetrahedra (gmsh, OpenCASCADE).

    Parameters
    ----------
    geometry : CasingGeometry
    element_size : float, optional
        Largest element edge, m (default :func:`default_casing_element_size`).

    Returns
    -------
    BodyMesh
        The casing's mesh in its frame, without bores (its interfaces come
        from :func:`casing_interfaces`).
    """
    import gmsh

    from .meshing import BodyMesh, generate_tet10, gmsh_model, skfem_mesh

    size = default_casing_element_size(geometry) if element_size is None else float(element_size)
    if not (math.isfinite(size) and size > 0):
        raise LinkModelError(f"casing element size must be a positive length in m, got {element_size!r}")
    g = geometry
    with gmsh_model("casing"):
        occ = gmsh.model.occ
        solid = [(3, occ.addCylinder(g.x_start, 0, 0, g.length, 0, 0, g.radius))]
        rings = [(3, occ.addCylinder(ring.x - ring.width / 2, 0, 0, ring.width, 0, 0, ring.outer_radius))
                 for ring in g.rings]
        if rings:
            solid, _ = occ.fuse(solid, rings)
        bore = (3, occ.addCylinder(g.x_start - g.length, 0, 0, 3 * g.length, 0, 0, g.inner_radius))
        occ.cut(solid, [bore])
        occ.synchronize()
        points, cells = generate_tet10(size, curvature_points=_CURVATURE_POINTS)
    mesh, _ = skfem_mesh("tetra10", points, cells)
    return BodyMesh(mesh=mesh, bores=(), source=f"gmsh casing mesh, element size {size * 1e3:.4g} mm")


#: Each smaller element size tried for one that meshes is this share of the last.
_SIZE_STEP = 0.9


class ElementSizeTooLarge(LinkModelError):
    """A parametric casing whose gmsh mesh at its element size has tangled elements.

    Attributes
    ----------
    element_size : float
        The size asked for, m.
    largest : float
        The largest size tried that meshes untangled, m (the default size
        when none larger does).
    """

    def __init__(self, message: str, element_size: float, largest: float):
        super().__init__(message)
        self.element_size, self.largest = element_size, largest


def element_size_error(geometry: CasingGeometry, element_size: float, tangled: int,
                       total: int) -> ElementSizeTooLarge:
    """Why *element_size* does not mesh *geometry*, with the largest size that does.

    Quadratic tetrahedra much larger than the wall's thickness, their edge
    nodes placed on the curved surfaces, fold over (on the reference casing,
    0.5 m radius and 25 mm wall: 0.13 m meshes, 0.14 m gives 2 tangled
    elements; a 50 mm wall tangles already at 0.22 m). The sizes from
    *element_size* down in steps of :data:`_SIZE_STEP` are meshed until one
    has no tangled element, at most down to the default size.

    Parameters
    ----------
    geometry : CasingGeometry
    element_size : float
        m.
    tangled, total : int
        Tangled elements at *element_size*, and all elements.
    """
    from .assembly import tangled_elements

    default = default_casing_element_size(geometry)
    size = float(f"{element_size * _SIZE_STEP:.3g}")      # the size tried is the size offered
    while size > default and tangled_elements(mesh_casing(geometry, size).mesh).size:
        size = float(f"{size * _SIZE_STEP:.3g}")
    largest = max(size, default)
    return ElementSizeTooLarge(
        f"the parametric casing meshed with element_size {element_size:.4g} m has {tangled} of "
        f"{total} quadratic elements tangled: larger than its {geometry.thickness:g} m wall several times "
        f"over, an element folds where its edge nodes follow the curved surfaces. element_size {largest:g} m "
        f"meshes (the default for this casing is {default:.3g} m)", element_size, largest)


@dataclass(frozen=True)
class CasingInterface:
    """Where a casing is joined to the scene.

    Attributes
    ----------
    name : str
    point : 3 floats
        The master node, casing frame, m: an eye point, or the axis point of
        a bearing plane.
    kind : {"eye", "bearing"}
        An eye takes the surface within ``reach`` of the point, a bearing
        plane the surface within ``reach`` of its x.
    reach : float
        The spider radius (eye) or the band's half-width (bearing plane), m.
    """

    name: str
    point: tuple
    kind: str
    reach: float


def casing_interfaces(casing_mesh: BodyMesh, interfaces, source: str) -> BodyMesh:
    """The casing mesh with one resolved :class:`~flexbodies.meshing.Bore` per interface.

    Each interface is the set of boundary faces whose centroids lie within
    its reach; its master node (the bore's centre) is the interface's point.
    A node that two interfaces reach belongs to the one it is nearer to.

    Raises
    ------
    ValueError
        An interface without a boundary face within its reach (the message
        gives the nearest boundary face's distance), or one whose nodes all
        belong to nearer interfaces; both name *source*.
    """
    from .meshing import Bore


    mesh = casing_mesh.mesh
    facets = mesh.boundary_facets()
    centroids = mesh.doflocs[:, mesh.facets[:, facets]].mean(axis=1)  # (3, faces)
    axis = np.array([1.0, 0.0, 0.0])
    bores = []
    for interface in interfaces:
        point = np.asarray(interface.point, dtype=float)
        hit = _reach(interface, centroids) <= interface.reach
        if not hit.any():
            what = (f"within {interface.reach:g} m of the eye point {point.tolist()} m" if interface.kind == "eye"
                    else f"within {interface.reach:g} m of the bearing plane x = {point[0]:g} m")
            raise LinkModelError(f"{source}: interface {interface.name!r}: no casing surface {what} "
                                 f"(the nearest surface face is {_reach(interface, centroids).min():.4g} m away)")
        nodes, weights = _tributary(mesh, facets[hit])
        bores.append(Bore(interface.name, point, axis, interface.reach, nodes, weights))
    nodes = np.concatenate([bore.nodes for bore in bores])
    owner = np.full(mesh.doflocs.shape[1], -1)
    if len(np.unique(nodes)) < len(nodes):
        shared = np.unique(nodes)
        reach = np.array([_reach(interface, mesh.doflocs[:, shared]) for interface in interfaces])
        for k, bore in enumerate(bores):
            reach[k, ~np.isin(shared, bore.nodes)] = np.inf
        owner[shared] = np.argmin(reach, axis=0)
        for k, (interface, bore) in enumerate(zip(interfaces, bores, strict=True)):
            keep = owner[bore.nodes] == k
            if not keep.any():
                raise LinkModelError(f"{source}: interface {interface.name!r}: every surface node within its reach "
                                     f"is nearer to another interface; move them apart or reduce the reach")
            bores[k] = dataclasses.replace(bore, nodes=bore.nodes[keep], weights=bore.weights[keep])
    return dataclasses.replace(casing_mesh, bores=tuple(bores))


def _tributary(mesh, facets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The nodes of boundary faces and each one's share of their area (each face's
    area split equally among its nodes; corners and, on quadratic meshes, edge
    nodes), m^2: positive weights that sum to the faces' area."""
    corners = mesh.facets[:, facets]
    x = mesh.doflocs[:, corners]
    area = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], axis=0), axis=0)
    per_face = [corners]
    if mesh.doflocs.shape[1] > mesh.nvertices:
        per_face.append(mesh.nvertices + mesh.f2e[:, facets])
    stacked = np.vstack(per_face)
    nodes, index = np.unique(stacked, return_inverse=True)
    weights = np.bincount(index.ravel(), weights=np.broadcast_to(area / len(stacked), stacked.shape).ravel(),
                          minlength=len(nodes))
    return nodes, weights


def _reach(interface: CasingInterface, points: np.ndarray) -> np.ndarray:
    """Distance of points (3, k) from an interface: from the eye point, or from the bearing plane, m."""
    point = np.asarray(interface.point, dtype=float)
    if interface.kind == "eye":
        return np.linalg.norm(points - point[:, None], axis=0)
    return np.abs(points[0] - point[0])
