"""A link as the mount sees it: what it is made of, and its reduction, cached.

:class:`LinkModel` names everything a reduction depends on: a parametric
geometry (or a user's mesh file with its bores), the material, the mesh
size and the interface coupling. :func:`reduce_link` turns it into a
:class:`~flexbodies.reduced.ReducedLink` for a mode request, and keeps the
result on disk under the hash of its inputs:

- ``fe-<hash>.json``: the reference frequencies of the FE model (the mounted
  fundamental decides what ``"auto"`` keeps), so a new excitation
  frequency does not need a new FE solve;
- ``link-<hash>.npz``: the reduced link, keyed by the inputs and the resolved
  mode decision.

A changed geometry, mesh file, material, mesh size, coupling or mode
selection changes the hash and recomputes. A cache file that fails its
checks is reported, recomputed and replaced, never used.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .assembly import FEModel, assemble
from .atomic import replacing
from .geometry import LinkGeometry
from .materials import STEEL, Material
from .meshing import default_element_size, load_mesh, mesh_link
from .reduced import SCHEMA_VERSION, ReducedLink, ReducedLinkFileError, load_reduced_link, package_version, save_reduced_link, with_decision
from .reduction import couple, reduce_coupled, reference_frequencies
from .selection import decide_modes

__all__ = ["MeshSource", "LinkModel", "reduce_link", "build_fe_model", "default_cache_dir"]

log = logging.getLogger(__name__)


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
            raise ValueError(f"mesh {self.path}: a link needs exactly two bores (A and B), got {len(self.bores)}")


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
            raise ValueError("a link model needs exactly one of geometry and mesh")

    def fingerprint(self) -> dict:
        """JSON-able description of every input; a mesh file enters by its SHA-256."""
        if self.geometry is not None:
            size = self.element_size if self.element_size is not None else default_element_size(self.geometry)
            shape = {"geometry": dataclasses.asdict(self.geometry), "element_size": size}
        else:
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
            "material": dataclasses.asdict(self.material),
            "interface": self.interface.upper(),
        }


def _hash(record: dict) -> str:
    text = json.dumps(record, sort_keys=True, default=lambda v: np.asarray(v).tolist())
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def default_cache_dir() -> Path:
    """Cache folder: ``$MOUNTWB_CACHE``, else ``~/.cache/mountwb``."""
    return Path(os.environ.get("MOUNTWB_CACHE") or Path.home() / ".cache" / "mountwb")


def _in_link_frame(fe: FEModel) -> FEModel:
    """The FE model rotated and shifted so that eye A is at the origin, eye B on +x, bore A's axis on z."""
    a, b = fe.bores[0].centre, fe.bores[1].centre
    ex = (b - a) / np.linalg.norm(b - a)
    ez = fe.bores[0].axis - ex * (fe.bores[0].axis @ ex)
    if np.linalg.norm(ez) < 1e-6:
        raise ValueError("the bore axis of eye A runs along the link axis; a link's bores must be across it")
    ez /= np.linalg.norm(ez)
    R = np.vstack([ex, np.cross(ez, ex), ez])  # rows: link axes in model coordinates
    if np.allclose(R, np.eye(3), atol=1e-12) and np.allclose(a, 0.0, atol=1e-12):
        return fe
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
    )


def build_fe_model(model: LinkModel) -> tuple[FEModel, dict]:
    """Mesh and assemble a link model in its link frame.

    Returns
    -------
    fe_model : FEModel
    timings : dict
        ``mesh_seconds`` and ``assembly_seconds``.
    """
    start = time.perf_counter()
    if model.geometry is not None:
        link_mesh = mesh_link(model.geometry, model.element_size)
    else:
        link_mesh = load_mesh(model.mesh.path, model.mesh.bores, scale=model.mesh.scale)
    meshed = time.perf_counter()
    fe = _in_link_frame(assemble(link_mesh, model.material))
    return fe, {"mesh_seconds": meshed - start, "assembly_seconds": time.perf_counter() - meshed}


def _read_summary(path: Path) -> dict | None:
    try:
        summary = json.loads(path.read_text())
        return {key: np.asarray(summary[key], dtype=float) for key in ("free_free_hz", "mounted_hz")}
    except FileNotFoundError:
        return None
    except (OSError, ValueError, KeyError, TypeError) as exc:
        log.warning("%s: unreadable frequency summary (%s); recomputing", path, exc)
        return None


def _write_summary(path: Path, frequencies: dict) -> None:
    with replacing(path) as temporary:
        temporary.write_text(json.dumps({key: np.asarray(v).tolist() for key, v in frequencies.items()}))


def reduce_link(model: LinkModel, modes="auto", excitation_hz: float | None = None, *, cache_dir=None, use_cache: bool = True) -> ReducedLink:
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
    ReducedLink
        ``cache_hit`` tells whether it was loaded; ``info`` holds the inputs,
        their hash and the time of each stage in s.
    """
    cache = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    fingerprint = model.fingerprint()
    fe_hash = _hash(fingerprint)
    summary_path = cache / f"fe-{fe_hash}.json"
    frequencies = _read_summary(summary_path) if use_cache else None
    fe_state = None
    if frequencies is None:
        fe, timings = build_fe_model(model)
        coupled = couple(fe, model.interface)
        start = time.perf_counter()
        frequencies = reference_frequencies(coupled)
        timings["frequency_seconds"] = time.perf_counter() - start
        fe_state = (coupled, timings)
        if use_cache:
            _write_summary(summary_path, frequencies)

    decision = decide_modes(modes, frequencies["mounted_hz"][0], excitation_hz)
    link_hash = _hash({"fe": fe_hash, "modes": decision.key})
    link_path = cache / f"link-{link_hash}.npz"
    if use_cache and link_path.exists():
        try:
            return with_decision(load_reduced_link(link_path), decision, cache_hit=True)
        except ReducedLinkFileError as exc:
            log.warning("%s; recomputing it", exc)

    if fe_state is None:
        fe, timings = build_fe_model(model)
        fe_state = (couple(fe, model.interface), timings)
    coupled, timings = fe_state
    info = {
        "inputs": fingerprint,
        "input_hash": link_hash,
        "package_version": package_version(),
        **timings,
    }
    link = reduce_coupled(coupled, decision, frequencies, info)
    if use_cache:
        save_reduced_link(link, link_path)
    return link
