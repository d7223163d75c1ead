"""Volume meshes of bodies (links, the engine casing, the mesh pylon), with their bore surfaces identified.

Two ways in:

- :func:`mesh_link` meshes a parametric :class:`~flexbodies.geometry.LinkGeometry`
  with gmsh (OpenCASCADE kernel, quadratic tetrahedra);
- :func:`load_mesh` reads a user's own mesh through meshio (gmsh ``.msh``,
  Abaqus ``.inp``, ``.vtu``, ...), with bores found geometrically or from
  named node sets.

Both return a :class:`BodyMesh`: a scikit-fem mesh whose finite element nodes
(vertices and, for quadratic elements, edge/face/cell nodes) are numbered as
``mesh.doflocs``, plus the resolved :class:`Bore` surfaces.

Bores are always resolved here rather than through scikit-fem's meshio import:
second-order gmsh meshes lose their named surfaces there (it looks for
``triangle`` cells, not ``triangle6``).
"""
from __future__ import annotations

import contextlib
import logging
import math
import signal
import threading
from dataclasses import dataclass
from pathlib import Path

import meshio
import numpy as np
import skfem
from skfem.io.meshio import HEX_MAPPING

from workbook._renamed import renamed_names

from .bores import Bore, BoreSpec
from .errors import LinkModelError
from .geometry import LinkGeometry, default_element_size

__all__ = ["Bore", "BoreSpec", "BodyMesh", "mesh_link", "load_mesh", "mesh_pieces", "default_element_size", "gmsh_model",
           "generate_tet10", "refine_near", "skfem_mesh", "surface_basis"]

logger = logging.getLogger(__name__)

#: meshio cell type -> scikit-fem mesh class, in order of preference
_CELL_TYPES = {
    "tetra10": skfem.MeshTet2,
    "hexahedron27": skfem.MeshHex2,
    "tetra": skfem.MeshTet1,
    "hexahedron": skfem.MeshHex1,
}
_LINEAR_TYPES = {"tetra", "hexahedron"}
_SUPPORTED_MESHES = tuple(_CELL_TYPES.values())

#: tetra10 node order of VTK/meshio (and scikit-fem): corners 0-3, then edges
#: 01, 12, 20, 03, 13, 23. gmsh's differs in the last two edge nodes.
_GMSH_TO_VTK_TET10 = np.array([0, 1, 2, 3, 4, 5, 6, 7, 9, 8])
_GMSH_TET10 = 11  # gmsh element type number

#: Relative radial tolerance of a geometric bore search when none is given.
_DEFAULT_RELATIVE_TOLERANCE = 1e-3
#: Integration order of the bore surface integrals (quadratic shape
#: function times a curved surface element).
_SURFACE_INTORDER = 4

#: The connectivity a scikit-fem mesh finds on first use (faces, edges and their maps to the elements):
#: it depends on the elements alone, so a moved copy of a mesh takes the original's.
_CONNECTIVITY = ("_facets", "_t2f", "_f2t", "_edges", "_t2e", "_f2e")

_GMSH_LOCK = threading.Lock()


@dataclass(frozen=True)
class BodyMesh:
    """A scikit-fem volume mesh of a body (a link, the casing, the mesh pylon) and its resolved bores.

    Parameters
    ----------
    mesh : skfem.MeshTet2, MeshTet1, MeshHex2 or MeshHex1
        Volume mesh in m. Its finite element nodes are ``mesh.doflocs``.
    bores : tuple of Bore
        The bores, in the order they were specified.
    source : str
        Where the mesh came from, for messages and reports.
    """

    mesh: skfem.Mesh
    bores: tuple = ()
    source: str = "scikit-fem mesh"

    def __post_init__(self):
        if type(self.mesh) not in _SUPPORTED_MESHES:
            raise TypeError(f"{self.source}: unsupported mesh type {type(self.mesh).__name__}; "
                            f"use one of {', '.join(c.__name__ for c in _SUPPORTED_MESHES)}")

    @classmethod
    def from_skfem(cls, mesh: skfem.Mesh, bores=(), source: str = "scikit-fem mesh") -> "BodyMesh":
        """Wrap a scikit-fem mesh and resolve geometric bore specifications.

        Parameters
        ----------
        mesh : skfem.MeshTet2, MeshTet1, MeshHex2 or MeshHex1
            Volume mesh in m.
        bores : sequence of BoreSpec, optional
            Geometric bore specifications (node sets need a mesh file).
        source : str, optional
            Description of the mesh's origin, used in messages.

        Returns
        -------
        BodyMesh
        """
        resolved = tuple(_resolve_bore(mesh, spec, source, node_sets=None) for spec in bores)
        return cls(mesh=mesh, bores=resolved, source=source)

    @property
    def nodes(self) -> np.ndarray:
        """Finite element node coordinates, shape (n, 3), m."""
        return self.mesh.doflocs.T

    @property
    def element_name(self) -> str:
        """Plain-words name of the element type, e.g. ``"quadratic tetrahedra"``."""
        return {
            skfem.MeshTet2: "quadratic tetrahedra",
            skfem.MeshTet1: "linear tetrahedra",
            skfem.MeshHex2: "quadratic hexahedra",
            skfem.MeshHex1: "linear hexahedra",
        }[type(self.mesh)]

    def describe(self) -> str:
        """One-line summary: element type, counts, DOF, bores and origin."""
        n = self.mesh.doflocs.shape[1]
        bores = ", ".join(f"{b.name} (r={b.radius * 1e3:.4g} mm, {b.nodes.size} nodes)" for b in self.bores)
        return (f"{self.element_name}, {self.mesh.nelements} elements, {n} nodes, {3 * n} DOF; "
                f"bores: {bores or 'none'}; from {self.source}")

    def surface_triangles(self) -> np.ndarray:
        """Triangles covering the outer surface, for drawing.

        Returns
        -------
        ndarray of int, shape (k, 3)
            Node indices, counter-clockwise seen from outside. A 6-node
            triangle face is split into 4 triangles through its edge nodes;
            a quadrilateral face into 2 through its corners.
        """
        return _surface_triangles(self.mesh)

    def to_meshio(self) -> meshio.Mesh:
        """The volume mesh as a meshio mesh, bores as point sets (node indices).

        Returns
        -------
        meshio.Mesh
            Points in m; cells in meshio (VTK) node order.
        """
        mesh = self.mesh
        cell_type = next(k for k, c in _CELL_TYPES.items() if type(mesh) is c)
        dofs = mesh.dofs.element_dofs
        if cell_type.startswith("hexahedron"):
            dofs = dofs[np.array(HEX_MAPPING[: dofs.shape[0]])]
        return meshio.Mesh(
            points=self.nodes.copy(),
            cells=[(cell_type, np.ascontiguousarray(dofs.T))],
            point_sets={b.name: b.nodes.copy() for b in self.bores},
        )


def mesh_link(geometry: LinkGeometry, element_size: float | None = None,
              bore_element_size: float | None = None) -> BodyMesh:
    """Mesh a parametric link with quadratic tetrahedra (gmsh, OpenCASCADE).

    The mesh is deterministic: the same input gives the same nodes and
    elements (gmsh runs single-threaded with fixed options). Nothing is
    written to disk and gmsh's terminal output is off.

    Parameters
    ----------
    geometry : LinkGeometry
        Link dimensions in m, in the local frame documented there.
    element_size : float, optional
        Largest element edge length in m. Bores get at least 16 elements
        around their circumference. Default :func:`default_element_size`.
    bore_element_size : float, optional
        A finer element edge at the bore surfaces, m, growing linearly to
        ``element_size`` at one bore radius from them (the local refinement
        of a stress request, :mod:`flexbodies.bore_stress`). Default: none.

    Returns
    -------
    BodyMesh
        Quadratic tetrahedra; bores "A" (centre at the origin) and "B"
        (centre at ``(length, 0, 0)``), both along local z.
    """
    size = default_element_size(geometry) if element_size is None else float(element_size)
    if not (math.isfinite(size) and size > 0):
        raise LinkModelError(f"element size must be a positive length in m, got {element_size!r}")
    fine = None if bore_element_size is None else float(bore_element_size)
    if fine is not None and not (math.isfinite(fine) and 0 < fine <= size):
        raise LinkModelError(f"bore element size must be a positive length in m up to the element size "
                             f"{size:.4g} m, got {bore_element_size!r}")
    g = geometry
    with gmsh_model("link"):
        _build_link_solid(geometry)
        if fine is not None:
            refine_near(_bore_surfaces(g), fine, size, g.bore_radius)
        points, cells = generate_tet10(size)
    mesh, _ = skfem_mesh("tetra10", points, cells)
    specs = (
        BoreSpec("A", centre=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), radius=g.bore_radius),
        BoreSpec("B", centre=(g.length, 0.0, 0.0), axis=(0.0, 0.0, 1.0), radius=g.bore_radius),
    )
    refined = "" if fine is None else f", {fine * 1e3:.4g} mm at the bores"
    link = BodyMesh.from_skfem(mesh, specs, source=f"gmsh link mesh, element size {size * 1e3:.4g} mm{refined}")
    logger.info("meshed link: %s", link.describe())
    return link


def load_mesh(path, bores, *, scale: float = 1.0, file_format: str | None = None) -> BodyMesh:
    """Read a user's link mesh with meshio and resolve its bores.

    Parameters
    ----------
    path : str or Path
        Mesh file in any format meshio reads (.msh, .inp, .vtu, ...).
    bores : sequence of BoreSpec
        Bores to find, e.g. ``[BoreSpec("A", centre=(0, 0, 0), axis=(0, 0, 1),
        radius=0.015), BoreSpec("B", node_set="BORE_B")]``. Geometric values
        are in m, i.e. after scaling.
    scale : float, optional
        Factor from file units to m, e.g. 1e-3 for a mesh in mm.
    file_format : str, optional
        meshio format name, when the file extension does not tell it.

    Returns
    -------
    BodyMesh

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        If the file cannot be read, holds no supported volume cells, is
        more than one connected piece (:func:`mesh_pieces`), or a bore
        cannot be found; the message names the file.

    Notes
    -----
    Supported volume cells: ``tetra10`` (preferred), ``hexahedron27``, and
    the linear ``tetra`` and ``hexahedron``, which are accepted with a
    warning because they are too stiff in bending. All volume cells must
    be of one type.
    """
    path = Path(path)
    if not (math.isfinite(scale) and scale > 0):
        raise LinkModelError(f"{path}: scale must be a positive factor from file units to m, got {scale!r}")
    if not path.is_file():
        raise FileNotFoundError(f"mesh file {path} does not exist")
    try:
        data = meshio.read(path, file_format=file_format)
    except (Exception, SystemExit) as exc:  # meshio raises many types, even SystemExit
        raise LinkModelError(f"cannot read mesh file {path}: {type(exc).__name__}: {exc}") from exc
    cell_type, cells = _volume_cells(data, path)
    if cell_type in _LINEAR_TYPES:
        logger.warning("%s: linear %s elements are too stiff in bending (shear locking); "
                       "prefer quadratic elements (tetra10)", path, cell_type)
    points = np.asarray(data.points, dtype=float)
    if points.shape[1] != 3:
        raise LinkModelError(f"{path}: expected 3-D points, got {points.shape[1]} coordinates per point")
    mesh, fe_index = skfem_mesh(cell_type, points * scale, cells)
    _check_one_piece(mesh, path)
    node_sets = _NodeSets(data, fe_index, path)
    resolved = tuple(_resolve_bore(mesh, spec, str(path), node_sets) for spec in bores)
    link = BodyMesh(mesh=mesh, bores=resolved, source=str(path))
    logger.info("loaded link mesh: %s", link.describe())
    return link


# --- gmsh -------------------------------------------------------------------


@contextlib.contextmanager
def gmsh_model(name: str):
    """A private gmsh model, single-threaded and silent; gmsh is cleaned up after.

    If gmsh was not initialised, it is initialised here and finalised on exit
    (also on error). If the caller already uses gmsh, only the temporary
    model is removed afterwards and the caller's current model restored (the
    options set here stay set).
    """
    import gmsh

    with _GMSH_LOCK:
        owner = not gmsh.isInitialized()
        if owner:
            gmsh.initialize(readConfigFiles=False, interruptible=False)
            _restore_python_signal_handlers()
        previous = None if owner else gmsh.model.getCurrent()
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.option.setNumber("General.Verbosity", 1)
            gmsh.option.setNumber("General.NumThreads", 1)
            gmsh.option.setNumber("Geometry.OCCParallel", 0)
            for dim in (1, 2, 3):
                gmsh.option.setNumber(f"Mesh.MaxNumThreads{dim}D", 1)
            gmsh.option.setNumber("Mesh.RandomSeed", 1)
            gmsh.model.add(name)
            try:
                yield gmsh
            finally:
                gmsh.model.remove()
        finally:
            if owner:
                gmsh.finalize()
            elif previous:
                gmsh.model.setCurrent(previous)


def _restore_python_signal_handlers() -> None:
    """Put Python's handlers of SIGINT, SIGTERM and SIGPIPE back: gmsh's
    initialisation sets the default ones, so that SIGTERM killed the process at
    once, skipping every clean-up, and a write to a closed pipe (a stopped
    worker process's) killed it too, where Python ignores SIGPIPE."""
    if threading.current_thread() is not threading.main_thread():
        return  # handlers can only be set, and only run, in the main thread
    for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGPIPE):
        handler = signal.getsignal(signum)
        if handler is not None:
            signal.signal(signum, handler)


def _build_link_solid(g: LinkGeometry) -> None:
    """Two eye discs fused with the shank bar, bores cut through (gmsh OCC)."""
    import gmsh

    occ = gmsh.model.occ
    half_t = g.thickness / 2
    eyes = [(3, occ.addCylinder(x, 0, -half_t, 0, 0, g.thickness, g.eye_outer_radius)) for x in (0.0, g.length)]
    shank = (3, occ.addBox(0, -g.shank_width / 2, -g.shank_thickness / 2,
                           g.length, g.shank_width, g.shank_thickness))
    solid, _ = occ.fuse([eyes[0]], [eyes[1], shank])
    holes = [(3, occ.addCylinder(x, 0, -g.thickness, 0, 0, 2 * g.thickness, g.bore_radius))
             for x in (0.0, g.length)]
    occ.cut(solid, holes)
    occ.synchronize()


def _bore_surfaces(g: LinkGeometry) -> list[int]:
    """The gmsh surface tags of the two bores of a built link solid."""
    import gmsh

    pad = 1e-6 * g.length
    found = []
    for x in (0.0, g.length):
        box = (x - g.bore_radius - pad, -g.bore_radius - pad, -g.thickness / 2 - pad,
               x + g.bore_radius + pad, g.bore_radius + pad, g.thickness / 2 + pad)
        found += [tag for dim, tag in gmsh.model.getEntitiesInBoundingBox(*box, dim=2)]
    return found


def refine_near(surfaces: list[int], fine: float, size: float, distance: float) -> None:
    """Ask gmsh for elements of edge *fine* (m) on *surfaces*, growing linearly to *size* (m) at *distance* (m)."""
    import gmsh

    field = gmsh.model.mesh.field
    near = field.add("Distance")
    field.setNumbers(near, "SurfacesList", surfaces)
    field.setNumber(near, "Sampling", 100)
    ramp = field.add("Threshold")
    field.setNumber(ramp, "InField", near)
    field.setNumber(ramp, "SizeMin", fine)
    field.setNumber(ramp, "SizeMax", size)
    field.setNumber(ramp, "DistMin", 0.0)
    field.setNumber(ramp, "DistMax", distance)
    field.setAsBackgroundMesh(ramp)


def generate_tet10(size: float, curvature_points: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """Generate quadratic tetrahedra in the current gmsh model.

    Parameters
    ----------
    size : float
        Largest element edge, m.
    curvature_points : int
        Elements at least per full circle of a curved edge (gmsh's
        ``Mesh.MeshSizeFromCurvature``).

    Returns
    -------
    points : ndarray, shape (n, 3)
    cells : ndarray of int, shape (m, 10), VTK/meshio node order
    """
    import gmsh

    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", curvature_points)
    gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay 2-D
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay 3-D
    gmsh.option.setNumber("Mesh.ElementOrder", 2)
    gmsh.model.mesh.generate(3)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    _, node_tags = gmsh.model.mesh.getElementsByType(_GMSH_TET10)
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(tags.size)
    cells = index[node_tags.astype(np.int64)].reshape(-1, 10)[:, _GMSH_TO_VTK_TET10]
    return coords.reshape(-1, 3), cells


# --- meshio -> scikit-fem -----------------------------------------------------


def _volume_cells(data: meshio.Mesh, path: Path) -> tuple[str, np.ndarray]:
    """The volume cells of a meshio mesh: one supported type, all blocks joined."""
    found = {block.type for block in data.cells}
    volume = [t for t in _CELL_TYPES if t in found]
    if not volume:
        listed = ", ".join(sorted(found)) or "no cells at all"
        raise LinkModelError(f"{path}: no supported volume cells (tetra10, hexahedron27, tetra, hexahedron); "
                             f"the file holds {listed}")
    if len(volume) > 1:
        raise LinkModelError(f"{path}: mixed volume cell types {', '.join(volume)} are not supported; "
                             "use one element type")
    cell_type = volume[0]
    cells = np.concatenate([b.data for b in data.cells if b.type == cell_type]).astype(np.int64)
    return cell_type, cells


def skfem_mesh(cell_type: str, points: np.ndarray, cells: np.ndarray):
    """Build a scikit-fem mesh from meshio-ordered cells.

    Unused points are dropped and the node order is checked.

    Returns
    -------
    mesh : skfem.Mesh
    fe_index : ndarray of int, shape (len(points),)
        Finite element node index of each input point, -1 if unused.
    """
    mesh_cls = _CELL_TYPES[cell_type]
    if cell_type.startswith("hexahedron"):
        cells = cells[:, np.argsort(HEX_MAPPING[: cells.shape[1]])]
    used, compact = np.unique(cells, return_inverse=True)
    # scikit-fem renumbers: corner vertices first, then the higher-order nodes.
    mesh = mesh_cls(np.ascontiguousarray(points[used].T), np.ascontiguousarray(compact.reshape(cells.shape).T))
    fe_index = np.full(points.shape[0], -1, dtype=np.int64)
    fe_index[cells.T] = mesh.dofs.element_dofs
    _check_node_order(mesh, points, fe_index, cell_type)
    return mesh, fe_index


def mesh_pieces(mesh: skfem.Mesh) -> np.ndarray:
    """The connected piece of every element: elements sharing a node are joined.

    Parameters
    ----------
    mesh : skfem.Mesh

    Returns
    -------
    ndarray of int, shape (nelements,)
        Piece number of each element, 0 for the piece with the most elements,
        then by decreasing size.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    dofs = mesh.dofs.element_dofs
    nodes = mesh.doflocs.shape[1]
    # each element joins its first node to its others
    graph = coo_matrix((np.ones(dofs[1:].size), (np.repeat(dofs[0], dofs.shape[0] - 1), dofs[1:].T.ravel())),
                       shape=(nodes, nodes))
    _, node_piece = connected_components(graph, directed=False)
    _, piece, sizes = np.unique(node_piece[dofs[0]], return_inverse=True, return_counts=True)
    rank = np.empty_like(sizes)
    rank[np.argsort(-sizes, kind="stable")] = np.arange(sizes.size)
    return rank[piece]


def _check_one_piece(mesh: skfem.Mesh, path: Path) -> None:
    """Refuse a mesh of more than one connected piece: each loose piece would move
    freely, with elastic frequencies of zero."""
    piece = mesh_pieces(mesh)
    count = int(piece.max()) + 1
    if count == 1:
        return
    sizes = np.bincount(piece)
    nodes = np.unique(mesh.dofs.element_dofs[:, piece == 1])
    low, high = mesh.doflocs[:, nodes].min(axis=1), mesh.doflocs[:, nodes].max(axis=1)
    raise LinkModelError(
        f"{path}: the mesh is {count} unconnected pieces ({', '.join(str(s) for s in sizes[:5])}"
        f"{', ...' if count > 5 else ''} elements), not one body: a loose piece moves freely (an elastic "
        f"frequency of zero). The second largest lies within x {low[0]:.4g} to {high[0]:.4g}, "
        f"y {low[1]:.4g} to {high[1]:.4g}, z {low[2]:.4g} to {high[2]:.4g} m. Remove the loose pieces, or "
        f"join pieces that touch by merging their duplicate nodes")


def _check_node_order(mesh, points, fe_index, cell_type) -> None:
    """Check that every input point landed on one FE node and edge nodes sit mid-edge."""
    used = np.flatnonzero(fe_index >= 0)
    if not np.array_equal(mesh.doflocs[:, fe_index[used]], points[used].T):
        raise LinkModelError(f"{cell_type} cells: inconsistent higher-order node numbering "
                             "(two cells disagree about a shared edge or face node)")
    if mesh.doflocs.shape[1] == mesh.nvertices:
        return
    a, b = (mesh.doflocs[:, mesh.edges[k]] for k in (0, 1))
    mid = mesh.doflocs[:, mesh.nvertices + np.arange(mesh.nedges)]
    off = np.linalg.norm(mid - (a + b) / 2, axis=0) / np.linalg.norm(b - a, axis=0)
    if off.max() > 0.25:
        raise LinkModelError(f"{cell_type} cells: edge nodes are not near their edge midpoints "
                             f"(worst offset {off.max():.2f} edge lengths); unsupported node order")


# --- bores ------------------------------------------------------------------


class _NodeSets:
    """Named node sets of a meshio mesh, as FE node indices."""

    def __init__(self, data: meshio.Mesh, fe_index: np.ndarray, path: Path):
        self._data = data
        self._fe_index = fe_index
        self._path = path

    def names(self) -> list[str]:
        d = self._data
        names = set(d.point_sets) | {k for k in d.cell_sets if not k.startswith("gmsh:")}
        return sorted(names | set(d.field_data))

    def get(self, name: str, bore: str) -> np.ndarray:
        """FE node indices of node set ``name``; ValueError listing the sets if absent."""
        names = self.names()
        matches = [n for n in names if n == name] or [n for n in names if n.lower() == name.lower()]
        if len(matches) != 1:
            listed = ", ".join(names) if names else "none"
            raise LinkModelError(f"bore {bore!r}: node set {name!r} not found in {self._path}; "
                                 f"node sets in the file: {listed}")
        points = self._points(matches[0])
        nodes = self._fe_index[points]
        return np.unique(nodes[nodes >= 0])

    def _points(self, name: str) -> np.ndarray:
        d = self._data
        if name in d.point_sets:
            return np.asarray(d.point_sets[name], dtype=np.int64)
        if name in d.cell_sets:
            blocks = zip(d.cells, d.cell_sets[name], strict=True)
            return np.unique(np.concatenate([b.data[idx].ravel() for b, idx in blocks if idx is not None]
                                            or [np.zeros(0, dtype=np.int64)]))
        tag = d.field_data[name][0]
        physical = d.cell_data.get("gmsh:physical", [None] * len(d.cells))
        return np.unique(np.concatenate([b.data[tags == tag].ravel() for b, tags in zip(d.cells, physical, strict=True)
                                         if tags is not None] or [np.zeros(0, dtype=np.int64)]))


def _resolve_bore(mesh, spec: BoreSpec, source: str, node_sets) -> Bore:
    """Find a bore's boundary faces and integrate its nodal weights."""
    facets = mesh.boundary_facets()
    corners = mesh.doflocs[:, mesh.facets[:, facets]]  # (3, corners per face, faces)
    if spec.node_set is not None:
        if node_sets is None:
            raise LinkModelError(f"bore {spec.name!r}: node sets need a mesh file (use load_mesh)")
        in_set = np.zeros(mesh.doflocs.shape[1], dtype=bool)
        in_set[node_sets.get(spec.node_set, spec.name)] = True
        facets = facets[in_set[mesh.facets[:, facets]].all(axis=0)]
        if facets.size == 0:
            raise LinkModelError(f"bore {spec.name!r}: node set {spec.node_set!r} of {source} contains "
                                 "no complete boundary face")
        return _bore_from_facets(mesh, spec.name, facets, None)
    assert spec.axis is not None and spec.radius is not None
    centre = np.asarray(spec.centre, dtype=float)
    axis = np.asarray(spec.axis, dtype=float) / np.linalg.norm(spec.axis)
    tol = spec.tolerance if spec.tolerance is not None else _DEFAULT_RELATIVE_TOLERANCE * spec.radius
    dist = _distance_to_axis(corners, centre, axis)
    hit = (np.abs(dist - spec.radius) <= tol).all(axis=0)
    if not hit.any():
        raise LinkModelError(_no_bore_message(spec, source, tol, dist, centre, axis))
    return _bore_from_facets(mesh, spec.name, facets[hit], (centre, axis, spec.radius))


def _distance_to_axis(x: np.ndarray, centre: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Distance of points ``x`` (3, ...) from the line through ``centre`` along unit ``axis``."""
    rel = x - centre.reshape((3,) + (1,) * (x.ndim - 1))
    along = np.tensordot(axis, rel, axes=1)
    return np.linalg.norm(rel - axis.reshape((3,) + (1,) * (x.ndim - 1)) * along, axis=0)


def _no_bore_message(spec, source, tol, dist, centre, axis) -> str:
    nearest = dist.ravel()[np.argmin(np.abs(dist.ravel() - spec.radius))] if dist.size else float("nan")
    return (f"bore {spec.name!r}: no boundary face of {source} lies on a cylinder of radius "
            f"{spec.radius:.6g} m (+- {tol:.3g} m) around the axis through {centre.tolist()} m "
            f"along {axis.tolist()}; the boundary node nearest to that cylinder is {nearest:.6g} m "
            "from the axis (check the centre, radius and the mesh's scale)")


def surface_basis(mesh, facets: np.ndarray) -> tuple:
    """A scikit-fem basis on some boundary faces of *mesh*, made about their own middle.

    scikit-fem finds the quadrature points' element coordinates by Newton's
    method to an absolute tolerance of 1e-12, which round-off defeats for
    small curved elements a metre from the origin: the basis is made on the
    mesh moved so that the faces' middle is at the origin.

    Returns
    -------
    basis : skfem.FacetBasis
        On the moved mesh (the same nodes, elements and faces).
    origin : ndarray, shape (3,)
        Where the faces' middle is, m: add it to the basis's coordinates.
    """
    origin = mesh.doflocs[:, np.unique(mesh.facets[:, facets])].mean(axis=1)
    moved = mesh.translated(-origin)
    for name in _CONNECTIVITY:  # moving does not change them: found once, not again for every bore
        if name in vars(mesh):
            setattr(moved, name, getattr(mesh, name))
    return skfem.FacetBasis(moved, moved.elem(), facets=facets, intorder=_SURFACE_INTORDER), origin


def _bore_from_facets(mesh, name: str, facets: np.ndarray, nominal) -> Bore:
    """Integrate shape functions over the bore faces; fit or adopt centre, axis, radius."""
    fb, origin = surface_basis(mesh, facets)
    weights = skfem.asm(_unit_load, fb)
    nodes = np.unique(fb.get_dofs(facets=facets).flatten())
    x = np.asarray(fb.global_coordinates()) + origin[:, None, None]  # (3, faces, points)
    dx = fb.dx
    area = dx.sum()
    centroid = np.einsum("ifq,fq->i", x, dx) / area
    if nominal is None:
        normals = np.asarray(fb.normals)
        axis = np.linalg.eigh(np.einsum("ifq,jfq,fq->ij", normals, normals, dx))[1][:, 0]
        radius = float(np.einsum("fq,fq->", _distance_to_axis(x, centroid, axis), dx) / area)
        spread = np.abs(_distance_to_axis(mesh.doflocs[:, nodes], centroid, axis) - radius).max()
        if spread > 0.05 * radius:
            logger.warning("bore %r: its nodes deviate up to %.3g m from a cylinder of radius %.4g m; "
                           "is the node set a complete cylindrical bore?", name, spread, radius)
    else:
        point, axis, radius = nominal
        centroid = point + axis * np.dot(centroid - point, axis)
    return Bore(name=name, centre=centroid, axis=axis, radius=float(radius),
                nodes=nodes, weights=weights[nodes])


@skfem.LinearForm
def _unit_load(v, w):
    return v


# --- drawing ------------------------------------------------------------------


def _surface_triangles(mesh) -> np.ndarray:
    """Outward-oriented triangles over the boundary faces (see BodyMesh.surface_triangles)."""
    facets = mesh.boundary_facets()
    corner = mesh.facets[:, facets]
    if corner.shape[0] == 4:
        corner = _cyclic_quads(mesh.doflocs, corner)
        tris = np.concatenate([corner[[0, 1, 2]], corner[[0, 2, 3]]], axis=1)
        owners = np.tile(mesh.f2t[0, facets], 2)
    elif mesh.doflocs.shape[1] > mesh.nvertices:
        tris, owners = _split_quadratic_faces(mesh, facets)
    else:
        tris, owners = corner, mesh.f2t[0, facets]
    return _orient_outward(mesh, tris, owners).T.copy()


def _split_quadratic_faces(mesh, facets):
    """Split each 6-node boundary triangle into 4 triangles through its edge nodes."""
    a, b, c = mesh.facets[:, facets]
    edges = mesh.f2e[:, facets]
    ends = mesh.edges[:, edges]  # (2, 3 edges, faces)
    opposite = a + b + c - ends[0] - ends[1]  # the corner not on each edge
    faces = np.arange(facets.size)

    def edge_node_opposite(corner_node):
        return mesh.nvertices + edges[np.argmax(opposite == corner_node, axis=0), faces]

    m_bc, m_ca, m_ab = (edge_node_opposite(n) for n in (a, b, c))
    tris = np.concatenate([
        np.array([a, m_ab, m_ca]), np.array([m_ab, b, m_bc]),
        np.array([m_ca, m_bc, c]), np.array([m_ab, m_bc, m_ca]),
    ], axis=1)
    return tris, np.tile(mesh.f2t[0, facets], 4)


def _cyclic_quads(x: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """Order the 4 corners of each quadrilateral face cyclically."""
    p = x[:, quads]  # (3, 4, faces)
    centre = p.mean(axis=1, keepdims=True)
    e1 = p[:, 0:1] - centre
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], axis=0)[:, None]
    e2 = np.cross(normal, e1, axis=0)
    rel = p - centre
    angle = np.arctan2((rel * e2).sum(axis=0), (rel * e1).sum(axis=0))
    return np.take_along_axis(quads, np.argsort(angle, axis=0), axis=0)


def _orient_outward(mesh, tris: np.ndarray, owners: np.ndarray) -> np.ndarray:
    """Flip triangles whose normal points into their owning element."""
    x = mesh.doflocs[:, tris]  # (3, 3, k)
    normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], axis=0)
    inward = mesh.doflocs[:, mesh.t[:, owners]].mean(axis=1) - x.mean(axis=1)
    flip = (normal * inward).sum(axis=0) > 0
    tris = tris.copy()
    tris[1:, flip] = tris[2:0:-1, flip]
    return tris


__getattr__ = renamed_names(__name__, {"LinkMesh": "BodyMesh"})
