"""The reduced body (a link, the engine casing) and its file (the package's "modal neutral file").

A :class:`ReducedBody` holds what Exudyn's ``ObjectFFRFreducedOrder`` needs
(node positions, mode basis, reduced matrices and the floating-frame inertia
invariants) plus what an engineer needs to trust it (frequencies, the mode
decision and its reason, the inputs and their hash, versions, timings).

The file is an uncompressed NumPy ``.npz`` archive (loading it costs no
decompression): one array per quantity and a JSON ``meta`` record holding
the schema name and version, the package version, the input hash (the
entry's key) and a SHA-256 checksum over every array. A file that fails any
of these checks raises :class:`ReducedBodyFileError`; it is never used.
A body clamped on part of its boundary (the mesh pylon) is a
:class:`ClampedReduction`, in a file of the same kind.
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

from workbook._renamed import renamed_names

from .atomic import replacing
from .errors import ReducedBodyFileError
from .selection import ModeDecision

__all__ = ["ReducedBody", "ReducedBodyFileError", "save_reduced_body", "load_reduced_body", "ClampedReduction",
           "save_clamped_reduction", "load_clamped_reduction", "SCHEMA", "SCHEMA_VERSION", "CLAMPED_SCHEMA"]

SCHEMA = "mountwb-reduced-link"
SCHEMA_VERSION = 3
CLAMPED_SCHEMA = "mountwb-clamped-reduction"
CLAMPED_SCHEMA_VERSION = 1

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
class ReducedBody:
    """A free body (a link, the engine casing) reduced by Craig-Bampton, in its own frame.

    A link's frame has eye A's centre at the origin, eye B's centre on +x and
    the bore axes along z; the casing's is the casing frame. Nodes are the FE nodes followed by one master node
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
        body frame, Voigt order xx, yy, zz, yz, xz, xy), Pa per modal unit;
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
        """Centre of mass in the body frame, m."""
        return np.asarray(self.ffrf["chiU"], dtype=float)

    @property
    def inertia_at_origin(self) -> np.ndarray:
        """Inertia tensor about the body-frame origin (a link's eye A centre), kg m^2."""
        return np.asarray(self.ffrf["inertiaLocal"], dtype=float)

    @property
    def length(self) -> float:
        """Distance between the first two master nodes (a link's eye centres), m."""
        a, b = self.nodes[self.master_nodes[:2]]
        return float(np.linalg.norm(b - a))

    @property
    def input_hash(self) -> str:
        return self.info["input_hash"]

    def master_position(self, interface: int) -> np.ndarray:
        """Position of an interface's master node in the body frame, m."""
        return self.nodes[self.master_nodes[interface]]


def _arrays_of(body: ReducedBody) -> dict:
    arrays = {
        "nodes": body.nodes,
        "master_nodes": body.master_nodes,
        "surface_triangles": body.surface_triangles,
        "mode_basis": body.mode_basis,
        "stress_modes": body.stress_modes,
        "residual_mass": body.residual_mass,
    }
    for i, nodes in enumerate(body.interface_nodes):
        arrays[f"interface_nodes_{i}"] = nodes
    for key in FFRF_KEYS:
        arrays[f"ffrf_{key}"] = np.asarray(body.ffrf[key])
    for key, value in body.frequencies.items():
        arrays[f"freq_{key}"] = np.asarray(value)
    return arrays


def _checksum(arrays: dict) -> str:
    digest = hashlib.sha256()
    for key in sorted(arrays):
        value = np.ascontiguousarray(arrays[key])
        digest.update(key.encode())
        digest.update(str(value.dtype).encode())
        digest.update(str(value.shape).encode())
        digest.update(value.reshape(-1).view(np.uint8).data)   # its bytes, as tobytes() gives them, without a copy
    return digest.hexdigest()


def save_reduced_body(body: ReducedBody, path) -> Path:
    """Write a reduced body atomically (temporary file in the same folder, then rename).

    Parameters
    ----------
    body : ReducedBody
    path : str or Path
        Target ``.npz`` file.

    Returns
    -------
    Path
    """
    meta = {
        "interface_names": list(body.interface_names),
        "n_interfaces": len(body.interface_nodes),
        "frequency_keys": sorted(body.frequencies),
        "decision": body.decision.to_dict(),
        "info": body.info,
    }
    return _write_archive(path, SCHEMA, SCHEMA_VERSION, _arrays_of(body), meta)


def load_reduced_body(path, key: str | None = None) -> ReducedBody:
    """Read and verify a reduced-body file.

    Parameters
    ----------
    path : str or Path
    key : str, optional
        The input hash the file must carry (a cache entry's key).

    Raises
    ------
    ReducedBodyFileError
        The file is missing, not an archive, damaged, of another schema or
        version, of another key, or its checksum does not match its contents.
    """
    path = Path(path)
    arrays, meta = _read_archive(path, SCHEMA, SCHEMA_VERSION, key)
    try:
        return ReducedBody(
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
        raise ReducedBodyFileError(f"{path}: incomplete reduced-body file (missing {exc})") from None


@dataclass(frozen=True)
class ClampedReduction:
    """A body clamped on part of its boundary, reduced by Craig-Bampton on its interfaces' master nodes.

    Its coordinates are the master nodes' six DOF each (static modes, in
    interface order), then the kept fixed-interface modes.

    Attributes
    ----------
    stiffness, mass : ndarray, shape (n, n)
        Reduced stiffness (N/m, N per rad) and mass (kg, kg m^2).
    point_map : ndarray, shape (3 n_points, n)
        Displacement of each point rigidly carried by an interface's master node, m per unit coordinate.
    fixed_interface_hz : ndarray
        Frequencies of the kept fixed-interface modes, Hz.
    info : dict
        JSON-able: inputs, input hash, ``fe_dof`` and the time of the reduction in s (``seconds``).
    cache_hit : bool
        True when this object was loaded from the cache.
    """

    stiffness: np.ndarray
    mass: np.ndarray
    point_map: np.ndarray
    fixed_interface_hz: np.ndarray
    info: dict
    cache_hit: bool = field(default=False, compare=False)

    def arrays(self) -> dict:
        """Its arrays by name, as its file holds them."""
        return {"stiffness": self.stiffness, "mass": self.mass, "point_map": self.point_map,
                "fixed_interface_hz": self.fixed_interface_hz}


def save_clamped_reduction(reduction: ClampedReduction, path) -> Path:
    """Write a clamped reduction atomically (temporary file in the same folder, then rename)."""
    return _write_archive(path, CLAMPED_SCHEMA, CLAMPED_SCHEMA_VERSION, reduction.arrays(), {"info": reduction.info})


def load_clamped_reduction(path, key: str | None = None) -> ClampedReduction:
    """Read and verify a clamped reduction's file.

    Raises
    ------
    ReducedBodyFileError
        As :func:`load_reduced_body`.
    """
    path = Path(path)
    arrays, meta = _read_archive(path, CLAMPED_SCHEMA, CLAMPED_SCHEMA_VERSION, key)
    try:
        return ClampedReduction(arrays["stiffness"], arrays["mass"], arrays["point_map"], arrays["fixed_interface_hz"],
                                meta["info"], cache_hit=True)
    except KeyError as exc:
        raise ReducedBodyFileError(f"{path}: incomplete clamped-reduction file (missing {exc})") from None


def _write_archive(path, schema: str, schema_version: int, arrays: dict, meta: dict) -> Path:
    """An uncompressed ``.npz`` of *arrays* and a ``meta`` record (schema, versions, units, checksum), written atomically."""
    path = Path(path)
    meta = {
        "schema": schema,
        "schema_version": schema_version,
        "package_version": package_version(),
        "units": {"length": "m", "mass": "kg", "time": "s", "frequency": "Hz", "force": "N"},
        **meta,
        "checksum": _checksum(arrays),
    }
    with replacing(path) as temporary, open(temporary, "wb") as handle:
        np.savez(handle, meta=np.array(json.dumps(meta)), **arrays)
    return path


def _read_archive(path: Path, schema: str, schema_version: int, key: str | None) -> tuple[dict, dict]:
    """The arrays and the ``meta`` record of a file :func:`_write_archive` wrote, verified.

    Raises
    ------
    ReducedBodyFileError
        Missing, not an archive, damaged, of another schema, version or key, or a checksum mismatch.
    """
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {key: data[key] for key in data.files}
    except FileNotFoundError:
        raise ReducedBodyFileError(f"{path}: no such reduced-body file") from None
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise ReducedBodyFileError(f"{path}: not a readable reduced-body file ({exc})") from None
    try:
        meta = json.loads(str(arrays.pop("meta")))
    except (KeyError, json.JSONDecodeError) as exc:
        raise ReducedBodyFileError(f"{path}: no valid 'meta' record ({exc})") from None
    if meta.get("schema") != schema:
        raise ReducedBodyFileError(f"{path}: schema {meta.get('schema')!r}, expected {schema!r}")
    if meta.get("schema_version") != schema_version:
        raise ReducedBodyFileError(
            f"{path}: schema version {meta.get('schema_version')}, this package reads version {schema_version}"
        )
    stored_key = (meta.get("info") or {}).get("input_hash")
    if key is not None and stored_key != key:
        raise ReducedBodyFileError(f"{path}: holds the entry of key {stored_key}, not of {key}")
    if _checksum(arrays) != meta.get("checksum"):
        raise ReducedBodyFileError(f"{path}: checksum mismatch, the file was altered or damaged")
    return arrays, meta


def with_decision(body: ReducedBody, decision: ModeDecision, cache_hit: bool) -> ReducedBody:
    """The same reduced body, carrying the decision of the current request."""
    return dataclasses.replace(body, decision=decision, cache_hit=cache_hit)


__getattr__ = renamed_names(__name__, {"ReducedLink": "ReducedBody", "ReducedLinkFileError": "ReducedBodyFileError",
                                       "save_reduced_link": "save_reduced_body", "load_reduced_link": "load_reduced_body"})
