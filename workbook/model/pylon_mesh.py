"""The pylon as a user's finite-element mesh: its inputs and its reduction to a compliance at the pins.

A solid mesh of the pylon (any volume mesh meshio reads, as for a link) is
clamped where it meets the wing, on every node of its root plane, and
carries the pylon pins: each pin is a bore of the mesh found around the
pin's position (axis and radius given, as for a link's bore), tied to a
master node by a rigid (RBE2) coupling. The pin moves with that master node
through a rigid offset from the bore's centre to the pin.

Its reduction (:func:`mesh_pylon_model`) follows the chain of the links
(:mod:`flexbodies`): the mesh read with its pin bores resolved, K and M
assembled with scikit-fem, every bore tied to a master node at its centre
(RBE2). Then the pylon's own steps:

- clamped: every degree of freedom of the nodes on the root plane is
  removed (a root node inside a bore is refused: the pin would be clamped);
- reduced by Craig-Bampton on the pins' master nodes (six DOF each): the
  static modes make the compliance exact at 0 Hz, and the fixed-interface
  modes are kept up to :data:`flexbodies.selection.MODE_MARGIN` times the
  highest frequency the case asks for (the links' rule), at least
  :data:`MINIMUM_MODES` of them;
- each pin moves with its bore's master node through the rigid offset from
  the bore's centre to the pin, ``x_pin = u + theta x r``.

The reduced matrices and that pin map are a
:class:`~workbook.model.pylon.PylonStructure`, whose compliance closes the
four-pole set as the box beam's does.
"""
from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np

from flexbodies.materials import Material
from workbook.errors import CaseError
from workbook.model.fields import positive_number, vector3
from workbook.model.pylon import Pin, PinDynamics, PylonModel, PylonStructure

__all__ = ["MeshPylon", "mesh_pylon_model", "MINIMUM_MODES"]


@dataclass(frozen=True)
class MeshPylon(PylonModel):
    """A pylon from a user's solid mesh, clamped on its root plane (a :class:`~workbook.model.pylon.PylonModel`).

    Parameters
    ----------
    path : str
        Mesh file (``.msh``, ``.inp``, ``.vtu``, ...; quadratic tetrahedra
        preferred), coordinates in the case's axes times ``scale``.
    root_point, root_normal : 3 floats
        A point of the root plane (m) and its normal: every mesh node within
        ``root_tolerance`` of the plane is clamped.
    bore_axis : 3 floats
        Direction of the pin bores' axes.
    bore_radius : float
        Radius of the pin bores, m.
    material : flexbodies.Material
    loss_factor : float
        Structural loss factor of the pylon's material (stiffness ``K (1 + i eta)``).
    scale : float
        Factor from the file's units to m (1e-3 for a file in mm).
    root_tolerance : float
        Distance from the root plane within which a node is clamped, m.
    name : str
    """

    effect: ClassVar[str] = "flexible pylon (mesh)"
    noun: ClassVar[str] = "pylon mesh"
    legacy_field: ClassVar[str] = "pylon_mesh"
    time_domain_note: ClassVar[str] = "the mesh is reduced to the pylon's compliance in the frequency domain"

    path: str
    root_point: tuple
    root_normal: tuple
    bore_axis: tuple
    bore_radius: float
    material: Material
    loss_factor: float = 0.02
    scale: float = 1.0
    root_tolerance: float = 1e-6
    name: str = "mesh pylon"

    def __post_init__(self):
        item = f"pylon mesh {self.name!r}"
        set_ = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        if not isinstance(self.path, (str, Path)) or not str(self.path):
            raise CaseError(item, "path", self.path, "the path of a mesh file")
        set_("path", str(self.path))
        for name in ("root_point", "root_normal", "bore_axis"):
            set_(name, vector3(item, name, getattr(self, name)))
        for name in ("root_normal", "bore_axis"):
            if not np.linalg.norm(getattr(self, name)) > 0:
                raise CaseError(item, name, getattr(self, name), "a non-zero direction")
        for name in ("bore_radius", "scale", "root_tolerance"):
            set_(name, positive_number(item, name, getattr(self, name)))
        if not isinstance(self.material, Material):
            raise CaseError(item, "material", self.material, "a Material")
        loss = float(self.loss_factor) if isinstance(self.loss_factor, (int, float)) and not isinstance(
            self.loss_factor, bool) else math.nan
        if not (math.isfinite(loss) and loss >= 0):
            raise CaseError(item, "loss_factor", self.loss_factor, "a number >= 0")
        set_("loss_factor", loss)

    def describe(self) -> str:
        """One line for the model card."""
        return (f"{self.name}: {self.material.name} mesh {Path(self.path).name}, clamped on its root plane, "
                f"pins on bores of radius {1e3 * self.bore_radius:.4g} mm, loss factor {self.loss_factor:g}")

    @property
    def label(self) -> str:
        """Its name."""
        return self.name

    def pins_at(self, pins: Sequence[Pin], frequencies_hz: Sequence[float], highest_hz: float) -> PinDynamics:
        """The reduced mesh's compliance at *pins* (:func:`mesh_pylon_model`, reduced for *highest_hz*)."""
        structure, facts = mesh_pylon_model(self, [position for position, _ in pins], highest_hz)
        modes = (f"{facts['modes']} fixed-interface modes up to {facts['highest_mode_hz']:.0f} Hz"
                 if facts["modes"] else "static modes only")
        return PinDynamics(None, structure.compliance(frequencies_hz),
                           f"{self.describe()}; {facts['fe_dof']} FE DOF reduced to {facts['reduced_dof']} "
                           f"(Craig-Bampton on the pins, {modes}) in {facts['seconds']:.2f} s, compliance at the pins")


#: Reduced pylons kept in memory, by their inputs and the mesh file's signature.
_reduced: dict = {}
_KEPT = 4

#: Fewest fixed-interface modes kept. With the pins held, a pylon's fixed-interface modes lie far above
#: its own modes on the mount, so the links' rule alone may keep one or two: on a clamped bar whose first
#: bending mode on its pin is near 40 Hz, the compliance at 30 Hz with the one mode the rule kept differed
#: by 0.59 % from a reduction keeping 10, and with 5 modes by 0.009 % from one keeping modes to 8 kHz.
MINIMUM_MODES = 6


def _skew(r: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def _root_coordinates(pylon: MeshPylon, nodes: np.ndarray, coupling, bore_nodes: set) -> np.ndarray:
    """Coupled coordinates of the root plane's nodes (the clamped ones)."""
    import scipy.sparse as sp

    item = f"pylon mesh {pylon.name!r}"
    normal = np.asarray(pylon.root_normal) / np.linalg.norm(pylon.root_normal)
    on_root = np.flatnonzero(np.abs((nodes - np.asarray(pylon.root_point)) @ normal) <= pylon.root_tolerance)
    if on_root.size == 0:
        raise CaseError(item, "root_point", pylon.root_point,
                        f"a plane through nodes of the mesh {pylon.path} (none lies within "
                        f"{pylon.root_tolerance:g} m of it, normal {tuple(pylon.root_normal)})")
    if bore_nodes & set(on_root.tolist()):
        raise CaseError(item, "root_point", pylon.root_point,
                        "a root plane that does not cut a pin bore (the pin would be clamped)")
    rows = (3 * on_root[:, None] + np.arange(3)).ravel()
    transform = sp.csr_matrix(coupling.transform)[rows]
    return np.unique(transform.indices)


def mesh_pylon_model(pylon: MeshPylon, pins, highest_hz: float) -> tuple[PylonStructure, dict]:
    """The reduced pylon of a user's mesh and what it cost, kept in memory while its mesh file is unchanged
    (the runs of a case share one reduction).

    Parameters
    ----------
    pylon : MeshPylon
    pins : sequence of 3 floats
        Pin positions, m (``Case.pylon_pins()`` order).
    highest_hz : float
        Highest frequency the compliance is asked at, Hz.

    Returns
    -------
    structure : PylonStructure
    facts : dict
        ``fe_dof``, ``reduced_dof``, ``modes`` (fixed-interface modes kept),
        ``highest_mode_hz`` and ``seconds``.

    Raises
    ------
    workbook.errors.CaseError
        The mesh file missing or unreadable, a pin bore not found, a root
        plane through no node or through a bore.
    """
    from flexbodies.cache import file_signature

    key = (pylon, tuple(tuple(float(v) for v in p) for p in pins), float(highest_hz), file_signature(Path(pylon.path)))
    if key not in _reduced:
        _reduced[key] = _reduce(pylon, [np.asarray(p, dtype=float) for p in pins], highest_hz)
        while len(_reduced) > _KEPT:
            _reduced.pop(next(iter(_reduced)))
    return _reduced[key]


def _reduce(pylon: MeshPylon, pins, highest_hz: float) -> tuple[PylonStructure, dict]:
    # scikit-fem, meshio and gmsh load here, where a pylon is meshed: runs without one never need them
    from flexbodies.assembly import assemble
    from flexbodies.craig_bampton import craig_bampton
    from flexbodies.interfaces import couple_interfaces
    from flexbodies.meshing import BoreSpec, load_mesh
    from flexbodies.selection import MODE_MARGIN

    start = time.perf_counter()
    item = f"pylon mesh {pylon.name!r}"
    specs = [BoreSpec(f"pin {i + 1}", centre=tuple(position), axis=pylon.bore_axis, radius=pylon.bore_radius)
             for i, position in enumerate(pins)]
    try:
        mesh = load_mesh(pylon.path, specs, scale=pylon.scale)
    except FileNotFoundError as error:
        raise CaseError(item, "path", pylon.path, f"a mesh file that exists ({error})") from None
    except ValueError as error:
        raise CaseError(item, "path", pylon.path,
                        f"a readable mesh with a bore of radius {pylon.bore_radius:g} m along "
                        f"{tuple(pylon.bore_axis)} at every pylon pin ({error})") from None
    fe = assemble(mesh, pylon.material)
    coupling = couple_interfaces(fe, "RBE2")
    stiffness, mass = coupling.reduce(fe.stiffness), coupling.reduce(fe.mass)
    bore_nodes = {int(n) for bore in fe.bores for n in bore.nodes}
    clamped = _root_coordinates(pylon, np.asarray(fe.nodes), coupling, bore_nodes)
    free = np.setdiff1d(np.arange(coupling.n_q), clamped)
    position = np.full(coupling.n_q, -1)
    position[free] = np.arange(len(free))
    stiffness, mass = stiffness[free][:, free], mass[free][:, free]
    masters = position[coupling.master_dofs]          # (pins, 6), in the free coordinates
    cb = craig_bampton(stiffness, mass, masters.ravel(), cutoff_hz=MODE_MARGIN * highest_hz)
    if len(cb.fixed_interface_hz) < MINIMUM_MODES:
        cb = craig_bampton(stiffness, mass, masters.ravel(), count=MINIMUM_MODES)
    pin_map = np.zeros((3 * len(pins), cb.vectors.shape[1]))
    for p, (pin, centre) in enumerate(zip(pins, coupling.centres, strict=True)):
        offset = np.asarray(pin, dtype=float) - centre
        # the master DOF are the first reduced coordinates, pin by pin (static modes)
        pin_map[3 * p:3 * p + 3, 6 * p:6 * p + 3] = np.eye(3)
        pin_map[3 * p:3 * p + 3, 6 * p + 3:6 * p + 6] = -_skew(offset)
    structure = PylonStructure(cb.project(stiffness), cb.project(mass), pin_map, pylon.loss_factor)
    modes = len(cb.fixed_interface_hz)
    return structure, {"fe_dof": int(fe.ndof), "reduced_dof": int(cb.vectors.shape[1]), "modes": modes,
                       "highest_mode_hz": float(cb.fixed_interface_hz[-1]) if modes else None,
                       "seconds": time.perf_counter() - start}
