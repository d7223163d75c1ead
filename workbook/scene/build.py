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

Test-rig force transducers (``case.test_rig`` with ``effects.rig_sensors``):
one per pylon pin, a point mass at the pin on a Cartesian spring-damper
from the ground (marker 0, so its ``Force`` is the force on the ground);
the pin's pylon-side hinges attach to that mass instead of the ground, and
the transducer forces, not the hinge forces, make the pylon force (what the
rig measures). Hinges and transducers are the scene's *force channels*
(:attr:`Scene.force_channels`), each with a force sensor;
:attr:`Scene.pylon_channels` names those summed into the pylon force.

Every Exudyn item is named within its kind (:func:`exudyn_name`, e.g.
``"hinge: front-up-left"``), so the case's names never collide with the
scene's own items.

For Exudyn users, :func:`build_scene` is the entry point: it returns the
``mbs`` with every item number, ready to extend and to solve with Exudyn's
own solvers (see ``docs/example_exudyn_script.py``).
"""
from __future__ import annotations

import logging
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from flexbodies.craig_bampton import ModeBudgetExceeded
from workbook.model.case import (
    ENGINE,
    POINT_TOLERANCE,
    PYLON,
    Case,
    Gravity,
    Hinge,
    PointForce,
    PointMoment,
    Simultaneous,
    SingleFrequencyExcitation,
    transducer_name,
)
from workbook.model.casing import CASING
from workbook.scene import hinge_laws
from workbook.scene.engine_casing import CasingItems, add_flexible_engine
from workbook.scene.excitation import ExcitationSignal
from workbook.scene.hinge_law_base import HingeLaw
from workbook.scene.link_workers import LinkJob, reduce_in_workers
from workbook.scene.mode_budget import mode_budget_error
from workbook.scene.structural_damping import equivalent_viscous_damping

__all__ = ["Scene", "EngineItems", "HingeItems", "TransducerItems", "ExcitationItems", "build_scene",
           "GyroscopicItems", "gyroscopics_built", "exudyn_gyroscopic_function", "reduce_links", "link_jobs",
           "exudyn_name", "loss_factors", "marker_bodies", "net_angular_momentum",
           "scene_warnings", "CANCELLED_MOMENTUM"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class EngineItems:
    """Exudyn items of the engine (of its core, when the casing is flexible).

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
        Pylon-side hinge: its force is part of the pylon force (with the
        rig's transducers built, it acts on a transducer instead, and the
        transducer forces make the pylon force).
    hinge_law : HingeLaw
        The hinge's law (:mod:`workbook.scene.hinge_laws`).
    law : exudyn.symbolic.UserFunction or None
        The recorded ``springForceUserFunction``, if the law built one.
    """

    connector: int
    sensor: int
    markers: tuple
    on_pylon: bool
    hinge_law: HingeLaw
    law: Any = field(default=None, repr=False)

    @property
    def nonlinear(self) -> bool:
        """The hinge's law makes the scene nonlinear."""
        return self.hinge_law.nonlinear


@dataclass(frozen=True)
class TransducerItems:
    """Exudyn items of a test-rig force transducer under one pylon pin.

    Attributes
    ----------
    node : int
        ``NodePoint`` of the transducer's moving half, at the pin.
    body : int
        ``ObjectMassPoint`` on that node.
    connector : int
        ``ObjectConnectorCartesianSpringDamper`` from the ground (marker 0) to
        the mass (marker 1): its ``Force`` is the force on the ground.
    sensor : int
        ``SensorObject`` of the connector force (stored in memory).
    markers : tuple of int
        Marker 0 on the ground and marker 1 on the mass; the pin's
        pylon-side hinges attach to marker 1.
    position : 3 floats
        The pin, m.
    hinges : tuple of str
        The pylon-side hinges the transducer carries.
    """

    node: int
    body: int
    connector: int
    sensor: int
    markers: tuple
    position: tuple
    hinges: tuple


@dataclass(frozen=True)
class ExcitationItems:
    """Exudyn items of the excitation.

    Attributes
    ----------
    name : str
    markers : tuple of int
        ``MarkerBodyPosition`` on the engine at each point of the excitation
        (one, or one per imbalance plane).
    loads : tuple of int
        ``LoadForceVector`` at each marker, with a symbolic load user function.
    signal : ExcitationSignal or None
        The resultant force law (the sum over the points), also evaluable
        with numpy; None for a :class:`~workbook.model.case.Simultaneous`
        excitation (several frequencies).
    functions : tuple of exudyn.symbolic.UserFunction
        The recorded symbolic load functions (kept alive here).
    excitation : RotatingForce, HarmonicForce or Imbalance
        The case's excitation.
    """

    name: str
    markers: tuple
    loads: tuple
    signal: ExcitationSignal | None
    functions: tuple = field(repr=False)
    excitation: Any = None


@dataclass(frozen=True)
class GyroscopicItems:
    """Exudyn items of the rotors' gyroscopic moment on the engine.

    Attributes
    ----------
    rotors : tuple of str
        Names of the rotors whose spin angular momenta are summed here.
    momentum : ndarray, shape (3,)
        Their total spin angular momentum ``sum(Ip Omega a)`` in engine
        coordinates, kg m^2/s.
    object : int
        ``ObjectGenericODE2`` on the engine node (zero mass matrix) whose
        symbolic ``forceUserFunction`` is the generalised gyroscopic force.
    function : exudyn.symbolic.UserFunction
        The recorded symbolic force function (kept alive here).
    """

    rotors: tuple
    momentum: np.ndarray
    object: int
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
    reduced : dict of str to flexbodies.ReducedBody
    hinges : dict of str to HingeItems
    transducers : dict of str to TransducerItems
        Test-rig force transducers by name (empty: the pylon pins are on
        rigid ground).
    static_loads : dict of str to list of int
        Load numbers per static load (gravity has one per body).
    excitation : ExcitationItems or None
    load_scale : float
        Largest of the static loads and the excitation amplitude, N; scales
        the Newton tolerances.
    gyroscopics : GyroscopicItems or None
        The rotors' gyroscopic moment (None: not built, see
        :func:`gyroscopics_built`).
    loss_factor_hz : float or None
        The frequency at which the loss factors of the hinges and links were
        built as their equivalent viscous damping (the time domain), Hz;
        None when they were not (no loss factor, no excitation, or the
        frequency domain adds them exactly, see :func:`loss_factors`).
    casing : CasingItems or None
        The flexible engine's casing, core and bearings
        (:mod:`workbook.scene.engine_casing`); None: a rigid engine.
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
    excitation: ExcitationItems | None
    load_scale: float
    transducers: dict = field(default_factory=dict)
    gyroscopics: GyroscopicItems | None = None
    loss_factor_hz: float | None = None
    casing: CasingItems | None = None

    def close(self) -> None:
        """Free Exudyn's system: reset the system container, whose memory
        (about 13 MB for the reference mount with flexible links) Python does
        not return when the scene is dropped. The scene cannot be solved or
        read afterwards; closing twice does nothing."""
        self.system.Reset()

    def __enter__(self) -> "Scene":
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    @property
    def force_channels(self) -> dict:
        """Every connector with a force sensor: the hinges (HingeItems), then
        the transducers (TransducerItems), by name."""
        return {**self.hinges, **self.transducers}

    @property
    def pylon_channels(self) -> list[str]:
        """Names of the force channels summed into the pylon force: the
        transducers when built, else the pylon-side hinges."""
        if self.transducers:
            return list(self.transducers)
        return [name for name, items in self.hinges.items() if items.on_pylon]

    def body_dof(self) -> dict[str, int]:
        """Degrees of freedom per body (engine, links, transducers)."""
        dof = {ENGINE: 6}
        if self.casing is not None:
            dof[CASING] = self.casing.casing.dof
        dof.update({name: link.dof for name, link in self.links.items()})
        dof.update({name: 3 for name in self.transducers})
        return dof

    def body_nodes(self) -> dict[str, tuple]:
        """Exudyn node numbers per body (engine, links, transducers)."""
        nodes = {ENGINE: (self.engine.node,)}
        if self.casing is not None:
            nodes[CASING] = tuple(self.casing.casing.nodes)
        nodes.update({name: tuple(link.nodes) for name, link in self.links.items()})
        nodes.update({name: (items.node,) for name, items in self.transducers.items()})
        return nodes

    def body_masses(self) -> dict[int, float]:
        """Mass of each Exudyn body of the engine and the links, kg."""
        masses = {self.engine.body: self.case.engine.mass if self.casing is None else self.casing.core.mass}
        if self.casing is not None:
            masses[self.casing.casing.body] = self.casing.casing.mass
        masses.update({link.body: link.mass for link in self.links.values()})
        return masses

    @contextmanager
    def excitation_paused(self):
        """Context in which the excitation force is zero (for static solves:
        Exudyn's static solver evaluates time-dependent loads at its load-step
        time)."""
        if self.excitation is None:
            yield
            return
        for load in self.excitation.loads:
            self.mbs.SetLoadParameter(load, "loadVectorUserFunction", 0)
        try:
            yield
        finally:
            for load, function in zip(self.excitation.loads, self.excitation.functions, strict=True):
                self.mbs.SetLoadParameter(load, "loadVectorUserFunction", function)

    @contextmanager
    def gaps_closed(self):
        """Context in which every nonlinear law is replaced by its connector's
        diagonal spring-damper: each clearance law by its contact stiffness,
        as if each gap were closed (for the mechanism check: the gaps of an
        unloaded mount are open, and inside them only the small residual
        stiffness of :mod:`workbook.scene.hinge_law` acts)."""
        laws = {items.connector: items.law for items in self.hinges.values() if items.nonlinear}
        for connector in laws:
            self.mbs.SetObjectParameter(connector, "springForceUserFunction", 0)
        try:
            yield
        finally:
            for connector, law in laws.items():
                self.mbs.SetObjectParameter(connector, "springForceUserFunction", law)

    def hinge_forces(self) -> dict[str, np.ndarray]:
        """Current force of every force channel (:attr:`force_channels`: the
        hinges, then the transducers) on its marker-0 body (the pylon for
        pylon-side hinges, the ground for transducers), N."""
        import exudyn as exu

        return {name: np.array(self.mbs.GetObjectOutput(items.connector, exu.OutputVariableType.Force))
                for name, items in self.force_channels.items()}


def exudyn_name(kind: str, name: str) -> str:
    """The Exudyn name of a scene item: ``"KIND: NAME"``.

    Every item is named within its kind (``"hinge"``, ``"link"``,
    ``"static load"``, ``"excitation"``, ``"rig"``, and ``"scene"`` for the
    scene's own items such as the engine), so a user's name can never clash
    with the scene's own or with another kind's; within a kind,
    :class:`~workbook.model.case.Case` keeps the names unique.
    """
    return f"{kind}: {name}"


def marker_bodies(hinge: Hinge) -> tuple[str, str]:
    """The bodies on a hinge connector's markers 0 and 1: the pylon first
    when it is one of them, else ``(body_a, body_b)``."""
    return hinge.bodies if hinge.body_b != PYLON else hinge.bodies[::-1]


def scene_warnings(case: Case) -> list[str]:
    """What the case gives that the scene does not build, in words: what
    each hinge law says (a contact stiffness on a hinge without a gap), and
    rotors whose spin angular momenta cancel (no gyroscopic moment)."""
    warnings = [warning for law in hinge_laws.HINGE_LAWS for warning in law.warnings(case)]
    if case.rotors and case.effects.gyroscopics and not gyroscopics_built(case):
        warnings.append(f"rotors {', '.join(repr(r.name) for r in case.rotors)}: their spin angular momenta cancel "
                        f"(net {np.linalg.norm(net_angular_momentum(case)):.3g} kg m^2/s), so they exert no "
                        f"gyroscopic moment and none is built")
    return warnings


def loss_factors(case: Case) -> tuple[dict[str, Any], dict[str, float]]:
    """The loss factors the scene of *case* carries: those of the hinges
    (with hinge damping switched on; one value or three, per direction) and
    of the flexible links (with link damping switched on), each by name,
    only where > 0."""
    effects = case.effects
    hinges = {h.name: h.loss_factor for h in case.hinges if effects.hinge_damping and h.values("loss_factor").max() > 0}
    links = {link.name: link.loss_factor for link in case.links
             if effects.link_damping and case.link_is_flexible(link.name) and link.loss_factor > 0}
    return hinges, links


def _reduction_frequency(case: Case, excitation: SingleFrequencyExcitation | Simultaneous | None) -> float:
    """Highest excitation frequency a reduction must serve, Hz."""
    if excitation is not None:
        return excitation.frequency
    frequencies = [e.frequency for e in case.excitations]
    return max(frequencies) if frequencies else 0.0


def link_jobs(case: Case, excitation: SingleFrequencyExcitation | Simultaneous | None = None) -> dict:
    """The distinct reductions the links of *case* need, each with the links it serves.

    Parameters
    ----------
    case : Case
    excitation : RotatingForce or HarmonicForce, optional
        The run's excitation (default: the case's highest frequency).

    Returns
    -------
    dict of LinkJob to list of str
        Link names per job, in the case's order. Every job serves all the
        case's excitation frequencies and the run's own.
    """
    frequencies = tuple(sorted({e.frequency for e in case.excitations} | {_reduction_frequency(case, excitation)}))
    jobs: dict = {}
    for link in case.links:
        stiffening = case.effects.stress_stiffening != "off" and case.link_is_flexible(link.name)
        jobs.setdefault(LinkJob(link.model, case.link_modes(link.name), frequencies, stiffening), []).append(link.name)
    return jobs


def _served_frequency(case: Case, excitation: SingleFrequencyExcitation | Simultaneous | None, reduced: dict) -> float:
    """The frequency the scene's reductions serve, Hz: that the links were reduced for (a
    sweep's highest), else the excitation's (:func:`_reduction_frequency`)."""
    served = [link.decision.excitation_hz for link in reduced.values() if link.decision.excitation_hz]
    return max(served) if served else _reduction_frequency(case, excitation)


def _import_multibody(flexible: bool) -> None:
    """Import Exudyn, and its FEM module for flexible links, which the scene needs once the links are
    reduced: done while a link worker still runs, on the core another has left idle."""
    import exudyn  # noqa: F401

    if flexible:
        import exudyn.FEM  # noqa: F401


def reduce_links(case: Case, excitation: SingleFrequencyExcitation | Simultaneous | None = None,
                 progress: Callable[[int], None] | None = None) -> dict:
    """Reduce every link of *case* (cached on disk and in memory by :mod:`flexbodies`).

    Flexible links keep the modes their ``modes`` field asks for, judged at the
    excitation's frequency (default: the case's highest); rigid links need
    only their mass properties and take the static reduction. Each distinct
    link is reduced once for every excitation of the case (fixed-interface
    modes are nested: one eigen-solve up to the highest need, truncated per
    excitation), so the other excitations' runs load it; distinct links the
    cache lacks are reduced side by side in worker processes
    (:func:`workbook.scene.link_workers.reduce_in_workers`).

    Parameters
    ----------
    case : Case
    excitation : RotatingForce or HarmonicForce, optional
    progress : callable, optional
        Called with the number of links reduced so far, as it grows.

    Returns
    -------
    dict of str to flexbodies.ReducedBody

    Raises
    ------
    CaseError
        An excitation (or a link's cut-off) asks for more fixed-interface
        modes than a reduction keeps (:mod:`workbook.scene.mode_budget`).
    """
    frequency = _reduction_frequency(case, excitation)
    jobs = link_jobs(case, excitation)
    shown = 0

    def show(count: int) -> None:
        nonlocal shown
        if progress is not None and count > shown:
            shown = count
            progress(count)

    flexible = any(case.link_is_flexible(link.name) for link in case.links)
    reduce_in_workers(list(jobs), done=lambda job: show(shown + len(jobs[job])),
                      spare=lambda: _import_multibody(flexible))
    reduced = {}
    for job, names in jobs.items():
        try:
            per_frequency = job.reduce()
        except ModeBudgetExceeded as error:
            raise mode_budget_error(case, f"link {names[0]!r}", job.modes, error) from None
        for name in names:
            reduced[name] = per_frequency[job.excitations_hz.index(frequency)]
        show(len(reduced))
    return {link.name: reduced[link.name] for link in case.links}


def _load_scale(case: Case, excitation: SingleFrequencyExcitation | Simultaneous | None, link_mass: float) -> float:
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


def build_scene(case: Case, excitation: SingleFrequencyExcitation | Simultaneous | None = None, *,
                reduced: dict | None = None, exact_loss_factors: bool = False) -> Scene:
    """Build the Exudyn system of *case*.

    Parameters
    ----------
    case : Case
    excitation : RotatingForce or HarmonicForce, optional
        The excitation to apply (with the case's smooth start); None builds
        the static scene only.
    reduced : dict of str to flexbodies.ReducedBody, optional
        Reduced links from :func:`reduce_links` (computed when omitted).
    exact_loss_factors : bool
        False (for a time integration): the loss factors of hinges and links
        become their equivalent viscous damping at the excitation's
        frequency (:mod:`workbook.scene.structural_damping`; nothing without
        an excitation). True: they are left out of the scene, for the
        frequency domain to add them exactly as complex stiffness.

    Returns
    -------
    Scene
        The assembled system and its item numbers. The system is assembled;
        nothing has been solved.
    """
    import exudyn as exu

    eii = exu.itemInterface
    if reduced is None:
        reduced = reduce_links(case, excitation)
    system = exu.SystemContainer()
    mbs = system.AddSystem()

    ground = mbs.AddObject(eii.ObjectGround(visualization=eii.VObjectGround(show=False)))
    casing = None
    if case.engine.casing is None:
        engine = _add_engine(mbs, case)
    else:
        core, casing = add_flexible_engine(mbs, case, _served_frequency(case, excitation, reduced),
                                           lambda label: exudyn_name("scene", label))
        engine = EngineItems(*core)
    hinge_loss, link_loss = loss_factors(case)
    loss_hz = None if exact_loss_factors or excitation is None or not (hinge_loss or link_loss) \
        else excitation.frequency
    links = _add_links(mbs, case, reduced, link_loss, loss_hz)
    transducers = _add_transducers(mbs, case, ground) if case.rig_sensors_built else {}
    pins = _Pins(mbs, case, ground, engine, casing, links, transducers)
    hinges = {hinge.name: _add_hinge(mbs, case, hinge, pins, hinge.name in hinge_loss, loss_hz)
              for hinge in case.hinges}
    static_loads = _add_static_loads(mbs, case, engine, links, casing) if case.effects.preload else {}
    gyroscopics = _add_gyroscopics(mbs, case, engine) if gyroscopics_built(case) else None
    excitation_items = None if excitation is None else _add_excitation(mbs, case, engine, excitation)

    mbs.Assemble()
    link_mass = sum(link.mass for link in links.values())
    scene = Scene(case, system, mbs, ground, engine, links, reduced, hinges, static_loads, excitation_items,
                  _load_scale(case, excitation, link_mass), transducers=transducers,
                  gyroscopics=gyroscopics, loss_factor_hz=loss_hz, casing=casing)
    log.info("scene of %r: %d bodies, %d hinges, %d transducers, %d ODE2 coordinates", case.name,
             1 + len(links) + (casing is not None), len(hinges), len(transducers), mbs.systemData.ODE2Size())
    return scene


def _viscous(loss_hz: float | None, loss_factor: float, stiffness: float) -> float:
    """The equivalent viscous damping built for a loss factor at *loss_hz*, N s/m (0 when none is built)."""
    return 0.0 if loss_hz is None else equivalent_viscous_damping(loss_factor, stiffness, loss_hz)


def _add_links(mbs, case: Case, reduced: dict, link_loss: dict[str, float], loss_hz: float | None) -> dict:
    """Add every link of *case* as a reduced body (flexible or rigid); their items by link name."""
    from flexbodies import add_link_to_exudyn

    links = {}
    damped = case.effects.link_damping
    for link in case.links:
        optional = {} if link.spin_frequency_hz is None else {"spin_frequency_hz": link.spin_frequency_hz}
        links[link.name] = add_link_to_exudyn(
            mbs, reduced[link.name], link.end_a, link.end_b,
            flexible=case.link_is_flexible(link.name), bore_axis=link.bore_axis,
            stiffness_damping=(link.stiffness_damping if damped else 0.0)
            + _viscous(loss_hz, link_loss.get(link.name, 0.0), 1.0),
            mass_damping=link.mass_damping if damped else 0.0,
            modal_damping_ratio=link.modal_damping if damped else 0.0, name=exudyn_name("link", link.name),
            **optional)
    return links


@dataclass
class _Pins:
    """The bodies a hinge can join, to find (or add) the marker of a pin."""

    mbs: Any
    case: Case
    ground: int
    engine: EngineItems
    casing: Any
    links: dict
    transducers: dict

    def marker(self, body_name: str, position) -> int:
        """The marker of body *body_name* at pin *position* (m)."""
        import exudyn as exu

        eii = exu.itemInterface
        if body_name == PYLON:
            if self.transducers:
                return next(items.markers[1] for items in self.transducers.values()
                            if _same_point(items.position, position))
            return self.mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=self.ground, localPosition=list(position)))
        if body_name == ENGINE and self.casing is not None:
            return self.casing.eye_marker(position)
        if body_name == ENGINE:
            local = np.subtract(position, self.case.engine.center_of_mass)
            return self.mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=self.engine.body, localPosition=list(local)))
        eye = self.case.link_map[body_name].eye_at(position)
        return self.links[body_name].marker_a if eye == "a" else self.links[body_name].marker_b


def _add_hinge(mbs, case: Case, hinge: Hinge, pins: _Pins, lossy: bool, loss_hz: float | None) -> HingeItems:
    """Add *hinge* as a Cartesian spring-damper with its law and force sensor.

    *lossy*: the hinge's loss factors are built (as viscous damping at
    *loss_hz*, or as the law damps them, the clearance law on its tangent
    stiffness). The law is the first of :mod:`workbook.scene.hinge_laws` that
    applies, else the plain spring-damper.
    """
    import exudyn as exu
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    eii = exu.itemInterface
    first, second = marker_bodies(hinge)
    markers = (pins.marker(first, hinge.position), pins.marker(second, hinge.position))
    hinge_law = hinge_laws.law_of(case, hinge)
    etas = hinge.values("loss_factor") if lossy else np.zeros(3)
    built = hinge_law.connector(case, hinge, hinge.values("stiffness"),
                                hinge.values("damping") if case.effects.hinge_damping else np.zeros(3),
                                np.array([_viscous(loss_hz, eta, 1.0) for eta in etas]))
    connector = mbs.AddObject(eii.ObjectConnectorCartesianSpringDamper(
        name=exudyn_name("hinge", hinge.name), markerNumbers=list(markers), stiffness=list(built.stiffness),
        damping=list(built.damping), visualization=eii.VObjectConnectorCartesianSpringDamper(show=False)))
    law = None
    if built.spring_force is not None:
        law = CreateSymbolicUserFunction(mbs, built.spring_force, "springForceUserFunction", connector)
        mbs.SetObjectParameter(connector, "springForceUserFunction", law)
    sensor = mbs.AddSensor(eii.SensorObject(
        name=exudyn_name("hinge force", hinge.name), objectNumber=connector, storeInternal=True, writeToFile=False,
        outputVariableType=exu.OutputVariableType.Force))
    return HingeItems(connector, sensor, markers, hinge.on_pylon, hinge_law, law)


def _add_excitation(mbs, case: Case, engine: EngineItems,
                    excitation: SingleFrequencyExcitation | Simultaneous) -> ExcitationItems:
    """Add the excitation's forces on the engine (one load per plane), each with its user function."""
    import exudyn as exu
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    eii = exu.itemInterface
    force_markers, loads, functions = [], [], []
    parts = ExcitationSignal.at_points(excitation, case.analysis.ramp_periods)
    for k, (position, part) in enumerate(parts, start=1):
        force_markers.append(mbs.AddMarker(eii.MarkerBodyPosition(
            bodyNumber=engine.body, localPosition=list(np.subtract(position, case.engine.center_of_mass)))))
        label = excitation.name if len(parts) == 1 else f"{excitation.name} {k}"
        loads.append(mbs.AddLoad(eii.LoadForceVector(name=exudyn_name("excitation", label),
                                                     markerNumber=force_markers[-1], loadVector=[0.0] * 3)))
        functions.append(CreateSymbolicUserFunction(mbs, part.exudyn_user_function(), "loadVectorUserFunction",
                                                    loads[-1]))
        mbs.SetLoadParameter(loads[-1], "loadVectorUserFunction", functions[-1])
    resultant = None if isinstance(excitation, Simultaneous) else ExcitationSignal.of(excitation,
                                                                                     case.analysis.ramp_periods)
    return ExcitationItems(excitation.name, tuple(force_markers), tuple(loads), resultant, tuple(functions),
                           excitation)


def _same_point(a, b) -> bool:
    """True if points *a* and *b* are the same pin (within the case's point tolerance)."""
    return float(np.linalg.norm(np.subtract(a, b))) <= POINT_TOLERANCE


def _add_transducers(mbs, case: Case, ground: int) -> dict[str, TransducerItems]:
    """One force transducer per pylon pin: a point mass at the pin on a
    spring-damper from the ground (no gravity on it: a rig zeroes its
    transducers with their fittings mounted)."""
    import exudyn as exu

    eii = exu.itemInterface
    rig = case.test_rig
    assert rig is not None
    transducers = {}
    for position, carried in case.pylon_pins():
        name = transducer_name(carried)
        node = mbs.AddNode(eii.NodePoint(name=exudyn_name("rig", name), referenceCoordinates=list(position),
                                         visualization=eii.VNodePoint(show=False)))
        body = mbs.AddObject(eii.ObjectMassPoint(name=exudyn_name("rig", f"{name} mass"), mass=rig.mass, nodeNumber=node,
                                                 visualization=eii.VObjectMassPoint(show=False)))
        markers = (mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=ground, localPosition=list(position))),
                   mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=node)))
        connector = mbs.AddObject(eii.ObjectConnectorCartesianSpringDamper(
            name=exudyn_name("rig", name), markerNumbers=list(markers), stiffness=list(rig.stiffness),
            damping=list(rig.damping),
            visualization=eii.VObjectConnectorCartesianSpringDamper(show=False)))
        sensor = mbs.AddSensor(eii.SensorObject(
            name=exudyn_name("rig force", name), objectNumber=connector, storeInternal=True, writeToFile=False,
            outputVariableType=exu.OutputVariableType.Force))
        transducers[name] = TransducerItems(node, body, connector, sensor, markers, position, tuple(carried))
    return transducers


def _add_engine(mbs, case: Case) -> EngineItems:
    import exudyn as exu

    eii = exu.itemInterface
    inertia = case.engine.inertia_matrix
    node = mbs.AddNode(eii.NodeRigidBodyRxyz(
        name=exudyn_name("scene", "engine"), referenceCoordinates=list(case.engine.center_of_mass) + [0.0, 0.0, 0.0],
        visualization=eii.VNodeRigidBodyRxyz(show=False)))
    body = mbs.AddObject(eii.ObjectRigidBody(
        name=exudyn_name("scene", "engine"), nodeNumber=node, mass=case.engine.mass,
        inertia=[inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[1, 2], inertia[0, 2], inertia[0, 1]],
        visualization=eii.VObjectRigidBody(show=False)))
    marker = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=body, localPosition=[0.0, 0.0, 0.0]))
    return EngineItems(node, body, marker)


def _add_static_loads(mbs, case: Case, engine: EngineItems, links: dict,
                      casing: CasingItems | None = None) -> dict[str, list]:
    """Static loads: forces and moments on the engine (its core), gravity on every body."""
    import exudyn as exu

    eii = exu.itemInterface
    loads = {}
    for load in case.static_loads:
        if isinstance(load, PointForce):
            local = np.subtract(load.point, case.engine.center_of_mass)
            point = mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=engine.body, localPosition=list(local)))
            loads[load.name] = [mbs.AddLoad(eii.LoadForceVector(name=exudyn_name("static load", load.name), markerNumber=point,
                                                               loadVector=list(load.force)))]
        elif isinstance(load, PointMoment):
            loads[load.name] = [mbs.AddLoad(eii.LoadTorqueVector(name=exudyn_name("static load", load.name),
                                                                markerNumber=engine.marker_rigid,
                                                                loadVector=list(load.moment)))]
        else:
            bodies = [engine.body] + ([casing.casing.body] if casing else []) + [link.body for link in links.values()]
            loads[load.name] = [
                mbs.AddLoad(eii.LoadMassProportional(
                    markerNumber=mbs.AddMarker(eii.MarkerBodyMass(bodyNumber=body)),
                    loadVector=list(load.acceleration)))
                for body in bodies]
    return loads


#: Net spin angular momentum, relative to the largest rotor's, below which
#: the rotors' gyroscopic moments cancel and are not built.
CANCELLED_MOMENTUM = 1e-9


def net_angular_momentum(case: Case) -> np.ndarray:
    """Total spin angular momentum of the case's rotors in engine coordinates, kg m^2/s."""
    return sum((np.asarray(rotor.angular_momentum, dtype=float) for rotor in case.rotors), np.zeros(3))


def gyroscopics_built(case: Case) -> bool:
    """True if *case* gives rotors, asks for their gyroscopic moments, and
    their net spin angular momentum does not cancel (the moment is linear in
    it: counter-rotating rotors of equal momentum exert none)."""
    if not (case.rotors and case.effects.gyroscopics):
        return False
    largest = max(float(np.linalg.norm(rotor.angular_momentum)) for rotor in case.rotors)
    return float(np.linalg.norm(net_angular_momentum(case))) > CANCELLED_MOMENTUM * largest


def exudyn_gyroscopic_function(momentum):
    """A ``forceUserFunction`` for an ``ObjectGenericODE2`` on the engine's
    ``NodeRigidBodyRxyz``: the gyroscopic moment of spinning rotors.

    Rotors of total spin angular momentum ``h0`` (engine coordinates,
    ``sum(Ip Omega a)``) turn with the engine, ``h = A h0``, and exert on it
    the moment ``M = -omega x h = h x omega``. With Exudyn's Tait-Bryan
    angles ``phi`` (``A = Rx(phi0) Ry(phi1) Rz(phi2)``) the global angular
    velocity is ``omega = G phi'``, the columns of G being ``e_x``,
    ``Rx e_y`` and ``Rx Ry e_z``, and the generalised force on the angles is
    ``G^T M`` (none on the translations). Exact for any rotation; zero at rest
    (the static solves), and its velocity derivative is the gyroscopic
    matrix ``-Ip Omega [a]x`` of the linearised equations.

    Parameters
    ----------
    momentum : 3 floats
        ``h0``, kg m^2/s.

    Returns
    -------
    callable
        ``f(mbs, t, itemNumber, q, q_t)`` for
        ``exudyn.advancedUtilities.CreateSymbolicUserFunction``.
    """
    import exudyn as exu

    esym = exu.symbolic  # type: ignore[attr-defined]  # the stubs omit the submodule
    hx, hy, hz = (float(h) for h in momentum)

    def gyroscopic_force(mbs, t, itemNumber, q, q_t):
        # the recording passes q and q_t empty: give them the node's six coordinates
        q.SetVector([0.0] * 6)
        q_t.SetVector([0.0] * 6)
        c0, s0 = esym.cos(q[3]), esym.sin(q[3])
        c1, s1 = esym.cos(q[4]), esym.sin(q[4])
        c2, s2 = esym.cos(q[5]), esym.sin(q[5])
        columns = ((1.0, 0.0, 0.0), (0.0, c0, s0), (s1, -s0 * c1, c0 * c1))
        omega = [columns[0][i] * q_t[3] + columns[1][i] * q_t[4] + columns[2][i] * q_t[5] for i in range(3)]
        x, y, z = c2 * hx - s2 * hy, s2 * hx + c2 * hy, hz                 # Rz h0
        x, z = c1 * x + s1 * z, -s1 * x + c1 * z                            # Ry
        h = (x, c0 * y - s0 * z, s0 * y + c0 * z)                           # Rx
        moment = (h[1] * omega[2] - h[2] * omega[1], h[2] * omega[0] - h[0] * omega[2],
                  h[0] * omega[1] - h[1] * omega[0])
        zero = esym.Real(0.0)
        return [zero, zero, zero] + [sum((column[i] * moment[i] for i in range(3)), zero) for column in columns]

    return gyroscopic_force


def _add_gyroscopics(mbs, case: Case, engine: EngineItems) -> GyroscopicItems:
    """The rotors' gyroscopic moment on the engine: one ``ObjectGenericODE2``
    on the engine node for all rotors (the moment is linear in the momentum;
    one object per rotor cost about 20 us per step each)."""
    import exudyn as exu
    from exudyn.advancedUtilities import CreateSymbolicUserFunction

    eii = exu.itemInterface
    momentum = net_angular_momentum(case)
    item = mbs.AddObject(eii.ObjectGenericODE2(name=exudyn_name("scene", "rotor gyroscopics"), nodeNumbers=[engine.node],
                                               massMatrix=np.zeros((6, 6)),
                                               visualization=eii.VObjectGenericODE2(show=False)))
    function = CreateSymbolicUserFunction(mbs, exudyn_gyroscopic_function(momentum), "forceUserFunction", item)
    mbs.SetObjectParameter(item, "forceUserFunction", function)
    return GyroscopicItems(tuple(rotor.name for rotor in case.rotors), momentum, item, function)
