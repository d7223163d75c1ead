"""Geometric (initial-stress) stiffness of a link under an axial load.

A link that carries an axial force ``P`` between its eyes is stiffer in
bending when pulled and softer when pushed. The linear FE model and its
Craig-Bampton reduction do not know that: their stiffness is that of the
unloaded link. This module adds it.

1. The static stress field of a unit tension: eye A's master node held
   (six DOF), a force of 1 N on eye B's master node along the line from
   eye A to eye B. The Craig-Bampton statics are exact, so the condensed
   boundary stiffness and the static modes of the link's interior
   factorisation give the full displacement field; the stress at each
   integration point is ``sigma = lambda tr(eps) I + 2 mu eps``.
2. The initial-stress bilinear form ``int sigma_ij dN_a/dx_i dN_b/dx_j dV``
   assembled with scikit-fem on the scalar element; it acts alike on each
   displacement component, so the FE geometric stiffness is
   ``K_G = G (x) I3`` (node-major), the same in every rotated frame.
3. Projected on a link's elastic mode basis it gives the reduced geometric
   stiffness per newton of tension, ``K_G,r``; the stiffened modal
   stiffness under a tension ``P`` (N, negative in compression) is
   ``K_r + P K_G,r`` (the stress is linear in ``P``).
4. The same projection on a pinned-pinned Craig-Bampton model (both masters
   pinned, the spin about the link axis held, static modes plus the lowest
   fixed-interface modes) gives the link's first mounted frequency under
   ``P`` and its buckling load, the compression at which that frequency
   reaches zero.

The floating frame of the multibody body already carries the stiffness of
the loads turning with the rigid link; ``K_G,r`` adds the part of the
elastic coordinates, which the linear modal stiffness lacks.

The FE part (``G``, the pinned-pinned model and its buckling load) is kept
on disk next to the reduced links, keyed by the link model's hash
(:meth:`flexbodies.link.LinkModel.key`); projecting ``G`` on a reduced
link's modes costs a few sparse products, and ``K_G,r`` is kept beside it,
keyed by the mode basis as well, so that a run with its links cached loads
NumPy arrays only (no SciPy).
"""
from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
from collections import OrderedDict
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .atomic import replacing
from .cache import MEMORY_ENTRIES, BodyCache, default_cache_dir, file_signature
from .materials import Material
from .reduced import ReducedBody

if TYPE_CHECKING:  # SciPy, scikit-fem and gmsh: imported where a link's geometric stiffness is computed
    import scipy.sparse as sp

    from .interior import InteriorSolver
    from .meshing import BodyMesh

__all__ = ["LinkStiffening", "stress_field", "geometric_stiffness", "unit_tension_displacement", "unit_tension_stiffness",
           "mesh_stiffening", "coupled_stiffening", "link_stiffening", "has_stiffening", "save_stiffening", "stiffened",
           "PINNED_FIXED_MODES"]

#: Fixed-interface modes in the pinned-pinned model that gives the first
#: mounted frequency and the buckling load (the link's own reduction may keep
#: fewer): enough for the first two bending modes in both planes.
PINNED_FIXED_MODES = 12

#: Integration order of the initial-stress form per scikit-fem mesh type: exact
#: for straight-sided elements (stress of degree p - 1 times two shape-function
#: gradients of degree p - 1).
_INTORDER = {"MeshTet2": 3, "MeshTet1": 1, "MeshHex2": 4, "MeshHex1": 2}

_FORMAT = "mountwb-link-stiffening-1"


@dataclass(frozen=True)
class LinkStiffening:
    """A link's geometric stiffness per newton of axial tension.

    Attributes
    ----------
    csr : tuple of ndarray
        ``data``, ``indices`` and ``indptr`` of :attr:`scalar` (compressed rows).
    pinned_stiffness, pinned_mass, pinned_geometric : ndarray, shape (k, k)
        The pinned-pinned Craig-Bampton model (both masters pinned, spin
        held): stiffness (N/m), mass (kg) and geometric stiffness per N of
        tension.
    buckling_load : float
        Compression at which the first pinned-pinned mode reaches zero, N
        (``inf`` when no compression buckles the model).
    cache_file : Path or None
        The cache file it was read from or written to; the projections
        (:func:`stiffened`) are kept beside it.
    """

    csr: tuple[np.ndarray, np.ndarray, np.ndarray]
    pinned_stiffness: np.ndarray
    pinned_mass: np.ndarray
    pinned_geometric: np.ndarray
    buckling_load: float
    cache_file: Path | None = field(default=None, compare=False)

    @property
    def nodes(self) -> int:
        """FE nodes of the link (the order of :attr:`scalar`)."""
        return len(self.csr[2]) - 1

    @functools.cached_property
    def scalar(self) -> sp.csr_matrix:
        """``G`` of the unit tension's stress field on the scalar element (FE nodes), shape (n, n); the FE
        geometric stiffness is ``G (x) I3`` node-major, (N/m) per N of tension."""
        import scipy.sparse as sp

        return sp.csr_matrix(self.csr, shape=(self.nodes, self.nodes))

    def project(self, basis: np.ndarray) -> np.ndarray:
        """``V^T (G (x) I3) V`` of node-major displacement vectors (rows beyond the FE nodes ignored).

        Parameters
        ----------
        basis : ndarray, shape (>= 3 n, k)
            E.g. a reduced link's ``mode_basis`` (FE nodes first, any rotation).

        Returns
        -------
        ndarray, shape (k, k)
            (N/m) per N of tension.
        """
        n = self.nodes
        nodal = np.asarray(basis)[: 3 * n].reshape(n, 3, -1)
        product = np.einsum("ick,icl->kl", nodal, (self.scalar @ nodal.reshape(n, -1)).reshape(n, 3, -1))
        return 0.5 * (product + product.T)

    def pinned_hz(self, tension, count: int = 2) -> np.ndarray:
        """Lowest pinned-pinned frequencies under an axial tension, Hz.

        Parameters
        ----------
        tension : float or ndarray
            Axial force, N (negative: compression); an array gives the
            frequencies at each of its tensions.
        count : int

        Returns
        -------
        ndarray, shape (..., count)
            Frequencies, Hz; a mode past its buckling load has a negative
            squared frequency, returned as a negative number.
        """
        tension = np.asarray(tension, dtype=float)
        stiffness, geometric = self._whitened      # one symmetric pencil per tension, whitened by M = L L^T
        lam = np.linalg.eigvalsh(stiffness + tension[..., None, None] * geometric)[..., :count]
        return np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * np.pi)

    @functools.cached_property
    def _whitened(self) -> tuple[np.ndarray, np.ndarray]:
        """``L^-1 K L^-T`` and ``L^-1 G L^-T`` of the pinned-pinned model, ``M = L L^T``."""
        factor = np.linalg.cholesky(self.pinned_mass)
        stiffness, geometric = (np.linalg.solve(factor, np.linalg.solve(factor, m).T)
                                for m in (self.pinned_stiffness, self.pinned_geometric))
        return stiffness, geometric

    def first_mode_shift(self, tension: float) -> float:
        """Relative change of the first pinned-pinned frequency under *tension* (N); -1 at buckling."""
        loaded, unloaded = self.pinned_hz(tension, 1)[0], self.pinned_hz(0.0, 1)[0]
        return float(loaded / unloaded - 1.0)


def stress_field(link_mesh: BodyMesh, displacement: np.ndarray, material: Material) -> np.ndarray:
    """Cauchy stress of a small displacement field at the initial-stress form's integration points.

    Parameters
    ----------
    link_mesh : BodyMesh
    displacement : ndarray, shape (3 n,)
        Node-major nodal displacements, m.
    material : Material

    Returns
    -------
    ndarray, shape (3, 3, n_elements, n_points)
        Stress, Pa.
    """
    scalar = _scalar_basis(link_mesh)
    components = np.asarray(displacement, dtype=float).reshape(-1, 3).T
    grad = np.stack([scalar.interpolate(component).grad for component in components])  # d u_c / d x_i
    strain = 0.5 * (grad + np.swapaxes(grad, 0, 1))
    trace = strain[0, 0] + strain[1, 1] + strain[2, 2]
    return 2 * material.shear_modulus * strain + material.lame_lambda * trace * np.eye(3)[:, :, None, None]


def _scalar_basis(link_mesh: BodyMesh):
    """The scalar element of the mesh at the initial-stress form's integration order (DOF i is node i).

    scikit-fem is imported here, not with the module: a run that only loads
    a link's geometric stiffness from the cache never needs it.
    """
    import skfem

    mesh = link_mesh.mesh
    return skfem.Basis(mesh, mesh.elem(), intorder=_INTORDER[type(mesh).__name__])


def _initial_stress(u, v, w):
    return np.einsum("ij...,i...,j...->...", w["sigma"], u.grad, v.grad)


def geometric_stiffness(link_mesh: BodyMesh, stress: np.ndarray) -> sp.csr_matrix:
    """Initial-stress form of a stress field on the scalar element, ``int sigma_ij dN_a/dx_i dN_b/dx_j dV``.

    The FE geometric stiffness is this matrix ``G`` times the 3 x 3 identity
    (node-major ``G (x) I3``), the same in every rotated frame.

    Parameters
    ----------
    link_mesh : BodyMesh
    stress : ndarray, shape (3, 3, n_elements, n_points)
        From :func:`stress_field`, Pa.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n, n)
        N/m, symmetric; rows follow the finite element nodes.
    """
    import scipy.sparse as sp
    import skfem

    matrix = skfem.asm(skfem.BilinearForm(_initial_stress), _scalar_basis(link_mesh), sigma=stress)
    return sp.csr_matrix(0.5 * (matrix + matrix.T))


def unit_tension_displacement(solver: InteriorSolver) -> np.ndarray:
    """Coupled-coordinate displacement of a unit tension: eye A held, 1 N on eye B away from A.

    Parameters
    ----------
    solver : InteriorSolver
        The link's interior factorisation (two interfaces, A first).

    Returns
    -------
    ndarray, shape (n_q,)
        m per N.
    """
    coupling = solver.coupling
    axis = coupling.centres[1] - coupling.centres[0]
    force = np.zeros(6)
    force[:3] = axis / np.linalg.norm(axis)
    loaded = solver.condensed[6:12, 6:12]
    master_b = np.linalg.solve(loaded, force)
    return solver.static_modes()[:, 6:12] @ master_b


def _buckling_load(stiffness: np.ndarray, geometric: np.ndarray) -> float:
    """Smallest compression ``P`` with ``(K - P G) x = 0``, N (inf when none)."""
    import scipy.linalg as sla

    # G x = kappa K x: the largest positive kappa is 1 / P_cr
    kappa = sla.eigh(geometric, stiffness, eigvals_only=True)
    return float(1.0 / kappa.max()) if kappa.max() > 0 else float("inf")


def mesh_stiffening(link_mesh: BodyMesh, material: Material, interface: str = "RBE2",
                    fixed_modes: int = PINNED_FIXED_MODES) -> LinkStiffening:
    """The geometric stiffness of a meshed link per newton of tension.

    Parameters
    ----------
    link_mesh : BodyMesh
        Two bores, A first.
    material : Material
    interface : {"RBE2", "RBE3"}
    fixed_modes : int
        Fixed-interface modes of the pinned-pinned model.

    Returns
    -------
    LinkStiffening
    """
    from .assembly import assemble
    from .interior import InteriorSolver
    from .reduction import couple

    coupled = couple(assemble(link_mesh, material), interface)
    solver = InteriorSolver(coupled.stiffness, coupled.mass, coupled.coupling)
    return coupled_stiffening(link_mesh, coupled, solver, material, fixed_modes)


def unit_tension_stiffness(link_mesh: BodyMesh, coupled, solver: InteriorSolver, material: Material,
                           rotation=None) -> sp.csr_matrix:
    """``G`` of a link's unit tension (:func:`geometric_stiffness` of its stress field), from its coupled
    model and the factorisation of its interior.

    Parameters
    ----------
    link_mesh, coupled, solver, material, rotation
        As for :func:`coupled_stiffening`.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n, n)
        (N/m) per N of tension, on the mesh's nodes.
    """
    displacement = coupled.coupling.transform @ unit_tension_displacement(solver)
    if rotation is not None:
        displacement = (displacement.reshape(-1, 3) @ np.asarray(rotation, dtype=float)).ravel()
    return geometric_stiffness(link_mesh, stress_field(link_mesh, displacement, material))


def coupled_stiffening(link_mesh: BodyMesh, coupled, solver: InteriorSolver, material: Material,
                       fixed_modes: int = PINNED_FIXED_MODES, rotation=None, scalar=None) -> LinkStiffening:
    """The geometric stiffness of a link per newton of tension, from its coupled model and the
    factorisation of its interior (those of its reduction, when the FE model is in the mesh's frame).

    Parameters
    ----------
    link_mesh : BodyMesh
        The mesh *coupled* was assembled from.
    coupled : flexbodies.reduction.CoupledModel
    solver : InteriorSolver
        Of *coupled*.
    material : Material
    fixed_modes : int
        Fixed-interface modes of the pinned-pinned model.
    rotation : ndarray, shape (3, 3), optional
        *coupled*'s frame against the mesh's: a vector v of the mesh is
        ``rotation @ v`` in *coupled* (default: the same frame). The stress
        is taken in the mesh's frame; ``K_G = G (x) I3`` is the same in both.
    scalar : scipy.sparse.csr_matrix, optional
        ``G`` of these arguments, when made already (:func:`unit_tension_stiffness`).

    Returns
    -------
    LinkStiffening
    """
    from .frequencies import mounted_constraint_basis

    transform = coupled.coupling.transform
    if scalar is None:
        scalar = unit_tension_stiffness(link_mesh, coupled, solver, material, rotation)
    _, fixed = solver.fixed_interface_modes(fixed_modes)
    basis = np.hstack([solver.static_modes() @ mounted_constraint_basis(coupled.coupling), fixed])

    def project(matrix):
        product = basis.T @ (matrix @ basis)
        return 0.5 * (product + product.T)

    stiffening = LinkStiffening((scalar.data, scalar.indices, scalar.indptr), project(coupled.stiffness),
                                project(coupled.mass), np.zeros(0), 0.0)
    g_pinned = stiffening.project((transform @ basis))
    return dataclasses.replace(stiffening, pinned_geometric=g_pinned,
                               buckling_load=_buckling_load(stiffening.pinned_stiffness, g_pinned))


def _path(model, cache_dir) -> Path:
    key = hashlib.sha256(json.dumps([_FORMAT, model.key(), PINNED_FIXED_MODES]).encode()).hexdigest()[:24]
    return Path(cache_dir if cache_dir is not None else default_cache_dir()) / f"stiffening-{key}.npz"


#: Cache file -> (LinkStiffening, signature of the file when read), most recent last: the runs of one
#: process read each file once while it stays as it was.
_memory: OrderedDict = OrderedDict()


def _load(path: Path) -> LinkStiffening | None:
    signature = file_signature(path)
    remembered = _memory.get(path)
    if remembered is not None and signature is not None and remembered[1] == signature:
        _memory.move_to_end(path)
        return remembered[0]
    try:
        with np.load(path, allow_pickle=False) as data:
            csr = (data["data"], data["indices"], data["indptr"])
            stiffening = LinkStiffening(csr, data["pinned_stiffness"], data["pinned_mass"], data["pinned_geometric"],
                                        float(data["buckling_load"]), path)
            shape = tuple(data["shape"])
    except (OSError, ValueError, KeyError, EOFError):
        return None
    if shape != (stiffening.nodes,) * 2 or not len(csr[0]) == len(csr[1]) == csr[2][-1]:
        return None
    _memory[path] = (stiffening, signature)
    _memory.move_to_end(path)
    while len(_memory) > MEMORY_ENTRIES:
        _memory.popitem(last=False)
    return stiffening


def link_stiffening(model, *, cache_dir=None, use_cache: bool = True) -> LinkStiffening:
    """The geometric stiffness of a link model per newton of tension, cached on disk.

    Parameters
    ----------
    model : flexbodies.LinkModel
        Meshed and assembled as for its reduction (same mesh, same node
        order), so :meth:`LinkStiffening.project` applies to its reduced
        links' mode bases.
    cache_dir : str or Path, optional
        Default :func:`flexbodies.cache.default_cache_dir`.
    use_cache : bool
        False recomputes and does not write.

    Returns
    -------
    LinkStiffening
    """
    path = _path(model, cache_dir)
    if use_cache:
        stored = _load(path)
        if stored is not None:
            return stored
    stiffening = mesh_stiffening(model.meshed(), model.material, model.interface)
    if use_cache:
        stiffening = dataclasses.replace(stiffening, cache_file=save_stiffening(model, stiffening, cache_dir=cache_dir))
    return stiffening


def has_stiffening(model, *, cache_dir=None) -> bool:
    """True when the geometric stiffness of the link model *model* is in the cache."""
    return _path(model, cache_dir).is_file()


def save_stiffening(model, stiffening: LinkStiffening, *, cache_dir=None) -> Path | None:
    """Keep *stiffening*, the geometric stiffness of the link model *model*, in the cache.

    Returns
    -------
    Path or None
        The cache file, or None when the cache folder cannot be written (the
        store warns once and the run goes on without it).
    """
    path = _path(model, cache_dir)
    data, indices, indptr = stiffening.csr

    def write(temporary: Path) -> None:
        with open(temporary, "wb") as handle:
            np.savez(handle, data=data, indices=indices, indptr=indptr,
                     shape=np.array([stiffening.nodes] * 2), pinned_stiffness=stiffening.pinned_stiffness,
                     pinned_mass=stiffening.pinned_mass, pinned_geometric=stiffening.pinned_geometric,
                     buckling_load=np.float64(stiffening.buckling_load))

    return path if BodyCache(path.parent).write(path, write) else None


#: (id of a geometric stiffness, id of a mode basis) -> (the two, ``K_G,r``), most recent last: the links that
#: share a reduction (a mount's left and right links), the stiffening passes and the runs of one process
#: project it once. The entry holds both inputs, so their ids stay theirs while it is kept.
_projections: OrderedDict = OrderedDict()


def _projection(stiffening: LinkStiffening, basis: np.ndarray) -> np.ndarray:
    """``stiffening.project(basis)``, computed once per pair of objects (the result is not to be changed)."""
    key = (id(stiffening), id(basis))
    kept = _projections.get(key)
    if kept is None:
        kept = _projections[key] = (stiffening, basis, _kept_projection(stiffening, basis))
        while len(_projections) > MEMORY_ENTRIES:
            _projections.popitem(last=False)
    _projections.move_to_end(key)
    return kept[2]


def _projection_file(stiffening_file: Path, basis: np.ndarray) -> Path:
    """Where ``K_G,r`` of a cached geometric stiffness and a mode basis is kept: beside the
    stiffening's file, named by the basis's SHA-256 as well."""
    basis = np.ascontiguousarray(basis)
    digest = hashlib.sha256(f"{basis.dtype} {basis.shape}".encode())
    digest.update(basis.reshape(-1).view(np.uint8).data)
    return stiffening_file.with_name(f"{stiffening_file.stem}-{digest.hexdigest()[:24]}.npy")


def _kept_projection(stiffening: LinkStiffening, basis: np.ndarray) -> np.ndarray:
    """``stiffening.project(basis)``, read from its file beside the stiffening's cache file or
    computed (SciPy's sparse product) and kept there; a file that cannot be read is recomputed and
    replaced, one that cannot be written is left out."""
    if stiffening.cache_file is None:
        return stiffening.project(basis)
    path = _projection_file(stiffening.cache_file, basis)
    try:
        kept = np.load(path, allow_pickle=False)
        if kept.shape == (basis.shape[1],) * 2 and kept.dtype == float:
            return kept
    except (OSError, ValueError, EOFError):
        pass
    projected = stiffening.project(basis)
    try:
        with replacing(path) as temporary, open(temporary, "wb") as handle:
            np.save(handle, projected)
    except OSError:
        pass
    return projected


def stiffened(link: ReducedBody, stiffening: LinkStiffening, tension: float) -> ReducedBody:
    """The reduced link with its modal stiffness under an axial tension: ``K_r + P K_G,r``.

    Parameters
    ----------
    link : ReducedBody
    stiffening : LinkStiffening
        Of the link's model (:func:`link_stiffening`).
    tension : float
        Axial force, N (negative: compression).

    Returns
    -------
    ReducedBody
        A copy; ``info["axial_tension_N"]`` records the tension.
    """
    if int(link.master_nodes[0]) != stiffening.nodes:
        raise ValueError(f"the link's reduction has {int(link.master_nodes[0])} FE nodes but its geometric "
                         f"stiffness {stiffening.nodes}: they were meshed differently")
    ffrf = dict(link.ffrf)
    ffrf["stiffnessMatrixReduced"] = (np.asarray(link.ffrf["stiffnessMatrixReduced"])
                                      + tension * _projection(stiffening, link.mode_basis))
    return dataclasses.replace(link, ffrf=ffrf, info={**link.info, "axial_tension_N": float(tension)})
