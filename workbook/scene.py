"""Build the Exudyn scene of a case and hand back its item numbers.

The scene: the pylon (ground), the engine (one rigid body with a Tait-Bryan
node at its centre of gravity), the links (reduced flexible bodies from
:mod:`flexbodies`, or rigid bodies), one Cartesian spring-damper per hinge
with a force sensor, the static loads, and - when an excitation is given -
the excitation force. Only what the case asks for is built: no static loads
without preload, no clearance law where the gap is zero, no damping where it
is zero or switched off.

Hinge forces: every hinge's connector has the pylon (or else its first
body) on marker 0, so its ``Force`` output (Exudyn:
``F = k (p1 - p0) + d (v1 - v0)``, acting as +F on marker 0 and -F on
marker 1) is the force on the pylon, or on the hinge's first body.

For Exudyn users, :func:`build_scene` is the entry point: it returns the
``mbs`` with every item number, ready to extend and to solve with Exudyn's
own solvers (see ``docs/example_exudyn_script.py``).
"""
from __future__ import annotations

import logging
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Callable, Union

import numpy as np

from .case import ENGINE, PYLON, Case, Gravity, PointForce, PointMoment, SingleFrequencyExcitation
from .clearance import exudyn_clearance_function
from .excitation import ExcitationSignal

__all__ = ["Scene", "EngineItems", "HingeItems", "ExcitationItems", "build_scene", "reduce_links",
           "link_is_flexible"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class EngineItems:
    """Exudyn items of the engine.

    Attributes
    ----------
    node : int
        ``NodeRigidBodyRxyz`` at the centre of gravity.
    body : int
        ``ObjectRigidBody``.
    marker_rigid : int
        ``MarkerBodyRigid`` at the centre of gravity.
    """

    node: int
    body: int
    marker_rigid: int


@dataclass(frozen=True)
class HingeItems:
    """Exudyn items of a hinge.

    Attributes
    ----------
    connector : int
        ``ObjectConnectorCartesianSpringDamper``.
    sensor : int
        ``SensorObject`` of the connector force (stored in memory).
    markers : tuple of int
        Marker 0 (pylon, or the hinge's first body) and marker 1.
    on_pylon : bool
        Pylon-side hinge: its force is part of the pylon force.
    clearance : bool
        The clearance law is built (gap > 0 and clearance switched on).
    """

    connector: int
    sensor: int
    markers: tuple
    on_pylon: bool
    clearance: bool


@dataclass(frozen=True)
class ExcitationItems:
    """Exudyn items of the excitation.

    Attributes
    ----------
    name : str
    marker : int
        ``MarkerBodyPosition`` on the engine at the excitation point.
    load : int
        ``LoadForceVector`` with a symbolic load user function.
    signal : ExcitationSignal
        The force law, also evaluable with numpy.
    function : exudyn.symbolic.UserFunction
        The recorded symbolic load function (kept alive here).
    """

    name: str
    marker: int
    load: int
    signal: ExcitationSignal
    function: Any = field(repr=False)


@dataclass
class Scene:
    """An Exudyn system built from a case, with the item numbers of its parts.

    Attributes
    ----------
    case : Case
    system : exudyn.SystemContainer
    mbs : exudyn.MainSystem
    ground : int
        The pylon (``ObjectGround``).
    engine : EngineItems
    links : dict of str to flexbodies.ExudynLink
    reduced : dict of str to flexbodies.ReducedLink
    hinges : dict of str to HingeItems
    static_loads : dict of str to list of int
        Load numbers per static load (gravity has one per body).
    excitation : ExcitationItems or None
    load_scale : float
        Largest of the static loads and the excitation amplitude, N; scales
        the Newton tolerances.
    """

    case: Case
    system: Any
    mbs: Any
    ground: int
    engine: EngineItems
    links: dict
    reduced: dict
    hinges: dict[str, HingeItems]
    static_loads: dict[str, list]
    excitation: Union[ExcitationItems, None]
    load_scale: float
    _keep_alive: list = field(default_factory=list, repr=False)

    @property
    def pylon_hinges(self) -> list[str]:
        """Names of the pylon-side hinges."""
        return [name for name, items in self.hinges.items() if items.on_pylon]

    def body_dof(self) -> dict[str, int]:
        """Degrees of freedom per body (engine and links)."""
        dof = {ENGINE: 6}
        dof.update({name: link.dof for name, link in self.links.items()})
        return dof

    def body_nodes(self) -> dict[str, tuple]:
        """Exudyn node numbers per body."""
        nodes = {ENGINE: (self.engine.node,)}
        nodes.update({name: tuple(link.nodes) for name, link in self.links.items()})
        return nodes

    @contextmanager
    def excitation_paused(self):
        """Context in which the excitation force is zero (for static solves:
        Exudyn's static solver evaluates time-dependent loads at its load-step
        time)."""
        if self.excitation is None:
            yield
            return
        load, function = self.excitation.load, self.excitation.function
        self.mbs.SetLoadParameter(load, "loadVectorUserFunction", 0)
        try:
            yield
        finally:
            self.mbs.SetLoadParameter(load, "loadVectorUserFunction", function)

    def hinge_forces(self) -> dict[str, np.ndarray]:
        """Current force of every hinge on its marker-0 body (the pylon for
        pylon-side hinges), N."""
        import exudyn as exu

        return {name: np.array(self.mbs.GetObjectOutput(items.connector, exu.OutputVariableType.Force))
                for name, items in self.hinges.items()}


def link_is_flexible(case: Case, name: str) -> bool:
    """True if link *name* is built as a flexible body in *case*."""
    return case.effects.flexible_links and case.link_map[name].flexible


def _reduction_frequency(case: Case, excitation: Union[SingleFrequencyExcitation, None]) -> float:
    """Highest excitation frequency a reduction must serve, Hz."""
    if excitation is not None:
        return excitation.frequency
    frequencies = [e.frequency for e in case.excitations]
    return max(frequencies) if frequencies else 0.0


def reduce_links(case: Case, excitation: Union[SingleFrequencyExcitation, None] = None,
                 progress: Union[Callable[[int], None], None] = None) -> dict:
    """Reduce every link of *case* (cached on disk by :mod:`flexbodies`).

    Flexible links keep the modes their ``modes`` field asks for, judged at the
    excitation's frequency (default: the case's highest); rigid links need
    only their mass properties and take the static reduction.

    Parameters
    ----------
    case : Case
    excitation : RotatingForce or HarmonicForce, optional
    progress : callable, optional
        Called with the number of links reduced so far, after each link.

    Returns
    -------
    dict of str to flexbodies.ReducedLink
    """
    from flexbodies import reduce_link

    frequency = _reduction_frequency(case, excitation)
    reduced = {}
    for link in case.links:
        modes = link.modes if link_is_flexible(case, link.name) else "static"
        reduced[link.name] = reduce_link(link.model, modes=modes, excitation_hz=frequency)
        if progress is not None:
            progress(len(reduced))
    return reduced


def _load_scale(case: Case, excitation: Union[SingleFrequencyExcitation, None], link_mass: float) -> float:
    scale = 1.0
    if excitation is not None:
        scale = max(scale, excitation.force_amplitude)
    if case.effects.preload:
        for load in case.static_loads:
            if isinstance(load, PointForce):
                scale = max(scale, float(np.linalg.norm(load.force)))
            elif isinstance(load, Gravity):
                scale = max(scale, (case.engine.mass + link_mass) * float(np.linalg.norm(load.acceleration)))
    return scale


def build_scene(case: Case, excitation: Union[SingleFrequencyExcitation, None] = None, *,
                reduced: Union[dict, None] = None) -> Scene:
    """Build the Exudyn system of *case*.

    Parameters
    ----------
    case : Case
    excitation : RotatingForce or HarmonicForce, optional
        The excitation to apply (with the case's smooth start); None builds
        the static scene only.
    reduced : dict of str to flexbodies.ReducedLink, optional
        Reduced links from :func:`reduce_links` (computed when omitted).

    Returns
    -------
    Scene
        The assembled system and its item numbers. The system is assembled;
        nothing has been solved.
    """
    import exudyn as exu
    from exudyn.advancedUtilities import CreateSymbolicUserFunction
    from flexbodies import add_link_to_exudyn

    eii = exu.itemInterface
    if reduced is None:
        reduced = reduce_links(case, excitation)
    system = exu.SystemContainer()
    mbs = system.AddSystem()
    keep_alive = []

    ground = mbs.AddObject(eii.ObjectGround(visualization=eii.VObjectGround(show=False)))
    engine = _add_engine(mbs, case)

    links = {}
    for link in case.links:
        damping = case.effects.link_damping
        optional = {} if link.spin_frequency_hz is None else {"spin_frequency_hz": link.spin_frequency_hz}
        links[link.name] = add_link_to_exudyn(
            mbs, reduced[link.name], link.end_a, link.end_b,
            flexible=link_is_flexible(case, link.name), bore_axis=link.bore_axis,
            stiffness_damping=link.stiffness_damping if damping else 0.0,
            mass_damping=link.mass_damping if damping else 0.0, name=link.name, **optional)

    def marker(body_name: str, position) -> int:
        if body_name == PYLON:
            return mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=ground, localPosition=list(position)))
        if body_name == ENGINE:
            local = np.subtract(position, case.engine.center_of_mass)
            return mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=engine.body, localPosition=list(local)))
        eye = case.link_map[body_name].eye_at(position)
        return links[body_name].marker_a if eye == "a" else links[body_name].marker_b

    clearance_functions = {}
    hinges = {}
    for hinge in case.hinges:
        first, second = hinge.bodies if hinge.body_b != PYLON else hinge.bodies[::-1]
        markers = (marker(first, hinge.position), marker(second, hinge.position))
        damping = hinge.damping if case.effects.hinge_damping else 0.0
        clearance = case.effects.clearance and hinge.radial_clearance > 0
        stiffness = hinge.gap_contact_stiffness if clearance else hinge.stiffness
        connector = mbs.AddObject(eii.ObjectConnectorCartesianSpringDamper(
            name=hinge.name, markerNumbers=list(markers), stiffness=[stiffness] * 3, damping=[damping] * 3,
            visualization=eii.VObjectConnectorCartesianSpringDamper(show=False)))
        if clearance:
            gap = hinge.radial_clearance
            if gap not in clearance_functions:
                clearance_functions[gap] = exudyn_clearance_function(gap)
            law = CreateSymbolicUserFunction(mbs, clearance_functions[gap], "springForceUserFunction", connector)
            mbs.SetObjectParameter(connector, "springForceUserFunction", law)
            keep_alive.append(law)
        sensor = mbs.AddSensor(eii.SensorObject(
            name=f"force {hinge.name}", objectNumber=connector, storeInternal=True, writeToFile=False,
            outputVariableType=exu.OutputVariableType.Force))
        hinges[hinge.name] = HingeItems(connector, sensor, markers, hinge.on_pylon, clearance)

    static_loads = _add_static_loads(mbs, case, engine, links) if case.effects.preload else {}

    excitation_items = None
    if excitation is not None:
        signal = ExcitationSignal.of(excitation, case.analysis.ramp_periods)
        point = mbs.AddMarker(eii.MarkerBodyPosition(
            bodyNumber=engine.body, localPosition=list(np.subtract(excitation.point, case.engine.center_of_mass))))
        load = mbs.AddLoad(eii.LoadForceVector(name=excitation.name, markerNumber=point, loadVector=[0.0] * 3))
        function = CreateSymbolicUserFunction(mbs, signal.exudyn_user_function(), "loadVectorUserFunction", load)
        mbs.SetLoadParameter(load, "loadVectorUserFunction", function)
        excitation_items = ExcitationItems(excitation.name, point, load, signal, function)

    mbs.Assemble()
    link_mass = sum(link.mass for link in links.values())
    scene = Scene(case, system, mbs, ground, engine, links, reduced, hinges, static_loads, excitation_items,
                  _load_scale(case, excitation, link_mass), keep_alive)
    log.info("scene of %r: %d bodies, %d hinges, %d ODE2 coordinates", case.name, 1 + len(links),
             len(hinges), mbs.systemData.ODE2Size())
    return scene


def _add_engine(mbs, case: Case) -> EngineItems:
    import exudyn as exu

    eii = exu.itemInterface
    inertia = case.engine.inertia_matrix
    node = mbs.AddNode(eii.NodeRigidBodyRxyz(
        name="engine", referenceCoordinates=list(case.engine.center_of_mass) + [0.0, 0.0, 0.0],
        visualization=eii.VNodeRigidBodyRxyz(show=False)))
    body = mbs.AddObject(eii.ObjectRigidBody(
        name="engine", nodeNumber=node, mass=case.engine.mass,
        inertia=[inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[1, 2], inertia[0, 2], inertia[0, 1]],
        visualization=eii.VObjectRigidBody(show=False)))
    marker = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=body, localPosition=[0.0, 0.0, 0.0]))
    return EngineItems(node, body, marker)


def _add_static_loads(mbs, case: Case, engine: EngineItems, links: dict) -> dict[str, list]:
    """Static loads: forces and moments on the engine, gravity on every body."""
    import exudyn as exu

    eii = exu.itemInterface
    loads = {}
    for load in case.static_loads:
        if isinstance(load, PointForce):
            local = np.subtract(load.point, case.engine.center_of_mass)
            point = mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=engine.body, localPosition=list(local)))
            loads[load.name] = [mbs.AddLoad(eii.LoadForceVector(name=load.name, markerNumber=point,
                                                               loadVector=list(load.force)))]
        elif isinstance(load, PointMoment):
            loads[load.name] = [mbs.AddLoad(eii.LoadTorqueVector(name=load.name, markerNumber=engine.marker_rigid,
                                                                loadVector=list(load.moment)))]
        else:
            bodies = [engine.body] + [link.body for link in links.values()]
            loads[load.name] = [
                mbs.AddLoad(eii.LoadMassProportional(
                    markerNumber=mbs.AddMarker(eii.MarkerBodyMass(bodyNumber=body)),
                    loadVector=list(load.acceleration)))
                for body in bodies]
    return loads
