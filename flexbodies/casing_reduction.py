"""An engine casing reduced by Craig-Bampton, cached, and put into Exudyn.

The casing passes through the links' chain (:mod:`flexbodies.link`): mesh,
assemble, couple the interfaces (:mod:`flexbodies.casing`: the mount eyes
and the bearing planes, any number of them), factorise the interior
stiffness once, reduce for every mode decision
(:func:`flexbodies.reduction.reduce_for_decisions`) into a
:class:`~flexbodies.reduced.ReducedBody` in the casing frame. Only the
fundamental of the low-frequency rule differs: a casing has no two-pin
mounting of its own, so its first *free-free* elastic frequency decides
(static modes only while the excitation is below a quarter of it).

The store is every body's (:class:`flexbodies.cache.BodyCache`): the
free-free frequencies under the hash of every input, the reduced casing
under that hash and the mode decision.
"""
from __future__ import annotations

import dataclasses
import functools
import hashlib
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .cached_reduction import cached_reductions
from .casing import CasingGeometry, casing_interfaces, default_casing_element_size, element_size_error, mesh_casing
from .exudyn_body import exudyn_cms_interface, modal_damping_matrix
from .materials import TITANIUM, Material
from .reduced import SCHEMA_VERSION, ReducedBody
from .selection import MOUNTED_BOUNDARY, decide_modes

# Meshing (gmsh, meshio), assembly (scikit-fem) and the reduction load where a casing is reduced: a run
# whose casing is in the cache never needs them.

__all__ = ["CasingModel", "ExudynCasing", "reduce_casing", "add_casing_to_exudyn", "FREE_FREE"]

#: The boundary of the casing's fundamental in the low-frequency rule.
FREE_FREE = "first free-free elastic mode of the casing"


@dataclass(frozen=True)
class CasingModel:
    """Everything a casing's reduction depends on.

    Attributes
    ----------
    interfaces : tuple of CasingInterface
        Eyes and bearing planes, in the casing frame.
    geometry : CasingGeometry, optional
        A parametric casing (exactly one of ``geometry`` and ``mesh_file``).
    mesh_file : str, optional
        A user's mesh file (meshio), in the casing frame after ``scale``.
    scale : float
        Factor from the mesh file's units to m.
    material : Material
    element_size : float, optional
        Mesh size of a parametric casing, m.

    Each eye is tied to its master node rigidly (RBE2, a lug), each bearing
    plane by averaging (RBE3: the bearing frame loads the casing without
    stiffening its cross-section).
    """

    interfaces: tuple
    geometry: CasingGeometry | None = None
    mesh_file: str | None = None
    scale: float = 1.0
    material: Material = TITANIUM
    element_size: float | None = None

    def fingerprint(self) -> dict:
        """JSON-able description of every input; a mesh file enters by its SHA-256."""
        if self.geometry is not None:
            size = self.element_size if self.element_size is not None else default_casing_element_size(self.geometry)
            shape = {"geometry": dataclasses.asdict(self.geometry), "element_size": size}
        else:
            assert self.mesh_file is not None
            path = Path(self.mesh_file)
            try:
                digest = hashlib.sha256(path.read_bytes()).hexdigest()
            except OSError as exc:
                raise FileNotFoundError(f"casing mesh file {path}: cannot be read ({exc.strerror})") from None
            shape = {"mesh_sha256": digest, "mesh_file": path.name, "scale": self.scale}
        return {"schema_version": SCHEMA_VERSION, "kind": "casing", **shape,
                "interfaces": [dataclasses.asdict(i) for i in self.interfaces],
                "material": self.material.elastic_inputs()}

    def couplings(self) -> list[str]:
        """The coupling of each interface: RBE2 for an eye, RBE3 for a bearing plane."""
        return ["RBE2" if interface.kind == "eye" else "RBE3" for interface in self.interfaces]

    def source(self) -> str:
        """Where the casing comes from, for messages."""
        return "the parametric casing" if self.geometry is not None else f"casing mesh {self.mesh_file}"

    def meshed(self):
        """The casing mesh with its interfaces resolved.

        Raises
        ------
        flexbodies.casing.ElementSizeTooLarge
            A parametric casing whose mesh has tangled elements (checked
            before its interfaces, which a tangled mesh may miss too).
        """
        from .meshing import load_mesh

        if self.geometry is not None:
            from .assembly import tangled_elements

            size = self.element_size if self.element_size is not None else default_casing_element_size(self.geometry)
            casing_mesh = mesh_casing(self.geometry, size)
            tangled = tangled_elements(casing_mesh.mesh).size
            if tangled:
                raise element_size_error(self.geometry, size, tangled, casing_mesh.mesh.nelements)
        else:
            casing_mesh = load_mesh(self.mesh_file, (), scale=self.scale)
        return casing_interfaces(casing_mesh, self.interfaces, self.source())


def _decide(modes, frequencies: dict, excitation_hz: float):
    """The mode decision on the casing's free-free fundamental (the reason says so)."""
    decision = decide_modes(modes, frequencies["free_free_hz"][0], excitation_hz)
    return dataclasses.replace(decision, reason=decision.reason.replace(MOUNTED_BOUNDARY, FREE_FREE))


def reduce_casing(model: CasingModel, modes="auto", excitations_hz=(None,), *, cache_dir=None,
                  use_cache: bool = True) -> tuple:
    """Reduce a casing for several excitations at once (one FE model and factorisation serve
    them all), reusing the cache where the inputs match.

    Parameters
    ----------
    model : CasingModel
    modes : {"auto", "static"} or int or float
        See :func:`flexbodies.selection.decide_modes`; ``"auto"`` judges each
        excitation against the casing's first free-free frequency.
    excitations_hz : sequence of float or None
        The highest excitation frequency of each run that needs the casing, Hz.
    cache_dir : str or Path, optional
    use_cache : bool

    Returns
    -------
    tuple of ReducedBody
        One per excitation, in the casing frame; one master node per
        interface, in order. ``frequencies["free_free_hz"]`` holds the six
        lowest elastic free-free frequencies of the FE model
        (``"mounted_hz"`` is empty); ``info`` the timings, s.
    """
    def prepare(frequencies):
        from .assembly import assemble
        from .interior import InteriorSolver
        from .reduction import couple

        start = time.perf_counter()
        casing_mesh = model.meshed()
        meshed = time.perf_counter()
        fe = assemble(casing_mesh, model.material)
        timings = {"mesh_seconds": meshed - start, "assembly_seconds": time.perf_counter() - meshed}
        coupled = couple(fe, model.couplings())
        start = time.perf_counter()
        solver = InteriorSolver(coupled.stiffness, coupled.mass, coupled.coupling)
        timings["reduction_seconds"] = time.perf_counter() - start
        if frequencies is None:
            start = time.perf_counter()
            # the store's summary holds the mounted frequencies of a link too: a casing has none
            frequencies = {"free_free_hz": solver.free_free_frequencies(6), "mounted_hz": np.zeros(0)}
            timings["frequency_seconds"] = time.perf_counter() - start
        return coupled, solver, frequencies, timings

    return cached_reductions(model.fingerprint(), functools.partial(_decide, modes), excitations_hz, prepare, cache_dir=cache_dir,
                             use_cache=use_cache)


@dataclass(frozen=True)
class ExudynCasing:
    """Item numbers of a casing in an Exudyn system.

    Attributes
    ----------
    body : int
        ``ObjectFFRFreducedOrder``.
    nodes : tuple of int
        Frame node, then the modal node.
    markers : dict of str to int
        ``MarkerSuperElementPosition`` at each interface's master node, by interface name.
    dof : int
    mass : float
        kg.
    """

    body: int
    nodes: tuple
    markers: dict
    dof: int
    mass: float


def add_casing_to_exudyn(mbs, casing: ReducedBody, position, *, modal_damping_ratio: float = 0.0,
                         name: str = "") -> ExudynCasing:
    """Add a reduced casing as an ``ObjectFFRFreducedOrder`` whose frame sits at *position* (global axes).

    Parameters
    ----------
    mbs : exudyn.MainSystem
    casing : ReducedBody
        From :func:`reduce_casing`.
    position : 3 floats
        Global position of the casing frame's origin, m.
    modal_damping_ratio : float
        Damping ratio of every elastic mode (:func:`flexbodies.exudyn_body.modal_damping_matrix`).
    name : str

    Returns
    -------
    ExudynCasing
    """
    import exudyn as exu

    eii = exu.itemInterface
    items = exudyn_cms_interface(casing).AddObjectFFRFreducedOrder(
        mbs, positionRef=list(np.asarray(position, dtype=float)), rotationMatrixRef=np.eye(3), name=name)
    body = items["oFFRFreducedOrder"]
    if modal_damping_ratio > 0:
        damping = exu.MatrixContainer()
        damping.SetWithDenseMatrix(modal_damping_matrix(casing, modal_damping_ratio), useDenseMatrix=False)
        mbs.SetObjectParameter(body, "dampingMatrixReduced", damping)
    markers = {interface: mbs.AddMarker(eii.MarkerSuperElementPosition(
        bodyNumber=body, meshNodeNumbers=[int(node)], weightingFactors=[1.0]))
        for interface, node in zip(casing.interface_names, casing.master_nodes, strict=True)}
    return ExudynCasing(body, (items["nRigidBody"], items["nGenericODE2"]), markers, casing.dof, casing.mass)
