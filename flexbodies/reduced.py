"""The reduced link and its file (the package's "modal neutral file").

A :class:`ReducedLink` holds what Exudyn's ``ObjectFFRFreducedOrder`` needs
(node positions, mode basis, reduced matrices and the floating-frame inertia
invariants) plus what an engineer needs to trust it (frequencies, the mode
decision and its reason, the inputs and their hash, versions, timings).

The file is an uncompressed NumPy ``.npz`` archive (loading it costs no
decompression): one array per quantity and a JSON ``meta`` record holding
the schema name and version, the package version, the input hash (the
entry's key) and a SHA-256 checksum over every array. A file that fails any
of these checks raises :class:`ReducedLinkFileError`; it is never used.
Lengths are in m, masses in kg, frequencies in Hz, stiffness in N/m.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .atomic import replacing
from .errors import ReducedLinkFileError
from .selection import ModeDecision

__all__ = ["ReducedLink", "ReducedLinkFileError", "save_reduced_link", "load_reduced_link", "SCHEMA", "SCHEMA_VERSION"]

SCHEMA = "mountwb-reduced-link"
SCHEMA_VERSION = 3

#: Floating-frame invariants, named as Exudyn's ObjectFFRFreducedOrder names them.
FFRF_KEYS = (
    "massMatrixReduced", "stiffnessMatrixReduced", "xRef", "inertiaLocal", "Mtt",
    "totalMass", "chiU", "chiUtilde", "mPsiTildePsi", "mPsiTildePsiTilde",
    "mPhitTPsi", "mPhitTPsiTilde", "mXRefTildePsi", "mXRefTildePsiTilde",
)


def package_version() -> str:
    """Installed version of this package (``"unknown"`` when run from a source tree)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("engine-mount-workbook")
    except PackageNotFoundError:
        return "unknown"


@dataclass(frozen=True)
class ReducedLink:
    """A link reduced by Craig-Bampton, in its own link frame.

    The link frame has eye A's centre at the origin, eye B's centre on +x and
    the bore axes along z. Nodes are the FE nodes followed by one master node
    per interface (massless, moving with the bore as the coupling says).

    Attributes
    ----------
    nodes : ndarray, shape (n_nodes, 3)
        Node positions, m.
    master_nodes : ndarray of int, shape (n_interfaces,)
        Indices of the master nodes in ``nodes``.
    interface_names : tuple of str
    interface_nodes : tuple of ndarray
        FE node indices of each bore surface.
    surface_triangles : ndarray of int, shape (k, 3)
        Outer surface, for drawing.
    mode_basis : ndarray, shape (3 n_nodes, n_modes)
        Elastic modes (no rigid-body motion), node-major, m per modal unit.
    ffrf : dict of str to ndarray
        Floating-frame invariants (:data:`FFRF_KEYS`).
    frequencies : dict of str to ndarray
        ``free_free_hz`` and ``mounted_hz`` of the full FE model,
        ``fixed_interface_hz`` of the kept modes, ``reduced_hz`` of the
        reduced free body, all in Hz.
    decision : ModeDecision
    info : dict
        JSON-able: inputs, input hash, coupling, FE DOF, description,
        versions, timings in s.
    stress_modes : ndarray, shape (n_fe_nodes, 6, n_modes)
        Stress shape of each elastic mode at the FE nodes (nodal-averaged,
        link frame, Voigt order xx, yy, zz, yz, xz, xy), Pa per modal unit;
        empty, shape (0, 6, 0), for a body reduced without them
        (:mod:`flexbodies.stress`).
    residual_mass : ndarray, shape (6 + n_modes, 6 + n_modes)
        The omitted fixed-interface modes' residual mass R
        (:func:`flexbodies.reduction.residual_mass`), kg s^2: their
        dynamic stiffness is ``-w^4 R`` on the body frame's translation and
        rotation (body frame) and the modal coordinates; shape (0, 0) when
        not computed.
    cache_hit : bool
        True when this object was loaded from the cache.
    """

    nodes: np.ndarray
    master_nodes: np.ndarray
    interface_names: tuple
    interface_nodes: tuple
    surface_triangles: np.ndarray
    mode_basis: np.ndarray
    ffrf: dict
    frequencies: dict
    decision: ModeDecision
    info: dict
    stress_modes: np.ndarray = field(default_factory=lambda: np.zeros((0, 6, 0)), compare=False)
    residual_mass: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)), compare=False)
    cache_hit: bool = field(default=False, compare=False)

    @property
    def n_modes(self) -> int:
        """Number of elastic modal coordinates."""
        return self.mode_basis.shape[1]

    @property
    def n_fixed_interface(self) -> int:
        """Number of fixed-interface normal modes in the basis."""
        return len(self.frequencies["fixed_interface_hz"])

    @property
    def dof(self) -> int:
        """Degrees of freedom as a floating body: 6 rigid-body plus the modal ones."""
        return 6 + self.n_modes

    @property
    def mass(self) -> float:
        """Total mass, kg."""
        return float(self.ffrf["totalMass"])

    @property
    def centre_of_mass(self) -> np.ndarray:
        """Centre of mass in the link frame, m."""
        return np.asarray(self.ffrf["chiU"], dtype=float)

    @property
    def inertia_at_origin(self) -> np.ndarray:
        """Inertia tensor about the link-frame origin (eye A centre), kg m^2."""
        return np.asarray(self.ffrf["inertiaLocal"], dtype=float)

    @property
    def length(self) -> float:
        """Distance between the first two master nodes (eye centres), m."""
        a, b = self.nodes[self.master_nodes[:2]]
        return float(np.linalg.norm(b - a))

    @property
    def input_hash(self) -> str:
        return self.info["input_hash"]

    def master_position(self, interface: int) -> np.ndarray:
        """Position of an interface's master node in the link frame, m."""
        return self.nodes[self.master_nodes[interface]]


def _arrays_of(link: ReducedLink) -> dict:
    arrays = {
        "nodes": link.nodes,
        "master_nodes": link.master_nodes,
        "surface_triangles": link.surface_triangles,
        "mode_basis": link.mode_basis,
        "stress_modes": link.stress_modes,
        "residual_mass": link.residual_mass,
    }
    for i, nodes in enumerate(link.interface_nodes):
        arrays[f"interface_nodes_{i}"] = nodes
    for key in FFRF_KEYS:
        arrays[f"ffrf_{key}"] = np.asarray(link.ffrf[key])
    for key, value in link.frequencies.items():
        arrays[f"freq_{key}"] = np.asarray(value)
    return arrays


def _checksum(arrays: dict) -> str:
    digest = hashlib.sha256()
    for key in sorted(arrays):
        value = np.ascontiguousarray(arrays[key])
        digest.update(key.encode())
        digest.update(str(value.dtype).encode())
        digest.update(str(value.shape).encode())
        digest.update(value.tobytes())
    return digest.hexdigest()


def save_reduced_link(link: ReducedLink, path) -> Path:
    """Write a reduced link atomically (temporary file in the same folder, then rename).

    Parameters
    ----------
    link : ReducedLink
    path : str or Path
        Target ``.npz`` file.

    Returns
    -------
    Path
    """
    path = Path(path)
    arrays = _arrays_of(link)
    meta = {
        "schema": SCHEMA,
        "schema_version": SCHEMA_VERSION,
        "package_version": package_version(),
        "units": {"length": "m", "mass": "kg", "time": "s", "frequency": "Hz", "force": "N"},
        "interface_names": list(link.interface_names),
        "n_interfaces": len(link.interface_nodes),
        "frequency_keys": sorted(link.frequencies),
        "decision": link.decision.to_dict(),
        "info": link.info,
        "checksum": _checksum(arrays),
    }
    with replacing(path) as temporary, open(temporary, "wb") as handle:
        np.savez(handle, meta=np.array(json.dumps(meta)), **arrays)
    return path


def load_reduced_link(path, key: str | None = None) -> ReducedLink:
    """Read and verify a reduced-link file.

    Parameters
    ----------
    path : str or Path
    key : str, optional
        The input hash the file must carry (a cache entry's key).

    Raises
    ------
    ReducedLinkFileError
        The file is missing, not an archive, damaged, of another schema or
        version, of another key, or its checksum does not match its contents.
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {key: data[key] for key in data.files}
    except FileNotFoundError:
        raise ReducedLinkFileError(f"{path}: no such reduced-link file") from None
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise ReducedLinkFileError(f"{path}: not a readable reduced-link file ({exc})") from None
    try:
        meta = json.loads(str(arrays.pop("meta")))
    except (KeyError, json.JSONDecodeError) as exc:
        raise ReducedLinkFileError(f"{path}: no valid 'meta' record ({exc})") from None
    if meta.get("schema") != SCHEMA:
        raise ReducedLinkFileError(f"{path}: schema {meta.get('schema')!r}, expected {SCHEMA!r}")
    if meta.get("schema_version") != SCHEMA_VERSION:
        raise ReducedLinkFileError(
            f"{path}: schema version {meta.get('schema_version')}, this package reads version {SCHEMA_VERSION}"
        )
    stored_key = (meta.get("info") or {}).get("input_hash")
    if key is not None and stored_key != key:
        raise ReducedLinkFileError(f"{path}: holds the entry of key {stored_key}, not of {key}")
    if _checksum(arrays) != meta.get("checksum"):
        raise ReducedLinkFileError(f"{path}: checksum mismatch, the file was altered or damaged")
    try:
        return ReducedLink(
            nodes=arrays["nodes"],
            master_nodes=arrays["master_nodes"],
            interface_names=tuple(meta["interface_names"]),
            interface_nodes=tuple(arrays[f"interface_nodes_{i}"] for i in range(meta["n_interfaces"])),
            surface_triangles=arrays["surface_triangles"],
            mode_basis=arrays["mode_basis"],
            ffrf={key: arrays[f"ffrf_{key}"] for key in FFRF_KEYS},
            frequencies={key: arrays[f"freq_{key}"] for key in meta["frequency_keys"]},
            decision=ModeDecision(**meta["decision"]),
            info=meta["info"],
            stress_modes=arrays["stress_modes"],
            residual_mass=arrays.get("residual_mass", np.zeros((0, 0))),
        )
    except (KeyError, TypeError) as exc:
        raise ReducedLinkFileError(f"{path}: incomplete reduced-link file (missing {exc})") from None


def with_decision(link: ReducedLink, decision: ModeDecision, cache_hit: bool) -> ReducedLink:
    """The same reduced link, carrying the decision of the current request."""
    return dataclasses.replace(link, decision=decision, cache_hit=cache_hit)
