"""The linear mount as a fast function of its design.

:meth:`LinearMount.prepare` runs the case once through the Exudyn pipeline
(reductions, preload, stress stiffening, linearisation) for each excitation
item and keeps the scene as a :class:`~workbook.design.expansion.SceneExpansion`.
:meth:`LinearMount.evaluate` then answers a design - the case with other
hinge stiffness, damping or loss factors (per hinge and per direction),
test-rig transducer springs, engine mass and inertia, a flexible engine
casing's Young's modulus, or excitation frequencies and amplitudes - in
NumPy alone: the preload equilibrium by
Newton (with the stress-stiffening passes of
:mod:`workbook.solve.stress_stiffening`), the linearisation at it, and one
complex solve per frequency. Its answers equal :func:`workbook.run_case`'s
(``tests/test_linear_mount.py``). A change the expansion cannot follow (a
link's section or material, the geometry, the effects, a mode selection the
new frequency changes) raises :class:`~workbook.errors.OutsideDesignModel`,
naming the change: such a design needs a new preparation.

A flexible casing's reduced stiffness scales with its modulus E exactly (its
Craig-Bampton basis does not change), and its modal damping
``2 zeta w_i`` with sqrt(E): a design at another E adds ``(E / E_0 - 1) K_r``
and ``(sqrt(E / E_0) - 1) D_r`` to the prepared casing's modal coordinates.
Only the casing's mode selection may change with E or the frequency (the
low-frequency rule and a cut-off judge its frequencies, which scale with
sqrt(E)): a design that changes the number of modes kept is refused.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg as sla

from workbook.answers.results import ExcitationResult, MountResult
from workbook.design.assembly import (
    ChannelSprings,
    Projection,
    StateLoads,
    projection,
    rest_matrices,
    static_state,
    tangent_stiffness,
    total,
    without_normal,
)
from workbook.design.expansion import SceneExpansion, expand_scene
from workbook.errors import BucklingError, OutsideDesignModel, ResonanceError, UnstablePreloadError
from workbook.model.case import Case, Engine, Gravity, Link, Simultaneous, SingleFrequencyExcitation, Sweep
from workbook.scene.build import Scene, loss_factors
from workbook.solve.harmonic import point_phasors
from workbook.solve.stages import link_warnings

if TYPE_CHECKING:
    from flexbodies.reduced import ReducedBody

__all__ = ["LinearMount", "DesignAnswer", "ItemSolution", "StressedLink", "channel_springs",
           "keeps_casing_modes"]


def channel_springs(case: Case, channels: list[str]) -> ChannelSprings:
    """The springs of the force channels *channels* of *case*: the hinges' as their laws give them
    (:meth:`~workbook.scene.hinge_law_base.HingeLaw.matrices`), then the transducers' along the global axes."""
    from workbook.scene.hinge_laws import law_of

    hinge_loss, _ = loss_factors(case)
    by_name = {hinge.name: hinge for hinge in case.hinges}
    springs = np.zeros((3, len(channels), 3, 3))        # stiffness, damping, loss factors
    for k, name in enumerate(channels):
        hinge = by_name.get(name)
        if hinge is None:
            rig = case.test_rig
            assert rig is not None
            springs[0, k], springs[1, k] = np.diag(rig.stiffness), np.diag(rig.damping)
            continue
        stiffness, damping, loss = law_of(case, hinge).matrices(case, hinge)
        springs[0, k] = stiffness
        if case.effects.hinge_damping:
            springs[1, k] = damping
        if name in hinge_loss:
            springs[2, k] = loss
    return ChannelSprings(springs[0], springs[1], springs[2] @ springs[0])


@dataclass(frozen=True)
class _FlexibleLink:
    """What the design evaluation needs of one flexible link's stress stiffening and loss."""

    name: str
    modal: np.ndarray                  # full coordinates of its modal coordinates
    geometric: np.ndarray              # K_G,r per N of tension
    base_tension: float                # the tension the prepared scene's K_r + P K_G,r holds
    stiffness_damping: float           # Rayleigh beta, s
    loss_factor: float
    reduced_stiffness: np.ndarray      # K_r of the prepared scene (stiffened there or not)
    unloaded_hz: float                 # first pinned-pinned frequency without tension
    stiffening: object = field(repr=False)   # flexbodies LinkStiffening


@dataclass(frozen=True)
class _Casing:
    """What the design evaluation needs of a flexible engine casing to change its modulus."""

    modal: np.ndarray                  # full coordinates of its modal coordinates
    stiffness: np.ndarray              # K_r at the prepared modulus
    damping: np.ndarray                # its modal damping at the prepared modulus
    modulus: float                     # the prepared modulus E_0, Pa
    reduced: ReducedBody = field(repr=False)

    def scale(self, case: Case) -> float:
        """E / E_0 of the design *case*."""
        casing = case.engine.casing
        assert casing is not None
        return float(casing.material.youngs_modulus) / self.modulus


@dataclass(frozen=True)
class StressedLink:
    """A flexible link whose stress the design evaluation recovers: ``sigma = S q`` of its modal coordinates.

    Attributes
    ----------
    link : workbook.model.case.Link
    coordinates : ndarray of int
        Its modal coordinates among the item's full coordinates.
    reduced : flexbodies.ReducedBody
        With its stress shapes.
    rotation : ndarray, shape (3, 3)
        Link frame to global.
    component_shapes : ndarray, shape (6, n, modes)
        The stress shapes component-major: ``(component_shapes[:, nodes] @ Q).reshape(6, -1).T`` is the
        stress at *nodes* of the columns of Q, a Fortran-ordered (nodes K, 6), quick to read by component.
    node_norms : ndarray, shape (n,)
        Each node's spectral norm of its stress shapes (6, modes): ``|S_i q| <= node_norms[i] |q|``, Pa.
    """

    link: Link
    coordinates: np.ndarray
    reduced: ReducedBody = field(repr=False)
    rotation: np.ndarray = field(repr=False)
    component_shapes: np.ndarray = field(repr=False)
    node_norms: np.ndarray = field(repr=False)


@dataclass
class _Item:
    """One excitation item, prepared."""

    name: str
    expansion: SceneExpansion
    size: int
    sign: float                        # Exudyn's Force output = sign * S d
    base_force: np.ndarray             # the rest's internal force at the prepared state
    compression: np.ndarray            # (links, channels, 3): link compression per channel force
    links: list                        # _FlexibleLink, in the case's order of the assessed links
    engine: np.ndarray                 # the engine's full coordinates
    points: list                       # excitation points of the item's excitations
    warnings: list
    modes: list
    base_engine: Engine
    prepared_seconds: float
    stressed: dict = field(default_factory=dict)     # name -> StressedLink, the links with stress shapes
    casing: _Casing | None = None                    # a flexible engine casing


@dataclass(frozen=True)
class DesignAnswer:
    """The answers of one design.

    Attributes
    ----------
    result : MountResult
        As :func:`workbook.run_case` gives it (no time histories; the model
        cards and preloads are those of the prepared case, the preloads
        replaced by the design's hinge forces).
    static_hinge_forces : dict of str to dict of str to ndarray
        Per excitation item, the preload force of every channel, N.
    seconds : float
        Wall time of the evaluation, s.
    engine_static : dict of str to ndarray
        Per excitation item, :attr:`ItemSolution.engine_static`.
    """

    result: MountResult
    static_hinge_forces: dict
    seconds: float
    engine_static: dict = field(default_factory=dict)


def _normalised(case: Case, base: Case) -> Case:
    """*case* with every field a design may change set to *base*'s."""
    hinges = tuple(dataclasses.replace(h, stiffness=b.stiffness, damping=b.damping, loss_factor=b.loss_factor)
                   for h, b in zip(case.hinges, base.hinges, strict=True)) \
        if [h.name for h in case.hinges] == [b.name for b in base.hinges] else case.hinges
    casing = case.engine.casing
    if casing is not None and base.engine.casing is not None:
        casing = dataclasses.replace(casing, material=dataclasses.replace(
            casing.material, youngs_modulus=base.engine.casing.material.youngs_modulus))
    engine = dataclasses.replace(case.engine, mass=base.engine.mass, inertia=base.engine.inertia, casing=casing)
    rig = case.test_rig
    if rig is not None and base.test_rig is not None:
        rig = dataclasses.replace(rig, stiffness=base.test_rig.stiffness, damping=base.test_rig.damping)
    return dataclasses.replace(case, name=base.name, hinges=hinges, engine=engine, test_rig=rig,
                               excitations=base.excitations)


class LinearMount:
    """A case's linear mount, prepared once and answered per design in NumPy.

    Use :meth:`prepare`; then :meth:`evaluate` answers any design the
    expansion follows (see the module text).
    """

    def __init__(self, case: Case, items: dict, channels: list, pylon: list, cards: dict, preloads: dict):
        self.case = case
        self.items = items
        self.channels = channels
        self.pylon = pylon
        self._cards = cards
        self._preloads = preloads

    @classmethod
    def prepare(cls, case: Case) -> "LinearMount":
        """Prepare every excitation item of *case* (the expensive part: reductions, Exudyn preload, expansion).

        Raises
        ------
        OutsideDesignModel
            A case the design evaluation cannot answer: a flexible pylon,
            clearance laws, or a time-domain method.
        workbook.errors.SimulationError
            As :func:`workbook.run_case`.
        """
        from workbook.solve.method import FREQUENCY, choose_method
        from workbook.solve.pipeline import prepare, solve_frequencies

        if case.flexible_pylon:
            raise OutsideDesignModel(case.name, "a flexible pylon (answered by the four-pole set)")
        items, cards, preloads = {}, {}, {}
        channels: list[str] = []
        pylon: list[str] = []
        for item in case.excitations:
            points = item.expand() if isinstance(item, (Sweep, Simultaneous)) else (item,)
            chosen = choose_method(case, sweep=isinstance(item, Sweep))
            if chosen.method != FREQUENCY:
                raise OutsideDesignModel(case.name, f"{item.name!r} is answered in the time domain ({chosen.reason})")
            start = time.perf_counter()
            highest = max(points, key=lambda point: point.frequency)
            prepared = prepare(case, points[0], reduce_for=highest)
            with prepared.scene as scene:
                for items_ in scene.hinges.values():
                    if items_.nonlinear:
                        raise OutsideDesignModel(case.name, f"{items_.hinge_law.name} laws (a nonlinear scene)")
                for run in solve_frequencies(case, prepared, points, chosen):
                    cards[run.name], preloads[run.name] = run.model_card, run.preload
                channels, pylon = list(scene.force_channels), list(scene.pylon_channels)
                items[item.name] = _prepare_item(case, item, scene, prepared, channels,
                                                 [np.asarray(p) for e in points for p, _ in point_phasors(e)],
                                                 time.perf_counter() - start)
        return cls(case, items, channels, pylon, cards, preloads)

    def check(self, case: Case) -> None:
        """Raise :class:`OutsideDesignModel` unless *case* differs from the prepared case only in what
        a design may change (see the module text)."""
        base = self.case
        if _normalised(case, base) != base:
            raise OutsideDesignModel(case.name, "a change beyond hinge springs, transducer springs, engine mass "
                                     "properties, the casing's modulus and excitation frequencies and amplitudes")
        if [type(e) for e in case.excitations] != [type(e) for e in base.excitations] or \
                [e.name for e in case.excitations] != [e.name for e in base.excitations]:
            raise OutsideDesignModel(case.name, "other excitations")
        for item in case.excitations:
            prepared = self.items[item.name]
            for excitation in points_of(item):
                for point, _ in point_phasors(excitation):
                    if tuple(np.round(np.asarray(point, dtype=float), 12)) not in prepared.expansion.points:
                        raise OutsideDesignModel(case.name, f"{excitation.name!r} acts at a point the prepared "
                                                 f"case has no excitation at ({point})")
        _check_mode_decisions(case, base)
        _check_casing_modes(case, base, self.items)

    def follows(self, case: Case) -> bool:
        """Whether :meth:`evaluate` answers *case* (:meth:`check` passes)."""
        try:
            self.check(case)
        except OutsideDesignModel:
            return False
        return True

    def evaluate(self, case: Case) -> DesignAnswer:
        """Answer the design *case* (the prepared case with other springs, masses or excitations).

        Raises
        ------
        OutsideDesignModel
            *case* changes what needs a new preparation.
        workbook.errors.SimulationError
            The design buckles a link, loses its stability under the preload,
            or is excited on an undamped resonance.
        """
        start = time.perf_counter()
        return self.answer(case, self.solve_items(case), start)

    def answer(self, case: Case, solutions: list["ItemSolution"], start: float) -> DesignAnswer:
        """The answers of the design *case* from its solved items (:meth:`solve_items`), begun at *start*
        (``time.perf_counter()``)."""
        runs, static, engine = [], {}, {}
        for item, solution in zip(case.excitations, solutions, strict=True):
            static[item.name] = dict(zip(self.channels, solution.state.forces, strict=True))
            engine[item.name] = solution.engine_static
            for excitation in points_of(item):
                run = _answer(case, solution.prepared, solution.model, excitation, self.channels, self.pylon)
                run.model_card, run.preload = self._cards.get(run.name), self._preloads.get(run.name)
                runs.append(run)
        result = MountResult(case.name, runs)
        return DesignAnswer(result, static, time.perf_counter() - start, engine)

    def solve_items(self, case: Case) -> list["ItemSolution"]:
        """The preload and the linear model of every excitation item of the design *case*.

        Raises
        ------
        As :meth:`evaluate`.
        """
        self.check(case)
        springs = channel_springs(case, self.channels)
        solutions = []
        for item in case.excitations:
            prepared = self.items[item.name]
            state = _solve_state(case, prepared, springs)
            solutions.append(ItemSolution(prepared, springs, state, linear_model(case, prepared, springs, state)))
        return solutions


def points_of(item) -> tuple:
    """The single-frequency excitations of an excitation item (a sweep's points, a simultaneous set's parts)."""
    return item.expand() if isinstance(item, (Sweep, Simultaneous)) else (item,)


def _check_mode_decisions(case: Case, base: Case) -> None:
    """The links' mode selections at *case*'s frequencies must be the prepared ones."""
    from workbook.scene.build import link_jobs

    for item, base_item in zip(case.excitations, base.excitations, strict=True):
        if max(p.frequency for p in points_of(item)) == max(p.frequency for p in points_of(base_item)):
            continue
        highest = max(points_of(item), key=lambda point: point.frequency)
        new = {name: job.modes for job, names in link_jobs(case, highest).items() for name in names}
        if any(case.link_modes(name) == "auto" for name in new):
            raise OutsideDesignModel(case.name, f"{item.name!r} at another frequency: the links' automatic mode "
                                     "selection may keep other modes")


def _check_casing_modes(case: Case, base: Case, items: dict) -> None:
    """The casing's mode selection at *case*'s modulus and frequencies must keep the prepared modes."""
    casing = case.engine.casing
    for item, base_item in zip(case.excitations, base.excitations, strict=True):
        prepared = items[item.name].casing
        if casing is None or prepared is None:
            continue
        if not keeps_casing_modes(casing.modes, prepared.reduced.frequencies, prepared.scale(case),
                                  max(p.frequency for p in points_of(base_item)),
                                  max(p.frequency for p in points_of(item))):
            raise OutsideDesignModel(case.name, f"the casing at {casing.material.youngs_modulus:g} Pa in "
                                     f"{item.name!r}: its mode selection {casing.modes!r} keeps other modes there "
                                     "(a count of modes keeps them)")


def keeps_casing_modes(modes, frequencies: dict, scale: float, prepared_hz: float, excitation_hz: float) -> bool:
    """Whether a casing reduced for *prepared_hz* keeps the same modes at *scale* times its modulus and
    the highest excitation *excitation_hz* (Hz): its frequencies scale with ``sqrt(scale)``.

    Parameters
    ----------
    modes : {"auto", "static"} or int or float
        The casing's mode request.
    frequencies : dict
        The reduced casing's ``free_free_hz`` and the ``fixed_interface_hz`` of its kept modes, Hz.
    """
    from flexbodies.craig_bampton import kept_count
    from flexbodies.selection import decide_modes

    root = np.sqrt(scale)
    first = frequencies["free_free_hz"][0]
    old = decide_modes(modes, first, prepared_hz)
    new = decide_modes(modes, root * first, excitation_hz)
    if new.count is not None:
        return old.count == new.count
    fixed = root * np.asarray(frequencies["fixed_interface_hz"])
    return bool(old.count is None and len(fixed) > 0 and fixed[-1] >= new.cutoff_hz
                and kept_count(fixed, None, new.cutoff_hz) == len(fixed))


def _prepare_item(case: Case, item, scene: Scene, prepared, channels: list[str], points: list,
                  seconds: float) -> _Item:
    from flexbodies.geometric_stiffness import link_stiffening
    from workbook.solve.preload import link_compression

    start = time.perf_counter()
    expansion = expand_scene(scene, points)
    size = len(expansion.state)
    forces = scene.hinge_forces()
    base_springs = channel_springs(case, channels)
    state = expansion.channels.state(total(expansion, np.zeros(size)))
    own = np.einsum("cab,cb->ca", base_springs.stiffness, state.separation)
    exudyn = np.array([forces[name] for name in channels])
    scale = max(np.abs(exudyn).max(), 1e-300)
    sign = 1.0 if np.abs(own - exudyn).max() <= np.abs(own + exudyn).max() else -1.0
    if np.abs(sign * own - exudyn).max() > 1e-6 * scale:
        raise OutsideDesignModel(case.name, "a force channel whose force is not its spring's (a user law)")
    base_force = -without_normal(expansion, np.zeros(size), expansion.channels.force(state, base_springs.stiffness))
    names = [link.name for link in case.links]
    compression = np.zeros((len(names), len(channels), 3))
    hinge_names = [hinge.name for hinge in case.hinges]
    for name in hinge_names:
        for axis in range(3):
            unit = {other: np.zeros(3) for other in hinge_names}
            unit[name] = np.eye(3)[axis]
            values = link_compression(scene, unit)
            compression[:, channels.index(name), axis] = [values[link] for link in names]
    flexible = []
    if case.effects.stress_stiffening != "off" and prepared.preload.solved:
        for link in case.links:
            if not case.link_is_flexible(link.name):
                continue
            reduced = scene.reduced[link.name]
            stiffening = link_stiffening(link.model)
            start_index = scene.mbs.GetNodeODE2Index(scene.links[link.name].nodes[1])
            reduced_stiffness = np.asarray(reduced.ffrf["stiffnessMatrixReduced"], dtype=float)
            flexible.append(_FlexibleLink(
                link.name, np.arange(start_index, start_index + reduced_stiffness.shape[0]),
                stiffening.project(reduced.mode_basis), float(reduced.info.get("axial_tension_N", 0.0)),
                link.stiffness_damping if case.effects.link_damping else 0.0,
                loss_factors(case)[1].get(link.name, 0.0), reduced_stiffness,
                float(stiffening.pinned_hz(0.0, 1)[0]), stiffening))
            if link.modal_damping > 0 and case.effects.link_damping:
                raise OutsideDesignModel(case.name, f"link {link.name!r}: modal damping on a stiffened link")
    engine = np.arange(scene.mbs.GetNodeODE2Index(scene.engine.node), scene.mbs.GetNodeODE2Index(scene.engine.node) + 6)
    warnings = link_warnings(case, scene.reduced)
    stressed = {}
    for link in case.links:
        reduced = scene.reduced.get(link.name)
        if case.link_is_flexible(link.name) and reduced is not None and reduced.stress_modes.size:
            first = scene.mbs.GetNodeODE2Index(scene.links[link.name].nodes[1])
            shapes = reduced.stress_modes
            stressed[link.name] = StressedLink(
                link, np.arange(first, first + shapes.shape[2]), reduced, np.asarray(scene.links[link.name].rotation),
                np.ascontiguousarray(shapes.transpose(1, 0, 2)), np.linalg.norm(shapes, ord=2, axis=(1, 2)))
    return _Item(item.name, expansion, size, sign, base_force, compression, flexible, engine, points, warnings,
                 prepared.modes, case.engine, seconds + time.perf_counter() - start, stressed,
                 _prepared_casing(case, scene))


def _prepared_casing(case: Case, scene: Scene) -> _Casing | None:
    """The flexible engine casing of *scene*, or None."""
    from flexbodies.exudyn_body import modal_damping_matrix

    casing = case.engine.casing
    if casing is None or scene.casing is None:
        return None
    reduced = scene.casing.reduced
    stiffness = np.asarray(reduced.ffrf["stiffnessMatrixReduced"], dtype=float)
    first = scene.mbs.GetNodeODE2Index(scene.casing.casing.nodes[1])
    return _Casing(np.arange(first, first + stiffness.shape[0]), stiffness,
                   modal_damping_matrix(reduced, casing.modal_damping), float(casing.material.youngs_modulus),
                   reduced)


@dataclass(frozen=True)
class _State:
    """A design's preloaded state."""

    dq: np.ndarray
    tensions: dict             # used in K_r + P K_G,r per flexible link (0: not stiffened)
    forces: np.ndarray         # (channels, 3) static channel forces, N
    loads: StateLoads
    passes: tuple = ()         # (dq, tensions, loads) of each preload solve, the last being this state's


def _engine_rotation_map(angles: np.ndarray) -> np.ndarray:
    """``G`` of Exudyn's Tait-Bryan (Rxyz) angles: body angular velocity = G @ angle rates."""
    _, b, c = angles
    return np.array([[np.cos(b) * np.cos(c), np.sin(c), 0.0],
                     [-np.cos(b) * np.sin(c), np.cos(c), 0.0],
                     [np.sin(b), 0.0, 1.0]])


def _state_loads(case: Case, prepared: _Item, tensions: dict) -> StateLoads:
    base = prepared.base_engine
    added_mass = case.engine.mass - base.mass
    added_inertia = case.engine.inertia_matrix - base.inertia_matrix
    force = np.zeros(prepared.size)
    mass = []
    if added_mass or np.any(added_inertia):
        def engine_mass(q: np.ndarray) -> np.ndarray:
            rotation = _engine_rotation_map(q[3:6])
            block = np.zeros((6, 6))
            block[:3, :3] = added_mass * np.eye(3)
            block[3:, 3:] = rotation.T @ added_inertia @ rotation
            return block
        mass.append((prepared.engine, engine_mass))
        if case.effects.preload:
            for load in case.static_loads:
                if isinstance(load, Gravity):
                    force[prepared.engine[:3]] += added_mass * np.asarray(load.acceleration)
    modal = [(link.modal, (tensions.get(link.name, 0.0) - link.base_tension) * link.geometric)
             for link in prepared.links if tensions.get(link.name, 0.0) != link.base_tension]
    casing = prepared.casing
    if casing is not None and casing.scale(case) != 1.0:
        modal.append((casing.modal, (casing.scale(case) - 1.0) * casing.stiffness))
    return StateLoads(modal, mass, force)



def _channel_forces(prepared: _Item, springs: ChannelSprings, dq: np.ndarray) -> np.ndarray:
    separation = prepared.expansion.channels.state(total(prepared.expansion, dq), second=False).separation
    return prepared.sign * np.einsum("cab,cb->ca", springs.stiffness, separation)


def _solve_state(case: Case, prepared: _Item, springs: ChannelSprings) -> _State:
    """The design's preload with the stress-stiffening passes of the Exudyn pipeline."""
    from workbook.solve.stress_stiffening import AUTO_SHIFT, MAX_PASSES, TENSION_TOLERANCE

    def solve(tensions: dict, start: np.ndarray) -> tuple[np.ndarray, np.ndarray, StateLoads]:
        loads = _state_loads(case, prepared, tensions)
        try:
            dq, _ = static_state(prepared.expansion, springs, prepared.base_force, loads, start)
        except np.linalg.LinAlgError as error:
            raise UnstablePreloadError(f"{case.name}: the design's preload has no stable equilibrium ({error})",
                                       []) from None
        passes.append((dq, tensions, loads))
        return dq, _channel_forces(prepared, springs, dq), loads

    passes: list = []
    dq, forces, loads = solve({}, np.zeros(prepared.size))
    tensions: dict = {}
    if prepared.links:
        names = [link.name for link in case.links]
        compression = dict(zip(names, np.einsum("lcx,cx->l", prepared.compression, forces), strict=True))
        chosen = []
        for link in prepared.links:
            tension = -compression[link.name]
            unloaded = link.unloaded_hz
            if -tension >= link.stiffening.buckling_load:
                raise BucklingError(case.name, link.name, -tension, link.stiffening.buckling_load, unloaded)
            shift = abs(float(link.stiffening.pinned_hz(tension, 1)[0]) / unloaded - 1.0)
            if case.effects.stress_stiffening == "on" or shift > AUTO_SHIFT:
                chosen.append(link.name)
            tensions[link.name] = tension
        used = {name: tensions[name] for name in chosen}
        while chosen and len(passes) <= MAX_PASSES:
            dq, forces, loads = solve(used, dq)
            new = dict(zip(names, -np.einsum("lcx,cx->l", prepared.compression, forces), strict=True))
            change = max(abs(new[name] - used[name]) for name in chosen) / max(abs(used[name]) for name in chosen)
            if change <= TENSION_TOLERANCE or len(passes) > MAX_PASSES:
                break
            used = {name: new[name] for name in chosen}
        tensions = used
    return _State(dq, tensions, forces, loads, tuple(passes))


@dataclass(frozen=True)
class _Harmonic:
    """The projected linear model at a state: ``Z = K - w^2 M + i (w D + H)``, outputs ``C_k + i (C_h + w C_d)``."""

    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    structural: np.ndarray
    outputs: tuple              # C_k, C_d, C_h, shape (3 c, n) each
    basis: Projection
    inputs: dict                # point -> (n, 3)

    def dynamic(self, omega: float) -> np.ndarray:
        """Z at the circular frequency *omega* (rad/s), shape (n, n)."""
        return self.stiffness - omega ** 2 * self.mass + 1j * (omega * self.damping + self.structural)

    def output(self, omega: float) -> np.ndarray:
        """The channel force phasors per motion phasor at *omega*, shape (3 C, n)."""
        stiffness_output, damping_output, structural_output = self.outputs
        return stiffness_output + 1j * (structural_output + omega * damping_output)

    def load(self, excitation: SingleFrequencyExcitation) -> np.ndarray:
        """The generalised force phasor of *excitation*, shape (n,)."""
        return sum(self.inputs[tuple(np.round(np.asarray(p, dtype=float), 12))] @ phasor
                   for p, phasor in point_phasors(excitation))


@dataclass(frozen=True)
class ItemSolution:
    """One excitation item of a design, solved: what :mod:`workbook.design.sensitivity` differentiates."""

    prepared: _Item
    springs: ChannelSprings
    state: _State
    model: _Harmonic

    @property
    def engine_static(self) -> np.ndarray:
        """The engine's static displacement at its centre of gravity (m) and its Rxyz rotation (rad)
        under the preload, shape (6,): its node coordinates, as ``mountwb loads`` gives them."""
        return (self.prepared.expansion.state + self.state.dq)[self.prepared.engine]


def linear_model(case: Case, prepared: _Item, springs: ChannelSprings, state: _State) -> _Harmonic:
    """The projected linear model of the item *prepared* at the preloaded *state*."""
    expansion, dq = prepared.expansion, state.dq
    channels = expansion.channels
    at = channels.state(total(expansion, dq))
    mass, rest_stiffness, damping = rest_matrices(expansion, dq, state.loads)
    stiffness = tangent_stiffness(expansion, dq, rest_stiffness, springs, at)
    damping += channels.matrix(at, springs.damping)
    structural = prepared.sign * channels.matrix(at, springs.structural)
    outputs = [prepared.sign * channels.outputs(at, spring)
               for spring in (springs.stiffness, springs.damping, springs.structural)]
    for link in prepared.links:
        added = (state.tensions.get(link.name, 0.0) - link.base_tension) * link.geometric
        block = np.ix_(link.modal, link.modal)
        damping[block] += link.stiffness_damping * added
        structural[block] += link.loss_factor * (link.reduced_stiffness + added)
    casing = prepared.casing
    if casing is not None:
        damping[np.ix_(casing.modal, casing.modal)] += (np.sqrt(casing.scale(case)) - 1.0) * casing.damping
    basis = projection(expansion, dq)
    inputs = {}
    q = total(expansion, dq)
    for key, point in expansion.points.items():
        _, jacobian, _ = point.expand(q[point.coordinates])
        full = np.zeros((prepared.size, 3))
        full[point.coordinates] = jacobian.T
        inputs[key] = basis.rows(full)
    return _Harmonic(basis.both(mass), basis.both(stiffness), basis.both(damping), basis.both(structural),
                     tuple(basis.columns(o) for o in outputs), basis, inputs)


def _answer(case: Case, prepared: _Item, model: _Harmonic, excitation: SingleFrequencyExcitation,
            channels: list[str], pylon: list[str]) -> ExcitationResult:
    omega = 2 * np.pi * excitation.frequency
    try:
        motion = sla.solve(model.dynamic(omega), model.load(excitation), check_finite=False)
    except (np.linalg.LinAlgError, sla.LinAlgWarning) as error:
        raise ResonanceError(f"{case.name} / {excitation.name}: the design is excited on an undamped resonance at "
                             f"{excitation.frequency:g} Hz ({error})") from None
    forces = (model.output(omega) @ motion).reshape(-1, 3)
    amplitudes = dict(zip(channels, np.abs(forces), strict=True))
    pylon_force = forces[[channels.index(name) for name in pylon]].sum(axis=0)
    return ExcitationResult(
        name=excitation.name, frequency_hz=excitation.frequency, excitation_amplitude=excitation.force_amplitude,
        pylon_amplitude=np.abs(pylon_force), hinge_amplitudes=amplitudes, pylon_hinges=list(pylon),
        steady_change=0.0, steady_tolerance=case.analysis.steady_tolerance, warnings=list(prepared.warnings))
