"""The flexible engine in the Exudyn scene: the casing, the core and their bearings.

Built only when the case gives ``Engine.casing`` (:mod:`workbook.model.casing`):

- the casing, reduced (:func:`reduce_engine_casing`, cached like the links)
  and added as an ``ObjectFFRFreducedOrder`` in the casing frame;
- the core, a rigid body whose node sits at the engine's centre of gravity
  (where the rigid engine's node sits, so every load and output defined on
  the engine body acts on the core unchanged) carrying the engine's mass
  properties less the casing's (:func:`~workbook.model.casing.split_engine`);
- at each bearing plane a Cartesian spring-damper (axial along x, radial in
  y and z) from the core's point on the axis to the casing's bearing master
  node, and one torsional spring about the axis between the core's node
  and the casing's frame node (without it the core would spin freely).

The engine-side hinges attach to the casing's eye master nodes.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from flexbodies.casing import ElementSizeTooLarge
from flexbodies.casing_reduction import add_casing_to_exudyn, reduce_casing
from flexbodies.craig_bampton import ModeBudgetExceeded
from workbook.errors import CaseError
from workbook.model.casing import CASING, CoreBody, bearing_name, casing_origin, parallel_axis, split_engine
from workbook.scene.mode_budget import mode_budget_error

__all__ = ["CasingItems", "reduce_engine_casing", "add_flexible_engine", "eye_name"]

#: Marker frame whose z axis is the node's x axis (the torsional spring acts about z).
_ABOUT_X = np.array([[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class CasingItems:
    """The flexible engine's parts in the scene.

    Attributes
    ----------
    reduced : flexbodies.ReducedBody
        The reduced casing (casing frame).
    casing : flexbodies.casing_reduction.ExudynCasing
    core : CoreBody
    eyes : tuple of (3 floats, int)
        Each mount eye's position (m) and its marker on the casing.
    bearings : tuple of int
        ``ObjectConnectorCartesianSpringDamper`` per bearing plane.
    spin_restraint : int
        ``ObjectConnectorTorsionalSpringDamper`` between core and casing.
    spin_stiffness : float
        N m/rad.
    seconds : float
        Wall time of the casing's reduction (or cache load) in this build, s.
    """

    reduced: Any = field(repr=False)
    casing: Any
    core: CoreBody
    eyes: tuple
    bearings: tuple
    spin_restraint: int
    spin_stiffness: float
    seconds: float

    def eye_marker(self, position) -> int:
        """The casing marker of the mount eye at *position* (m)."""
        return min(self.eyes, key=lambda eye: float(np.linalg.norm(np.subtract(eye[0], position))))[1]


def eye_name(hinges) -> str:
    """Interface name of the mount eye carrying *hinges* (names)."""
    return "eye " + " + ".join(hinges)


def reduce_engine_casing(case, excitation_hz: float):
    """The case's casing reduced for *excitation_hz* (Hz), from the cache where it matches (a
    reduction serves every excitation frequency of the case at once, from one factorisation).

    Raises
    ------
    CaseError
        The mesh file cannot be read or has no surface at an interface, or two
        interfaces overlap (the message is the reduction's, naming the file);
        a parametric casing's element size too large to mesh untangled; or
        an excitation asks for more modes than a reduction keeps.
    """
    casing, engine = case.engine.casing, case.engine
    model = casing.model(engine.center_of_mass, [(eye_name(names), point) for point, names in case.engine_eyes()])
    try:
        frequencies = sorted({e.frequency for e in case.excitations} | {excitation_hz})
        return reduce_casing(model, casing.modes, frequencies)[frequencies.index(excitation_hz)]
    except ModeBudgetExceeded as error:
        raise mode_budget_error(case, f"the {CASING}", casing.modes, error) from None
    except ElementSizeTooLarge as error:
        raise CaseError(CASING, "element_size", error.element_size,
                        f"an element size of at most {error.largest:g} m: {error}") from None
    except (ValueError, OSError) as error:
        field_name = "mesh" if casing.mesh is not None else "geometry"
        raise CaseError("engine casing", field_name, casing.mesh or "the parametric casing",
                        f"a casing meshed with surface at every mount eye and bearing plane: {error}") from None


def add_flexible_engine(mbs, case, excitation_hz: float, names) -> tuple[tuple[int, int, int], CasingItems]:
    """Add the casing, the core and their bearings.

    Parameters
    ----------
    mbs : exudyn.MainSystem
    case : Case
        With ``engine.casing``.
    excitation_hz : float
        Frequency the casing's reduction must serve, Hz.
    names : callable
        ``names(label)`` gives the Exudyn name of a scene item.

    Returns
    -------
    core : (int, int, int)
        The core's node, body and rigid marker at the engine's centre of gravity.
    items : CasingItems
    """
    import exudyn as exu

    eii = exu.itemInterface
    engine, casing = case.engine, case.engine.casing
    start = time.perf_counter()
    reduced = reduce_engine_casing(case, excitation_hz)
    seconds = time.perf_counter() - start
    origin = casing_origin(engine.center_of_mass)
    cg = np.asarray(engine.center_of_mass, dtype=float)
    core = split_engine(engine.mass, cg, engine.inertia_matrix, reduced.mass, origin + reduced.centre_of_mass,
                        _about_centre(reduced))
    offset = core.centre_of_mass - cg
    inertia = core.inertia + parallel_axis(core.mass, offset)
    node = mbs.AddNode(eii.NodeRigidBodyRxyz(name=names("engine core"), referenceCoordinates=list(cg) + [0.0] * 3,
                                             visualization=eii.VNodeRigidBodyRxyz(show=False)))
    body = mbs.AddObject(eii.ObjectRigidBody(
        name=names("engine core"), nodeNumber=node, mass=core.mass, centerOfMass=list(offset),
        inertia=[inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[1, 2], inertia[0, 2], inertia[0, 1]],
        visualization=eii.VObjectRigidBody(show=False)))
    marker = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=body, localPosition=[0.0, 0.0, 0.0]))
    flexible = add_casing_to_exudyn(mbs, reduced, origin, modal_damping_ratio=casing.modal_damping,
                                    name=names("engine casing"))
    radial, axial = casing.bearing_stiffness
    radial_damping, axial_damping = casing.bearing_damping
    bearings = []
    for x in casing.bearing_planes:
        on_core = mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=body, localPosition=[x - cg[0], 0.0, 0.0]))
        bearings.append(mbs.AddObject(eii.ObjectConnectorCartesianSpringDamper(
            name=names(f"engine {bearing_name(x)}"), markerNumbers=[on_core, flexible.markers[bearing_name(x)]],
            stiffness=[axial, radial, radial], damping=[axial_damping, radial_damping, radial_damping],
            visualization=eii.VObjectConnectorCartesianSpringDamper(show=False))))
    spin_stiffness = float(core.inertia[0, 0]) * (2 * np.pi * casing.core_spin_hz) ** 2
    spin = mbs.AddObject(eii.ObjectConnectorTorsionalSpringDamper(
        name=names("engine core spin"), stiffness=spin_stiffness,
        markerNumbers=[mbs.AddMarker(eii.MarkerNodeRigid(nodeNumber=node, localHT=_ABOUT_X)),
                       mbs.AddMarker(eii.MarkerNodeRigid(nodeNumber=flexible.nodes[0], localHT=_ABOUT_X))],
        visualization=eii.VObjectConnectorTorsionalSpringDamper(show=False)))
    eyes = tuple((tuple(point), flexible.markers[eye_name(hinges)]) for point, hinges in case.engine_eyes())
    return (node, body, marker), CasingItems(reduced, flexible, core, eyes, tuple(bearings), spin, spin_stiffness,
                                             seconds)


def _about_centre(reduced) -> np.ndarray:
    """The reduced casing's inertia about its own centre of mass, kg m^2."""
    return reduced.inertia_at_origin - parallel_axis(reduced.mass, reduced.centre_of_mass)
