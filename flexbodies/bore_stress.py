"""Peak stress at a link's bores under a pin's bearing load, on meshes refined at the bores.

The reduced link ties each bore rigidly (RBE2) or by averaging (RBE3) to
its master node: right for the link's stiffness and mass, not for the stress
at the bore. A rigid tie meets the eye's faces in an edge where the stress
is singular, so its peak grows without bound as the mesh is refined. A pin
instead presses on the half of the bore it bears on. This module answers
the bore peak of that load, on a static FE model of the link alone (a
*sub-model*):

- the link is meshed again with :func:`flexbodies.meshing.mesh_link`,
  elements of ``bore_element_size`` at the bores growing to the link's
  element size one bore radius away;
- a unit axial force (tension, then compression) enters each eye through a
  cosine bearing pressure on the half of its bore the pin bears on,
  ``p(theta) = p0 cos(theta)``, the resultant along the link axis
  (:func:`bearing_load`); the two eyes' loads balance, and the body is held
  statically determinate (3-2-1 at the shank's middle, reactions zero);
- the peak von Mises stress over each eye's nodes (within the eye's outer
  radius of its centre) per newton is kept in the link cache,
  ``bores-<key>.json``, under the link model's key and the bore size.

A two-force link (ball hinges at both eyes) carries its axial force only, so
a load case's bore peak is ``|N|`` times the peak per newton of the
direction of ``N``; the link's own weight and inertia are left out (a few
per mille of the reference links' forces). Two bore sizes,
:func:`convergence_sizes`, give the peak and its change between them.
"""
from __future__ import annotations

import hashlib
import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from .atomic import replacing
from .cache import default_cache_dir
from .errors import LinkModelError

__all__ = ["BorePeaks", "BORE_DIVISIONS", "convergence_sizes", "bearing_load", "bore_peaks"]

#: Elements around a bore's circumference of the two refined meshes of a stress request.
BORE_DIVISIONS = (36, 54)
#: The format of a ``bores-<key>.json`` cache file.
_FORMAT = 1


@dataclass(frozen=True)
class BorePeaks:
    """Peak von Mises stress at a link's bores per newton of axial force, on one mesh.

    Attributes
    ----------
    bore_element_size : float
        Element edge at the bores, m.
    tension, compression : tuple of 2 floats
        Peak von Mises stress in eye A and eye B per newton of tension and of
        compression, Pa/N.
    nodes : int
        FE nodes of the mesh.
    seconds : float
        Meshing, assembly and the solves when computed, s.
    """

    bore_element_size: float
    tension: tuple
    compression: tuple
    nodes: int
    seconds: float

    def peak(self, axial_force: float) -> float:
        """The larger eye's peak von Mises stress under an axial force (N, tension positive), Pa."""
        per_newton = self.tension if axial_force >= 0 else self.compression
        return abs(float(axial_force)) * max(per_newton)


def convergence_sizes(model) -> tuple[float, float]:
    """The bore element sizes (m) of a link model's two refined meshes: :data:`BORE_DIVISIONS` per bore
    circumference, at most the link's element size."""
    if model.geometry is None:
        raise LinkModelError("the bore peak needs a parametric link geometry to mesh again; "
                             "a link from a mesh file is not refined")
    from .geometry import default_element_size

    size = model.element_size if model.element_size is not None else default_element_size(model.geometry)
    coarse, fine = (min(2 * np.pi * model.geometry.bore_radius / n, size) for n in BORE_DIVISIONS)
    return coarse, fine


def bearing_load(link_mesh, bore, direction, force: float) -> np.ndarray:
    """Nodal forces of a pin bearing on a bore: a cosine pressure on the half facing *direction*.

    Parameters
    ----------
    link_mesh : flexbodies.meshing.BodyMesh
    bore : flexbodies.bores.Bore
        One of ``link_mesh.bores``.
    direction : array_like, shape (3,)
        The pin's push, across the bore axis (normalised here).
    force : float
        The resultant along *direction*, N.

    Returns
    -------
    ndarray, shape (3 n,)
        Node-major forces, N: the traction ``p0 cos(theta) e_r`` (``e_r`` the
        radial unit vector from the bore axis, ``theta`` its angle from
        *direction*, zero where ``cos(theta) < 0``), scaled so that the nodal
        forces sum to ``force * direction``.
    """
    import skfem

    from .meshing import surface_basis

    mesh = link_mesh.mesh
    axis = np.asarray(bore.axis, float) / np.linalg.norm(bore.axis)
    push = np.asarray(direction, float)
    push = push - axis * (push @ axis)
    push /= np.linalg.norm(push)
    on_bore = np.zeros(mesh.doflocs.shape[1], dtype=bool)
    on_bore[bore.nodes] = True
    facets = mesh.boundary_facets()
    facets = facets[on_bore[mesh.facets[:, facets]].all(axis=0)]
    basis, origin = surface_basis(mesh, facets)
    centre = np.asarray(bore.centre, float) - origin

    def radial(x):
        rel = np.stack([x[i] - centre[i] for i in range(3)])
        rel -= np.einsum("i,i...->...", axis, rel)[None] * axis.reshape(3, *([1] * (rel.ndim - 1)))
        return rel / np.linalg.norm(rel, axis=0)

    def component(c):
        @skfem.LinearForm
        def traction(v, w):
            e_r = radial(w.x)
            return v * np.maximum(np.einsum("i,i...->...", push, e_r), 0.0) * e_r[c]
        return skfem.asm(traction, basis)

    loads = np.stack([component(c) for c in range(3)], axis=1)
    resultant = loads.sum(axis=0) @ push
    return (force / resultant * loads).ravel()


def _held(nodes: np.ndarray, length: float) -> np.ndarray:
    """Six DOF holding a link statically determinate (3-2-1) about the shank's middle."""
    def nearest(point):
        return int(np.argmin(np.linalg.norm(nodes - np.asarray(point), axis=1)))

    a, b, c = nearest((0.5 * length, 0, 0)), nearest((0.6 * length, 0, 0)), nearest((0.5 * length, 1.0, 0))
    return np.array([3 * a, 3 * a + 1, 3 * a + 2, 3 * b + 1, 3 * b + 2, 3 * c + 2])


def _solve_peaks(model, bore_element_size: float) -> BorePeaks:
    """Mesh, assemble and solve the sub-model of a link for unit tension and compression."""
    from .assembly import assemble
    from .eigen import factorize, free_dofs
    from .meshing import mesh_link
    from .stress import nodal_stress_operator, von_mises

    start = time.perf_counter()
    g = model.geometry
    link_mesh = mesh_link(g, model.element_size, bore_element_size)
    fe = assemble(link_mesh, model.material)
    nodes = fe.nodes
    free = free_dofs(fe.ndof, _held(nodes, g.length))
    factor = factorize(fe.stiffness[free][:, free].tocsc())
    bore_a, bore_b = link_mesh.bores
    loads = np.stack([bearing_load(link_mesh, bore_a, (-sign, 0, 0), 1.0)
                      + bearing_load(link_mesh, bore_b, (sign, 0, 0), 1.0) for sign in (1.0, -1.0)], axis=1)
    u = np.zeros_like(loads)
    u[free] = factor.solve(loads[free])
    residual = fe.stiffness @ u - loads
    if np.abs(residual).max() > 1e-3:  # N per N: the reactions, from the discrete pressure's side resultant
        raise LinkModelError(f"the bore sub-model of {link_mesh.source} is not in equilibrium "
                             f"(largest nodal residual {np.abs(residual).max():.3g} N per N of load)")
    vm = von_mises(nodal_stress_operator(link_mesh, model.material).of(u))     # (n, 2)
    peaks = []
    for bore in (bore_a, bore_b):
        inside = np.linalg.norm((nodes - bore.centre)[:, :2], axis=1) <= g.eye_outer_radius * (1 + 1e-9)
        peaks.append(vm[inside].max(axis=0))
    tension, compression = (tuple(float(p[k]) for p in peaks) for k in (0, 1))
    return BorePeaks(float(bore_element_size), tension, compression, len(nodes), time.perf_counter() - start)


def _path(model, bore_element_size: float, cache_dir) -> Path:
    record = json.dumps([_FORMAT, model.key(), float(f"{bore_element_size:.12g}")])
    key = hashlib.sha256(record.encode()).hexdigest()[:24]
    return Path(cache_dir if cache_dir is not None else default_cache_dir()) / f"bores-{key}.json"


def bore_peaks(model, bore_element_size: float, *, cache_dir=None, use_cache: bool = True) -> BorePeaks:
    """The peak von Mises stress at a link's bores per newton of axial force, cached (see the module).

    Parameters
    ----------
    model : flexbodies.LinkModel
        With a parametric geometry.
    bore_element_size : float
        Element edge at the bores, m.
    cache_dir : str or Path, optional
        Default :func:`flexbodies.cache.default_cache_dir`.
    use_cache : bool
        False recomputes and does not write.

    Returns
    -------
    BorePeaks
        ``seconds`` is the time of the computation, also when loaded.
    """
    if model.geometry is None:
        raise LinkModelError("the bore peak needs a parametric link geometry to mesh again; "
                             "a link from a mesh file is not refined")
    path = _path(model, bore_element_size, cache_dir)
    if use_cache:
        try:
            stored = json.loads(path.read_text())
            return BorePeaks(stored["bore_element_size"], tuple(stored["tension"]), tuple(stored["compression"]),
                             int(stored["nodes"]), float(stored["seconds"]))
        except (OSError, ValueError, KeyError, TypeError):
            pass
    peaks = _solve_peaks(model, bore_element_size)
    if use_cache:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            with replacing(path) as temporary:
                temporary.write_text(json.dumps(asdict(peaks)))
        except OSError:
            pass  # the cache's own trouble is reported by the reductions that share its folder
    return peaks
