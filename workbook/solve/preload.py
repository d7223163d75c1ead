"""Static preload: mechanism check, static solve, equilibrium check.

1. The scene is linearised in its reference configuration; a mode with
   (near) zero frequency is a free motion and the run stops with
   :class:`MechanismError` naming it (a ball-jointed mount with a link
   missing is a mechanism, and a static solve would fail or return absurd
   forces). Only stiffness restrains a motion, so the check solves
   ``K x = w^2 M x`` without the rotors' gyroscopic coupling.
2. The static loads are solved for (Newton, tolerance scaled to the loads),
   and the solution becomes the initial state of the dynamic run. A solve
   that fails is tried again in :data:`LOAD_STEPS` adaptive load steps; if
   that fails too, :class:`EquilibriumError` says how much of the loads was
   carried (a limit load: buckling or tipping) or that even a small share
   was not (a stiffness beyond double precision), with Exudyn's own output
   as its ``detail``.
3. The scene is linearised again about the preloaded equilibrium, where the
   loads add geometric stiffness to the rigid-body motion of the engine and
   the links (a compressed link pushes sideways as it turns); the bending of
   a compressed flexible link is checked against its buckling load by the
   stress-stiffening stage that follows
   (:mod:`workbook.solve.stress_stiffening`). A negative stiffness there stops the run with
   :class:`UnstablePreloadError` (the preload buckles a link or tips the
   mount) naming the motion, the loads and the compressed links; a free
   motion there is a :class:`MechanismError` as in 1.
4. The pylon force - the vector sum of the pylon-side hinge forces, or of
   the test-rig transducer forces when they are built - must equal the
   applied static loads (forces on the engine plus the weight of every body;
   the transducers carry no weight, see
   :class:`~workbook.model.case.ForceTransducers`) to ``equilibrium_tolerance``
   of the loads, plus the force a position round-off of the geometry puts
   on the stiffest hinge (:func:`geometry_roundoff_force`), or the run stops
   with :class:`EquilibriumError`.
"""
from __future__ import annotations

import logging
import re
from dataclasses import dataclass

import numpy as np

from workbook.answers.isolation import pylon_sum
from workbook.answers.results import PYLON_SUM
from workbook.errors import EquilibriumError, MechanismError, UnstablePreloadError, interruption
from workbook.model.case import DIRECTIONS, ENGINE, Gravity, PointForce, PointMoment
from workbook.scene.build import Scene, marker_bodies
from workbook.solve.guards import solver_output
from workbook.solve.modes import FREE_FREQUENCY_HZ, Mode, free_motions, linearize, modes_of, unstable_modes

__all__ = ["Preload", "applied_static_force", "check_mechanism", "check_preloaded_stability", "link_compression",
           "static_failure_message", "LOAD_STEPS",
           "check_equilibrium", "solve_preload", "spring_roundoff_force", "stiffest_spring", "ROUNDOFF_MARGIN",
           "geometry_roundoff_force", "GEOMETRY_PRECISION"]

log = logging.getLogger(__name__)

#: Newton tolerances stay this many times above the round-off of the stiffest
#: spring's force (:func:`spring_roundoff_force`).
ROUNDOFF_MARGIN = 10.0
#: Relative precision of the hinge marker positions: a link eye placed
#: through the link's Euler parameters or a mesh lies up to about 1e-12 of
#: its distance from the origin off the hinge point (1.6e-12 m at 1.6 m on
#: the reference mount); kept with a margin of 100.
GEOMETRY_PRECISION = 1e-10
#: A static solve that fails in one step is tried again in this many
#: (adaptive) load steps.
LOAD_STEPS = 20
#: A stepped static solve that failed beyond this share of the loads met a
#: limit load (buckling or tipping); below it, Newton could not converge at all.
LIMIT_LOAD_SHARE = 0.5


@dataclass(frozen=True)
class Preload:
    """The preloaded equilibrium.

    Attributes
    ----------
    hinge_forces : dict of str to ndarray, shape (3,)
        Static force of each force channel (:attr:`Scene.force_channels`):
        of each hinge on the pylon (pylon-side hinges) or on the hinge's
        first body, and of each test-rig transducer on the ground, N.
    pylon_force : ndarray, shape (3,)
        Vector sum over the pylon channels (:attr:`Scene.pylon_channels`):
        the force on the pylon, N.
    applied_force : ndarray, shape (3,)
        Sum of the applied static loads (forces and weights), N.
    relative_mismatch : float
        ``|pylon_force - applied_force| / |applied_force|``.
    solved : bool
        False when the case has no preload (nothing was solved).
    stiffening : workbook.solve.stress_stiffening.StressStiffening or None
        What the stress-stiffening stage did (None before it ran).
    """

    hinge_forces: dict
    pylon_force: np.ndarray
    applied_force: np.ndarray
    relative_mismatch: float
    solved: bool
    stiffening: object = None

    def to_pandas(self):
        """The static force of each channel, N, one row per channel; pylon sum last.

        Returns
        -------
        pandas.DataFrame
            Index: channel (hinge or transducer); columns ``Fx N``, ``Fy N``, ``Fz N``.
        """
        import pandas as pd

        forces = {**self.hinge_forces, PYLON_SUM: self.pylon_force}
        return pd.DataFrame.from_dict({k: list(v) for k, v in forces.items()}, orient="index",
                                      columns=[f"F{d} N" for d in DIRECTIONS]).rename_axis("hinge")


def applied_static_force(scene: Scene) -> np.ndarray:
    """Resultant of the constant forces applied in the scene's Exudyn system, N.

    Read from the system itself, so that loads a script adds to ``scene.mbs``
    count too: every ``LoadForceVector`` without a user function and every
    ``LoadMassProportional`` times its body's mass. Loads with user functions
    (the excitation, paused during the static solve) do not count.

    Raises
    ------
    ValueError
        For a mass-proportional load on a body whose mass is unknown.
    """
    mbs = scene.mbs
    masses = scene.body_masses()
    total = np.zeros(3)
    for index in range(mbs.systemData.NumberOfLoads()):
        load = mbs.GetLoad(index)
        if load["loadType"] not in ("ForceVector", "MassProportional") or load["loadVectorUserFunction"] != 0:
            continue
        vector = np.asarray(load["loadVector"], dtype=float)
        if load["loadType"] == "ForceVector":
            total += vector
            continue
        body = mbs.GetMarker(load["markerNumber"])["bodyNumber"]
        mass = masses.get(body, mbs.GetObject(body).get("mass"))
        if mass is None:
            raise ValueError(f"load {load['name']!r}: mass of body {body} unknown for the equilibrium check")
        total += mass * vector
    return total


def stiffest_spring(scene: Scene) -> float:
    """The largest stiffness of the scene's springs: the hinges, the rig's
    transducers and a flexible engine's bearings, N/m."""
    case = scene.case
    stiffness = [h.largest_stiffness for h in case.hinges]
    if scene.transducers:
        assert case.test_rig is not None
        stiffness += list(case.test_rig.stiffness)
    if case.engine.casing is not None:
        stiffness += list(case.engine.casing.bearing_stiffness)
    return max(stiffness, default=0.0)


def spring_roundoff_force(scene: Scene) -> float:
    """Force the static Newton iteration can resolve on the stiffest spring (:func:`stiffest_spring`), N.

    A spring force ``k (p1 - p0)`` is computed from positions of size
    ``|p|``, known to the machine epsilon ``eps``: its round-off is
    ``k eps |p|``, which a Newton tolerance must not undercut (a 1e12 N/m
    transducer 1.7 m from the origin: 4e-4 N, ten times the default
    tolerance on the reference mount). Returned with a margin of
    :data:`ROUNDOFF_MARGIN`.
    """
    reach = max((float(np.abs(h.position).max()) for h in scene.case.hinges), default=0.0)
    return ROUNDOFF_MARGIN * stiffest_spring(scene) * np.finfo(float).eps * max(reach, 1.0)


def geometry_roundoff_force(scene: Scene) -> float:
    """Force that the round-off of the hinge marker positions puts on the
    stiffest hinge, N.

    Two markers of a hinge built at the same point are apart by up to
    :data:`GEOMETRY_PRECISION` times the hinge's distance from the origin,
    so an unloaded mount carries pin forces of that size (4 to 30 µN on
    the reference mount: 2e7 N/m across 1e-13 to 1.6e-12 m). They are no
    mismatch of the equilibrium.

    Returns
    -------
    float
        ``GEOMETRY_PRECISION * k_max * max(reach, 1 m)``, with ``k_max`` the
        stiffest hinge stiffness (N/m; a rig transducer is in series with
        a hinge, so it does not count) and ``reach`` the farthest hinge's
        largest coordinate (m).
    """
    hinges = scene.case.hinges
    reach = max((float(np.abs(h.position).max()) for h in hinges), default=0.0)
    return GEOMETRY_PRECISION * max((h.largest_stiffness for h in hinges), default=0.0) * max(reach, 1.0)


def check_mechanism(scene: Scene) -> list[Mode]:
    """Linearise the scene as built and stop if it has free motions.

    Returns
    -------
    list of Mode
        All modes of the unloaded scene.

    Raises
    ------
    MechanismError
        Naming each free motion.
    """
    # a clearance restrains once its gap closes: check with the gaps closed
    with scene.gaps_closed():
        modes = modes_of(linearize(scene, exact=False), gyroscopic=False)
    _stop_on_free_motions(scene, modes)
    return modes


def _stop_on_free_motions(scene: Scene, modes: list[Mode]) -> None:
    free = free_motions(modes)
    if free:
        case = scene.case
        hinged = {(body, case.link_map[body].eye_at(h.position)) for h in case.hinges for body in h.bodies
                  if body in case.link_map}
        loose = [f"link {link.name!r} eye {eye.upper()} at {getattr(link, 'end_' + eye)} m"
                 for link in case.links for eye in ("a", "b") if (link.name, eye) not in hinged]
        raise MechanismError(case.name, [mode.description for mode in free], loose, _soft_hinges(scene))


def _soft_hinges(scene: Scene) -> list[str]:
    """The hinges with a stiffness above 0 on which the lighter body they join would alone move below
    :data:`~workbook.solve.modes.FREE_FREQUENCY_HZ`, each with that stiffness (N/m)."""
    masses = {name: link.mass for name, link in scene.links.items()}
    masses[ENGINE] = scene.case.engine.mass
    limit = (2 * np.pi * FREE_FREQUENCY_HZ) ** 2
    soft = []
    for hinge in scene.case.hinges:
        mass = min(masses.get(body, np.inf) for body in hinge.bodies)  # the pylon holds still
        stiffness = hinge.values("stiffness")
        too_soft = stiffness[(stiffness > 0) & (stiffness < limit * mass)]
        if too_soft.size:
            soft.append(f"{hinge.name!r} ({too_soft.min():.3g} N/m)")
    return soft


def link_compression(scene: Scene, forces: dict) -> dict:
    """Axial compression of every link from the hinge forces on its eyes, N
    (negative: tension).

    Parameters
    ----------
    scene : Scene
    forces : dict of str to ndarray, shape (3,)
        Force of each hinge on its marker-0 body (:meth:`Scene.hinge_forces`), N;
        complex hinge force phasors give the axial force phasors.
    """
    case = scene.case
    compression: dict = {link.name: 0.0 for link in case.links}
    for hinge in case.hinges:
        first = marker_bodies(hinge)[0]
        for body in hinge.bodies:
            if body not in compression:
                continue
            link = case.link_map[body]
            axis = np.subtract(link.end_b, link.end_a) / np.linalg.norm(np.subtract(link.end_b, link.end_a))
            on_link = forces[hinge.name] if body == first else -forces[hinge.name]
            # eye a pushed towards b, or eye b towards a: compression (half from each eye)
            sign = 1.0 if link.eye_at(hinge.position) == "a" else -1.0
            compression[body] += 0.5 * sign * (on_link @ axis)
    return compression


def _load_listing(scene: Scene) -> str:
    parts = []
    for load in scene.case.static_loads:
        if isinstance(load, PointForce):
            parts.append(f"{load.name!r} {np.linalg.norm(load.force):.4g} N along "
                         f"{np.round(np.asarray(load.force) / np.linalg.norm(load.force), 3).tolist()}")
        elif isinstance(load, PointMoment):
            parts.append(f"{load.name!r} {np.linalg.norm(load.moment):.4g} N m")
        elif isinstance(load, Gravity):
            parts.append(f"{load.name!r} {np.linalg.norm(load.acceleration):.4g} m/s^2")
    return ", ".join(parts)


def check_preloaded_stability(scene: Scene, forces: dict) -> list[Mode]:
    """Linearise the scene about its preloaded state (geometric stiffness of
    the loads for the bodies' rigid-body motion included; not that of a
    flexible link's own bending, see :mod:`workbook.solve.stress_stiffening`)
    and stop if it is unstable or free there.

    Parameters
    ----------
    scene : Scene
        Solved for its preload (the initial state is the equilibrium).
    forces : dict of str to ndarray
        Its hinge forces (:meth:`Scene.hinge_forces`), N.

    Returns
    -------
    list of Mode
        The modes of ``K x = w^2 M x`` at the preload.

    Raises
    ------
    UnstablePreloadError
        A direction with negative stiffness: the preload buckles a link or
        tips the mount.
    MechanismError
        A free motion at the preload.
    """
    modes = modes_of(linearize(scene, exact=False), gyroscopic=False)
    unstable = unstable_modes(modes)
    if unstable:
        case = scene.case
        compressed = sorted(((force, name) for name, force in link_compression(scene, forces).items()
                             if force > 0), reverse=True)
        listing = "; ".join(
            f"{mode.description} (w^2 = {mode.omega_squared:.4g} 1/s^2; kinetic energy in "
            + ", ".join(f"{body} {100 * share:.0f} %" for body, share in
                        sorted({ENGINE: mode.engine_share, **mode.body_shares}.items(),
                               key=lambda item: -item[1]) if share >= 0.05) + ")"
            for mode in unstable)
        links = (", ".join(f"{name!r} {force / 1e3:.4g} kN" for force, name in compressed[:4])
                 if compressed else "none")
        raise UnstablePreloadError(
            f"case {case.name!r}: the preload makes the mount unstable: at the preloaded equilibrium the "
            f"stiffness is negative in {len(unstable)} direction(s): {listing}. The static loads "
            f"({_load_listing(scene)}) buckle a compressed link or tip the mount; links in compression: "
            f"{links}. Reduce or redirect the load, or stiffen or rearrange the links that carry it in "
            f"compression.", [mode.omega_squared for mode in unstable])
    _stop_on_free_motions(scene, modes)
    return modes


def solve_preload(scene: Scene) -> Preload:
    """Check for mechanisms, solve the static equilibrium, check it.

    The solution is written to the scene's initial values, so a following
    dynamic run starts preloaded.

    Raises
    ------
    MechanismError
        The mount has a free motion, unloaded or at the preload.
    UnstablePreloadError
        The preloaded equilibrium is unstable.
    EquilibriumError
        The static solve failed, or the pylon force (pylon-side hinges or
        rig transducers) differs from the applied static loads by more than
        the case's tolerance.
    """
    import exudyn as exu

    check_mechanism(scene)
    case = scene.case
    tolerance = case.analysis.equilibrium_tolerance
    if case.effects.preload and scene.static_loads:
        settings = exu.SimulationSettings()
        settings.solution.file.write = False
        settings.solution.sensors.writePeriod = 1.0
        # Newton a thousand times tighter than the check (not below round-off,
        # neither of the loads nor of the stiffest spring's force)
        relative = max(1e-3 * tolerance, 1e-12)
        settings.staticSolver.newton.absoluteTolerance = max(relative * scene.load_scale,
                                                             spring_roundoff_force(scene))
        settings.staticSolver.newton.relativeTolerance = relative
        # keep the tolerance relative to the loads: a first Newton step that
        # overshoots (a closed clearance gap) must not loosen it
        settings.staticSolver.newton.adaptInitialResidual = False
        settings.staticSolver.verboseMode = 0
        _solve_static(scene, settings)
    forces = scene.hinge_forces()
    if case.effects.preload and scene.static_loads:
        check_preloaded_stability(scene, forces)
    pylon = pylon_sum(forces, scene.pylon_channels)
    applied = applied_static_force(scene)
    mismatch = check_equilibrium(case.name, pylon, applied, tolerance, scene.load_scale,
                                 roundoff=geometry_roundoff_force(scene))
    log.info("preload of %r: pylon force %s N, relative mismatch %.1e", case.name, np.round(pylon, 1), mismatch)
    return Preload(forces, pylon, applied, mismatch, bool(case.effects.preload and scene.static_loads))


def _attempt(scene: Scene, settings) -> tuple[bool, str]:
    """One static solve; whether it converged, and what Exudyn printed."""
    import exudyn as exu

    with solver_output() as output, scene.excitation_paused():
        try:
            converged = bool(scene.mbs.SolveStatic(settings, updateInitialValues=True))
        except exu.SolverError as error:
            interrupt = interruption(error)      # Ctrl-C or SIGTERM while Exudyn solved: not a failed solve
            if interrupt is not None:
                raise interrupt from None
            converged = False
    return converged, output.getvalue()


def _solve_static(scene: Scene, settings) -> None:
    """Solve the static loads: in one step, else in up to :data:`LOAD_STEPS`
    adaptive load steps; if that fails too, say why in plain words."""
    converged, said = _attempt(scene, settings)
    if converged:
        return
    settings.staticSolver.numberOfLoadSteps = LOAD_STEPS
    settings.staticSolver.verboseMode = 1        # reports the load factor reached
    converged, stepped = _attempt(scene, settings)
    if converged:
        log.info("case %r: the static loads needed %d load steps", scene.case.name, LOAD_STEPS)
        return
    factors = re.findall(r"load factor = ([-+0-9.eE]+)", stepped)
    reached = float(factors[-1]) if factors else 0.0
    raise EquilibriumError(static_failure_message(scene, reached, settings.staticSolver.newton.absoluteTolerance),
                           detail=said + stepped)


def static_failure_message(scene: Scene, reached: float, tolerance: float) -> str:
    """Why the static solve failed, in plain words, with advice.

    Parameters
    ----------
    scene : Scene
    reached : float
        Largest share of the static loads for which Newton still converged
        when they were applied in steps (0 to 1).
    tolerance : float
        Newton's absolute tolerance, N.
    """
    case = scene.case
    stiffest = max(h.largest_stiffness for h in case.hinges)
    where = f"case {case.name!r}: the static solve failed"
    if reached >= LIMIT_LOAD_SHARE:
        return (f"{where}: applied in steps, the static loads ({_load_listing(scene)}) could be carried up to "
                f"{100 * reached:.3g} % of their value and no further: there the mount reaches its limit load, "
                f"where the preload buckles a compressed link or tips the mount. Reduce or redirect the loads, "
                f"or stiffen or rearrange the links that carry them in compression.")
    return (f"{where}: Newton's iteration did not converge even on {100 * reached:.2g} % of the static loads. "
            f"Likely cause: a stiffness too large for double precision: the stiffest hinge has {stiffest:.3g} N/m, "
            f"whose force is known only to {spring_roundoff_force(scene) / ROUNDOFF_MARGIN:.2g} N at these "
            f"coordinates; summed over the mount this noise keeps the residual above Newton's tolerance "
            f"({tolerance:.2g} N). Lower the stiffest hinge stiffnesses: a hinge far stiffer than the link it "
            f"holds acts as rigid anyway (on the reference mount 1e12 N/m still solves, 1e13 N/m does not).")


def check_equilibrium(case_name: str, pylon_force, applied_force, tolerance: float, load_scale: float, *,
                      roundoff: float = 0.0) -> float:
    """Compare the pylon force with the applied static loads.

    The check passes when ``|pylon - applied| <= tolerance * reference +
    roundoff``: a mount without static loads carries only the round-off
    pin forces of its geometry, which a small excitation's scale (1 N:
    a limit of 1 µN) must not call a mismatch.

    Parameters
    ----------
    case_name : str
    pylon_force, applied_force : array_like, shape (3,)
        N.
    tolerance : float
        Largest relative mismatch.
    load_scale : float
        Reference force when no static force is applied, N.
    roundoff : float
        Mismatch the geometry's round-off explains
        (:func:`geometry_roundoff_force`), N.

    Returns
    -------
    float
        The relative mismatch ``|pylon - applied| / reference``.

    Raises
    ------
    EquilibriumError
        If the mismatch exceeds the tolerance.
    """
    pylon, applied = np.asarray(pylon_force, dtype=float), np.asarray(applied_force, dtype=float)
    reference = np.linalg.norm(applied) if np.linalg.norm(applied) > 0 else load_scale
    mismatch = float(np.linalg.norm(pylon - applied) / reference)
    allowed = tolerance + roundoff / reference
    if not mismatch <= allowed:
        allowed_text = f"{tolerance:.0e}" if roundoff == 0 else (
            f"{allowed:.2e}: the tolerance {tolerance:.0e} plus the geometry's round-off of {roundoff:.2g} N")
        raise EquilibriumError(
            f"case {case_name!r}: the pylon-side hinge forces sum to {np.round(pylon, 3).tolist()} N but the "
            f"applied static loads sum to {np.round(applied, 3).tolist()} N (relative mismatch {mismatch:.2e} "
            f"> {allowed_text}); the preload is not trustworthy")
    return mismatch
