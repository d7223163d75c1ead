"""The mesh pylon reduced by Craig-Bampton on its pins, clamped on its root plane, and cached.

A user's solid mesh of the pylon follows the chain of the links: the mesh
read with its pin bores resolved (:func:`flexbodies.meshing.load_mesh`), K
and M assembled with scikit-fem, every bore tied to a master node at its
centre (RBE2). Then the pylon's own steps:

- clamped: every degree of freedom of the nodes on the root plane is
  removed (a root node inside a bore is refused: the pin would be clamped);
- reduced by Craig-Bampton on the pins' master nodes (six DOF each): the
  static modes make the compliance exact at 0 Hz, and the fixed-interface
  modes are kept up to :data:`flexbodies.selection.MODE_MARGIN` times the
  highest frequency asked for (the links' rule), at least
  :data:`MINIMUM_MODES` of them;
- each pin moves with its bore's master node through the rigid offset from
  the bore's centre to the pin, ``x_pin = u + theta x r``.

The result, a :class:`~flexbodies.reduced.ClampedReduction`, is kept in the
store of every reduced body (:class:`flexbodies.cache.BodyCache`) under the
hash of every input (the mesh file's SHA-256, the pins, the root plane, the
material, the mode rule), made under that key's lock: a second run, or a
second process, loads it.
"""
from __future__ import annotations

import dataclasses
import hashlib
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from workbook.errors import CaseError

from .bores import BoreSpec
from .cache import BodyCache
from .cached_reduction import record_hash
from .materials import Material
from .reduced import CLAMPED_SCHEMA_VERSION, ClampedReduction, package_version
from .selection import MODE_MARGIN

# Meshing (meshio), assembly (scikit-fem) and the reduction load where a pylon is reduced: a run whose
# pylon is in the cache never needs them.

__all__ = ["PylonMeshModel", "reduce_pylon", "MINIMUM_MODES"]

#: Fewest fixed-interface modes kept. With the pins held, a pylon's fixed-interface modes lie far above
#: its own modes on the mount, so the links' rule alone may keep one or two: on a clamped bar whose first
#: bending mode on its pin is near 40 Hz, the compliance at 30 Hz with the one mode the rule kept differed
#: by 0.59 % from a reduction keeping 10, and with 5 modes by 0.009 % from one keeping modes to 8 kHz.
MINIMUM_MODES = 6


@dataclass(frozen=True)
class PylonMeshModel:
    """Everything a mesh pylon's reduction depends on (``workbook.model.pylon_mesh.MeshPylon.model`` makes it).

    Attributes
    ----------
    path : str
        Mesh file (meshio), coordinates in the case's axes times ``scale``.
    pins : tuple of 3-tuples of float
        Pin positions, m; each hangs in a bore of the mesh around it.
    root_point, root_normal : 3 floats
        A point of the root plane (m) and its normal.
    bore_axis : 3 floats
        Direction of the pin bores' axes.
    bore_radius : float
        Radius of the pin bores, m.
    material : Material
    scale : float
        Factor from the file's units to m.
    root_tolerance : float
        Distance from the root plane within which a node is clamped, m.
    name : str
        For messages only (not an input of the reduction).
    """

    path: str
    pins: tuple
    root_point: tuple
    root_normal: tuple
    bore_axis: tuple
    bore_radius: float
    material: Material
    scale: float = 1.0
    root_tolerance: float = 1e-6
    name: str = "mesh pylon"

    @property
    def item(self) -> str:
        """The pylon as a message names it."""
        return f"pylon mesh {self.name!r}"

    def bores(self) -> list[BoreSpec]:
        """The pin bores to find in the mesh, one per pin."""
        return [BoreSpec(f"pin {i + 1}", centre=tuple(position), axis=self.bore_axis, radius=self.bore_radius)
                for i, position in enumerate(self.pins)]

    def fingerprint(self) -> dict:
        """JSON-able description of every input; the mesh file enters by its SHA-256.

        Raises
        ------
        workbook.errors.CaseError
            The mesh file cannot be read.
        """
        path = Path(self.path)
        try:
            digest = hashlib.sha256(path.read_bytes()).hexdigest()
        except OSError as error:
            raise CaseError(self.item, "path", self.path,
                            f"a mesh file that exists ({error.strerror}: {path})") from None
        return {
            "schema_version": CLAMPED_SCHEMA_VERSION,
            "mesh_sha256": digest,
            "mesh_file": path.name,
            "scale": self.scale,
            "bores": [dataclasses.asdict(spec) for spec in self.bores()],
            "root": {"point": self.root_point, "normal": self.root_normal, "tolerance": self.root_tolerance},
            "material": self.material.elastic_inputs(),
            "interface": "RBE2",
        }


def reduce_pylon(model: PylonMeshModel, highest_hz: float, *, cache_dir=None, use_cache: bool = True) -> ClampedReduction:
    """The mesh pylon reduced on its pins for frequencies up to *highest_hz*, from the cache or made once.

    Parameters
    ----------
    model : PylonMeshModel
    highest_hz : float
        Highest frequency the pylon is asked at, Hz.
    cache_dir : str or Path, optional
        Default :func:`flexbodies.cache.default_cache_dir`.
    use_cache : bool
        False recomputes and does not read or write the cache.

    Returns
    -------
    ClampedReduction
        Its coordinates are the pins' master DOF then the kept modes;
        ``point_map`` gives the pins' displacements; ``cache_hit`` tells
        whether it was loaded.

    Raises
    ------
    workbook.errors.CaseError
        The mesh file missing or unreadable, a pin bore not found, a root
        plane through no node or through a bore.
    """
    cache = BodyCache(cache_dir, enabled=use_cache)
    inputs = {**model.fingerprint(), "modes": {"cutoff_hz": MODE_MARGIN * float(highest_hz), "minimum": MINIMUM_MODES}}
    key = record_hash(inputs)
    stored = cache.load_clamped(key)
    if stored is not None:
        return dataclasses.replace(stored, cache_hit=True)
    with cache.lock(key):
        stored = cache.load_clamped(key)  # another process may have made it while this one waited
        if stored is not None:
            return dataclasses.replace(stored, cache_hit=True)
        reduction = _reduce(model, MODE_MARGIN * float(highest_hz),
                            {"inputs": inputs, "input_hash": key, "package_version": package_version()})
        cache.save_clamped(key, reduction)
        return reduction


def _skew(r: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def _root_coordinates(model: PylonMeshModel, nodes: np.ndarray, coupling, bore_nodes: set) -> np.ndarray:
    """Coupled coordinates of the root plane's nodes (the clamped ones)."""
    import scipy.sparse as sp

    normal = np.asarray(model.root_normal) / np.linalg.norm(model.root_normal)
    on_root = np.flatnonzero(np.abs((nodes - np.asarray(model.root_point)) @ normal) <= model.root_tolerance)
    if on_root.size == 0:
        raise CaseError(model.item, "root_point", model.root_point,
                        f"a plane through nodes of the mesh {model.path} (none lies within "
                        f"{model.root_tolerance:g} m of it, normal {tuple(model.root_normal)})")
    if bore_nodes & set(on_root.tolist()):
        raise CaseError(model.item, "root_point", model.root_point,
                        "a root plane that does not cut a pin bore (the pin would be clamped)")
    rows = (3 * on_root[:, None] + np.arange(3)).ravel()
    transform = sp.csr_matrix(coupling.transform)[rows]
    return np.unique(transform.indices)


def _reduce(model: PylonMeshModel, cutoff_hz: float, info: dict) -> ClampedReduction:
    # scikit-fem, meshio and gmsh load here, where a pylon is meshed: runs without one never need them
    from .assembly import assemble
    from .craig_bampton import craig_bampton
    from .interfaces import couple_interfaces
    from .meshing import load_mesh

    start = time.perf_counter()
    try:
        mesh = load_mesh(model.path, model.bores(), scale=model.scale)
    except FileNotFoundError as error:
        raise CaseError(model.item, "path", model.path, f"a mesh file that exists ({error})") from None
    except ValueError as error:
        raise CaseError(model.item, "path", model.path,
                        f"a readable mesh with a bore of radius {model.bore_radius:g} m along "
                        f"{tuple(model.bore_axis)} at every pylon pin ({error})") from None
    fe = assemble(mesh, model.material)
    coupling = couple_interfaces(fe, "RBE2")
    stiffness, mass = coupling.reduce(fe.stiffness), coupling.reduce(fe.mass)
    bore_nodes = {int(n) for bore in fe.bores for n in bore.nodes}
    clamped = _root_coordinates(model, np.asarray(fe.nodes), coupling, bore_nodes)
    free = np.setdiff1d(np.arange(coupling.n_q), clamped)
    position = np.full(coupling.n_q, -1)
    position[free] = np.arange(len(free))
    stiffness, mass = stiffness[free][:, free], mass[free][:, free]
    masters = position[coupling.master_dofs]          # (pins, 6), in the free coordinates
    cb = craig_bampton(stiffness, mass, masters.ravel(), cutoff_hz=cutoff_hz)
    if len(cb.fixed_interface_hz) < MINIMUM_MODES:
        cb = craig_bampton(stiffness, mass, masters.ravel(), count=MINIMUM_MODES)
    pin_map = np.zeros((3 * len(model.pins), cb.vectors.shape[1]))
    for p, (pin, centre) in enumerate(zip(model.pins, coupling.centres, strict=True)):
        offset = np.asarray(pin, dtype=float) - centre
        # the master DOF are the first reduced coordinates, pin by pin (static modes)
        pin_map[3 * p:3 * p + 3, 6 * p:6 * p + 3] = np.eye(3)
        pin_map[3 * p:3 * p + 3, 6 * p + 3:6 * p + 6] = -_skew(offset)
    return ClampedReduction(cb.project(stiffness), cb.project(mass), pin_map, np.asarray(cb.fixed_interface_hz, dtype=float),
                            {**info, "fe_dof": int(fe.ndof), "seconds": time.perf_counter() - start})
