"""A link as the mount sees it: what it is made of, and its reduction, cached.

:class:`LinkModel` names everything a reduction depends on: a parametric
geometry (or a user's mesh file with its bores), the material, the mesh
size and the interface coupling. :func:`reduce_link` turns it into a
:class:`~flexbodies.reduced.ReducedBody` for a mode request, and keeps the
result on disk under the hash of its inputs:

- ``fe-<hash>.json``: the reference frequencies of the FE model (the mounted
  fundamental decides what ``"auto"`` keeps), so a new excitation
  frequency does not need a new FE solve;
- ``link-<hash>.npz``: the reduced link, keyed by the inputs and the resolved
  mode decision.

A changed geometry, mesh file, material, mesh size, coupling or mode
selection changes the hash and recomputes. The store itself (verified
entries, the lock per link, cache trouble) is :mod:`flexbodies.cache`.
"""
from __future__ import annotations

import dataclasses
import hashlib
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .cache import BodyCache, default_cache_dir
from .cached_reduction import cached_reductions, record_hash, stored_reductions
from .errors import LinkModelError
from .geometry import LinkGeometry, default_element_size
from .materials import STEEL, Material
from .reduced import SCHEMA_VERSION, ReducedBody
from .selection import decide_modes

# The modules that mesh (gmsh, meshio), assemble (scikit-fem) and reduce a link are imported where a
# link is reduced: a run whose links are all in the cache never loads them.

__all__ = ["MeshSource", "LinkModel", "reduce_link", "reduce_link_set", "is_reduced", "build_fe_model", "default_cache_dir"]

@dataclass(frozen=True)
class MeshSource:
    """A user's own link mesh.

    Attributes
    ----------
    path : str
        Mesh file readable by meshio (.msh, .inp, .vtu, ...).
    bores : tuple of BoreSpec
        Eye A's bore first, then eye B's.
    scale : float
        Factor from file units to m (1e-3 for a file in mm).
    """

    path: str
    bores: tuple
    scale: float = 1.0

    def __post_init__(self):
        object.__setattr__(self, "bores", tuple(self.bores))
        if len(self.bores) != 2:
            raise LinkModelError(f"mesh {self.path}: a link needs exactly two bores (A and B), got {len(self.bores)}")


@dataclass(frozen=True)
class LinkModel:
    """Everything a link's reduction depends on.

    Attributes
    ----------
    geometry : LinkGeometry, optional
        Parametric link (exactly one of ``geometry`` and ``mesh``).
    mesh : MeshSource, optional
        A user's mesh file.
    material : Material
    element_size : float, optional
        Mesh size for a parametric link, m (default: see ``mesh_link``).
    interface : {"RBE2", "RBE3"}
        How each bore is tied to its master node.
    """

    geometry: LinkGeometry | None = None
    mesh: MeshSource | None = None
    material: Material = STEEL
    element_size: float | None = None
    interface: str = "RBE2"

    def __post_init__(self):
        if (self.geometry is None) == (self.mesh is None):
            raise LinkModelError("a link model needs exactly one of geometry and mesh")

    def fingerprint(self) -> dict:
        """JSON-able description of every input; a mesh file enters by its SHA-256."""
        if self.geometry is not None:
            size = self.element_size if self.element_size is not None else default_element_size(self.geometry)
            shape = {"geometry": dataclasses.asdict(self.geometry), "element_size": size}
        else:
            assert self.mesh is not None
            path = Path(self.mesh.path)
            try:
                digest = hashlib.sha256(path.read_bytes()).hexdigest()
            except OSError as exc:
                raise FileNotFoundError(f"mesh file {path}: cannot be read ({exc.strerror})") from None
            shape = {
                "mesh_sha256": digest,
                "mesh_file": path.name,
                "bores": [dataclasses.asdict(b) for b in self.mesh.bores],
                "scale": self.mesh.scale,
            }
        return {
            "schema_version": SCHEMA_VERSION,
            **shape,
            "material": self.material.elastic_inputs(),
            "interface": self.interface.upper(),
        }

    def key(self) -> str:
        """Hash of :meth:`fingerprint`: the key of the link's cache entries and of its lock."""
        return record_hash(self.fingerprint())

    def meshed(self):
        """The link's mesh (a :class:`flexbodies.meshing.BodyMesh`): the parametric geometry meshed,
        or the mesh file read."""
        from .meshing import load_mesh, mesh_link

        if self.geometry is not None:
            return mesh_link(self.geometry, self.element_size)
        assert self.mesh is not None
        return load_mesh(self.mesh.path, self.mesh.bores, scale=self.mesh.scale)


def _in_link_frame(fe):
    """The FE model (a :class:`flexbodies.assembly.FEModel`) rotated and shifted so that eye A is at the
    origin, eye B on +x, bore A's axis on z, and the rotation R (rows: the link axes in the model's
    coordinates; a link-frame vector is R v)."""
    a, b = fe.bores[0].centre, fe.bores[1].centre
    ex = (b - a) / np.linalg.norm(b - a)
    ez = fe.bores[0].axis - ex * (fe.bores[0].axis @ ex)
    if np.linalg.norm(ez) < 1e-6:
        raise LinkModelError("the bore axis of eye A runs along the link axis; a link's bores must be across it")
    ez /= np.linalg.norm(ez)
    R = np.vstack([ex, np.cross(ez, ex), ez])  # rows: link axes in model coordinates
    if np.allclose(R, np.eye(3), atol=1e-12) and np.allclose(a, 0.0, atol=1e-12):
        return fe, np.eye(3)
    import scipy.sparse as sp

    block = sp.kron(sp.identity(len(fe.nodes)), sp.csr_matrix(R), format="csr")
    bores = tuple(
        dataclasses.replace(bore, centre=R @ (bore.centre - a), axis=R @ bore.axis) for bore in fe.bores
    )
    return dataclasses.replace(
        fe,
        nodes=(fe.nodes - a) @ R.T,
        stiffness=(block @ fe.stiffness @ block.T).tocsr(),
        mass=(block @ fe.mass @ block.T).tocsr(),
        bores=bores,
    ), R


def build_fe_model(model: LinkModel) -> tuple:
    """Mesh and assemble a link model in its link frame.

    Returns
    -------
    fe_model : flexbodies.assembly.FEModel
    timings : dict
        ``mesh_seconds`` and ``assembly_seconds``.
    """
    fe, _, _, timings = _meshed_fe_model(model)
    return fe, timings


def _meshed_fe_model(model: LinkModel) -> tuple:
    """:func:`build_fe_model` with the link's mesh and the rotation from the mesh's frame to the link
    frame (see :func:`_in_link_frame`)."""
    from .assembly import assemble

    start = time.perf_counter()
    link_mesh = model.meshed()
    meshed = time.perf_counter()
    fe, rotation = _in_link_frame(assemble(link_mesh, model.material))
    return fe, link_mesh, rotation, {"mesh_seconds": meshed - start, "assembly_seconds": time.perf_counter() - meshed}


def reduce_link(model: LinkModel, modes="auto", excitation_hz: float | None = None, *, cache_dir=None,
                use_cache: bool = True) -> ReducedBody:
    """Reduce a link for a mode request, reusing the cache where the inputs match.

    Parameters
    ----------
    model : LinkModel
    modes : {"auto", "static"} or int or float
        See :func:`flexbodies.selection.decide_modes`.
    excitation_hz : float, optional
        Highest excitation frequency the link must follow, Hz (needed by ``"auto"``).
    cache_dir : str or Path, optional
        Default :func:`default_cache_dir`.
    use_cache : bool
        False recomputes and does not write.

    Returns
    -------
    ReducedBody
        ``cache_hit`` tells whether it was loaded; ``info`` holds the inputs,
        their hash and the time of each stage in s.
    """
    (link,) = reduce_link_set(model, modes, [excitation_hz], cache_dir=cache_dir, use_cache=use_cache)
    return link


def _decider(modes):
    """The mode decision of a link for one excitation, judged on its first mounted frequency."""
    return lambda frequencies, excitation_hz: decide_modes(modes, frequencies["mounted_hz"][0], excitation_hz)


def is_reduced(model: LinkModel, modes="auto", excitations_hz=(None,), *, cache_dir=None,
               stiffening: bool = False) -> bool:
    """True when the cache holds all that :func:`reduce_link_set` would return for these arguments
    (and the link's geometric stiffness when *stiffening*), so that the call only loads.

    Parameters
    ----------
    model, modes, excitations_hz, cache_dir, stiffening
        As for :func:`reduce_link_set`.

    Returns
    -------
    bool
    """
    cache = BodyCache(cache_dir)
    _, _, _, links = stored_reductions(cache, record_hash(model.fingerprint()), _decider(modes), list(excitations_hz))
    if links is None or any(link is None for link in links):
        return False
    if not stiffening:
        return True
    from .geometric_stiffness import has_stiffening  # SciPy's solvers: not for a workbook check

    return has_stiffening(model, cache_dir=cache_dir)


def _timed_stress_operator(link_mesh, material, rotation, timings: dict):
    """The link's nodal stress operator; its time in ``timings["stress_operator_seconds"]``, s."""
    from .stress import nodal_stress_operator

    start = time.perf_counter()
    stress = nodal_stress_operator(link_mesh, material, rotation)
    timings["stress_operator_seconds"] = time.perf_counter() - start
    return stress


def reduce_link_set(model: LinkModel, modes="auto", excitations_hz=(None,), *, cache_dir=None,
                    use_cache: bool = True, stiffening: bool = False) -> tuple:
    """Reduce a link for several excitations at once: one FE model, every decision served from it.

    Parameters
    ----------
    model : LinkModel
    modes : {"auto", "static"} or int or float
        See :func:`flexbodies.selection.decide_modes`.
    excitations_hz : sequence of float or None
        The highest excitation frequency of each run that needs the link, Hz.
    cache_dir : str or Path, optional
        Default :func:`default_cache_dir`.
    use_cache : bool
        False recomputes and does not read or write the cache.
    stiffening : bool
        Also keep the link's geometric stiffness in the cache
        (:func:`flexbodies.geometric_stiffness.link_stiffening` then loads
        it), computed from this reduction's FE model and factorisation when
        the link is reduced now and the cache has none yet.

    Returns
    -------
    tuple of ReducedBody
        One per excitation, in order, each carrying its own decision.
    """
    def prepare(frequencies):
        from .geometric_stiffness import PINNED_FIXED_MODES, coupled_stiffening, has_stiffening, save_stiffening, unit_tension_stiffness
        from .interior import InteriorSolver
        from .reduction import couple

        fe, link_mesh, rotation, timings = _meshed_fe_model(model)
        stiffen = (stiffening and use_cache and BodyCache(cache_dir).writable()
                   and not has_stiffening(model, cache_dir=cache_dir))
        with ThreadPoolExecutor(max_workers=1) as beside:  # SuperLU and NumPy release the GIL
            stress = beside.submit(_timed_stress_operator, link_mesh, model.material, rotation, timings)
            coupled = couple(fe, model.interface)
            start = time.perf_counter()
            solver = InteriorSolver(coupled.stiffness, coupled.mass, coupled.coupling)
            timings["reduction_seconds"] = time.perf_counter() - start  # the factorisation; the reduction adds its own
            # the unit tension's geometric stiffness beside the eigen-solves (it needs only the static modes)
            tension = (beside.submit(unit_tension_stiffness, link_mesh, coupled, solver, model.material, rotation)
                       if stiffen else None)
            if frequencies is None:
                start = time.perf_counter()
                # the stiffening's fixed-interface modes beside them, the solves of the three made together
                frequencies = solver.reference_frequencies(PINNED_FIXED_MODES if stiffen else 0)
                timings["frequency_seconds"] = time.perf_counter() - start
            coupled = dataclasses.replace(coupled, stress=stress.result())
            if tension is not None:
                start = time.perf_counter()
                save_stiffening(model, coupled_stiffening(link_mesh, coupled, solver, model.material, rotation=rotation,
                                                          scalar=tension.result()), cache_dir=cache_dir)
                timings["stiffening_seconds"] = time.perf_counter() - start
        return coupled, solver, frequencies, timings

    return cached_reductions(model.fingerprint(), _decider(modes), excitations_hz, prepare, cache_dir=cache_dir,
                             use_cache=use_cache)
