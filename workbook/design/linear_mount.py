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
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from workbook.answers.results import ExcitationResult, MountResult
from workbook.design.assembly import (
    AddedRigidMass,
    ChannelSprings,
    StateLoads,
    add_tangent_terms,
    projected,
    projection,
    rest_matrices,
    total,
    without_normal,
)
from workbook.design.channel_set import spring_matrix, spring_rows
from workbook.design.equilibrium import PRELOAD_STEPS, ChordStiffness, PreparedTangent, prepared_tangent, static_state
from workbook.design.expansion import SceneExpansion, expand_scene
from workbook.design.harmonic_model import BodyHarmonic, Harmonic
from workbook.design.memory import keep_freed_memory
from workbook.design.pinned_shift import ShiftBracket
from workbook.errors import BucklingError, OutsideDesignModel, ResonanceError, SimulationError, UnstablePreloadError
from workbook.model.case import Case, Engine, Gravity, Link, Simultaneous, Sweep
from workbook.scene.build import Scene, loss_factors
from workbook.solve.harmonic import point_phasors
from workbook.solve.stages import link_warnings

if TYPE_CHECKING:
    from flexbodies.reduced import ReducedBody

__all__ = ["LinearMount", "DesignAnswer", "ItemSolution", "StressedLink", "channel_springs",
           "keeps_casing_modes", "REACH_M", "REACH_RAD"]


def hinge_frames(case: Case) -> dict:
    """Each hinge's frame (:func:`~workbook.scene.hinge_law_base.hinge_frame`) by its name."""
    from workbook.scene.hinge_law_base import hinge_frame

    return {hinge.name: hinge_frame(case, hinge) for hinge in case.hinges}


def channel_springs(case: Case, channels: list[str], frames: dict | None = None) -> ChannelSprings:
    """The springs of the force channels *channels* of *case*: the hinges' as their laws give them
    (:meth:`~workbook.scene.hinge_law_base.HingeLaw.matrices`, in the hinges' *frames* when given), then the
    transducers' along the global axes."""
    return designs_springs([case], channels, hinge_frames(case) if frames is None else frames).take(0)


def designs_springs(cases: list[Case], channels: list[str], frames: dict) -> ChannelSprings:
    """:func:`channel_springs` of the designs *cases* at once (springs of shape (B, C, 3, 3)), whose hinges
    and transducers sit where the hinges' *frames* (by name) say.

    The laws' :meth:`~workbook.scene.hinge_law_base.HingeLaw.matrices`, for all designs together: a hinge
    isotropic in stiffness, damping and loss factor has them times the identity, any other ``R^T diag R``
    in its frame R.
    """
    effects = cases[0].effects
    hinge_names = {hinge.name for hinge in cases[0].hinges}
    values = np.zeros((len(cases), len(channels), 3, 3))          # design, channel, quantity, direction
    transducers = np.zeros((len(cases), len(channels), 2, 3))      # stiffness and damping per global axis
    for b, case in enumerate(cases):
        by_name = {hinge.name: hinge for hinge in case.hinges}
        for k, name in enumerate(channels):
            hinge = by_name.get(name)
            if hinge is None:
                rig = case.test_rig
                assert rig is not None
                transducers[b, k] = rig.stiffness, rig.damping
                continue
            values[b, k] = [value if isinstance(value, tuple) else (value, value, value)
                            for value in (hinge.stiffness, hinge.damping, hinge.loss_factor)]
    isotropic = (values == values[..., :1]).all(axis=(-1, -2))
    if not effects.hinge_damping:
        values[..., 1:, :] = 0.0
    rotation = np.array([frames[name] if name in hinge_names else np.eye(3) for name in channels])  # (C, 3, 3)
    turned = (rotation.swapaxes(-1, -2)[:, None] * values[..., None, :]) @ rotation[:, None]         # (B, C, 3, 3, 3)
    turned = np.where(isotropic[..., None, None, None], values[..., :1, None] * np.eye(3), turned)
    is_hinge = np.array([name in hinge_names for name in channels])[:, None, None]
    stiffness = np.where(is_hinge, turned[:, :, 0], transducers[:, :, 0, :, None] * np.eye(3))
    damping = np.where(is_hinge, turned[:, :, 1], transducers[:, :, 1, :, None] * np.eye(3))
    return ChannelSprings(stiffness, damping, np.where(is_hinge, turned[:, :, 2], 0.0) @ stiffness)


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
    shift: ShiftBracket = field(repr=False)  # whether tensions shift that frequency


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
    flexible_positions: list           # the positions of *links* among the case's links
    points: list                       # excitation points of the item's excitations
    warnings: list
    modes: list
    base_engine: Engine
    prepared_seconds: float
    stressed: dict = field(default_factory=dict)     # name -> StressedLink, the links with stress shapes
    casing: _Casing | None = None                    # a flexible engine casing
    tangent: PreparedTangent | None = None           # at the prepared state, links unstiffened (None: singular)


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
        Wall time of the evaluation (of designs answered together, its share of theirs), s.
    engine_static : dict of str to ndarray
        Per excitation item, :attr:`ItemSolution.engine_static`.
    """

    result: MountResult
    static_hinge_forces: dict
    seconds: float
    engine_static: dict = field(default_factory=dict)


def _same_except(one, other, changes: dict) -> bool:
    """Whether the dataclasses *one* and *other* are equal but in the fields named in *changes*; a name that
    maps to a dict compares those fields' own fields likewise (None: the field is free)."""
    if one is other:
        return True
    if type(one) is not type(other):
        return False
    for name in _field_names(type(one)):
        mine, theirs = getattr(one, name), getattr(other, name)
        if name not in changes:
            if not (mine is theirs or mine == theirs):
                return False
        elif changes[name] is not None and not (
                (mine is None and theirs is None) or (mine is not None and theirs is not None
                                                      and _same_except(mine, theirs, changes[name]))):
            return False
    return True


_FIELD_NAMES: dict[type, tuple[str, ...]] = {}


def _field_names(kind: type) -> tuple[str, ...]:
    """The field names of the dataclass *kind*."""
    if kind not in _FIELD_NAMES:
        _FIELD_NAMES[kind] = tuple(item.name for item in dataclasses.fields(kind))
    return _FIELD_NAMES[kind]


#: Largest change of the engine's static translation (m) and rotation (rad) from the prepared design's preload
#: that a design's answer may have: the expansion about the prepared state is of second order, and T drifts
#: from the pipeline's as the preload moves (the far-design table of docs/design-evaluation.md); a
#: mechanism's "equilibrium" lies kilometres away.
REACH_M = 0.01
REACH_RAD = 0.01
#: What a design may change, by field (module text); the excitations are checked on their own.
_DESIGN_CHANGES = {"name": None, "excitations": None, "hinges": None,
                   "engine": {"mass": None, "inertia": None, "casing": {"material": {"youngs_modulus": None}}},
                   "test_rig": {"stiffness": None, "damping": None}}
_HINGE_CHANGES = {"stiffness": None, "damping": None, "loss_factor": None}


def _follows(case: Case, base: Case) -> bool:
    """Whether *case* differs from *base* only in what a design may change (not checking the excitations)."""
    return _same_except(case, base, _DESIGN_CHANGES) and len(case.hinges) == len(base.hinges) and all(
        _same_except(hinge, other, _HINGE_CHANGES) for hinge, other in zip(case.hinges, base.hinges, strict=True))


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
        self._frames = hinge_frames(case)

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
        if not _follows(case, base):
            raise OutsideDesignModel(case.name, "a change beyond hinge springs, transducer springs, engine mass "
                                     "properties, the casing's modulus and excitation frequencies and amplitudes")
        if [type(e) for e in case.excitations] != [type(e) for e in base.excitations] or \
                [e.name for e in case.excitations] != [e.name for e in base.excitations]:
            raise OutsideDesignModel(case.name, "other excitations")
        for item, base_item in zip(case.excitations, base.excitations, strict=True):
            if item is base_item:                 # the prepared excitation itself (a study's rows share it)
                continue
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
        answer = self.evaluate_many([case])[0]
        if isinstance(answer, Exception):
            raise answer
        return answer

    def evaluate_many(self, cases: Sequence[Case]) -> list[DesignAnswer | SimulationError]:
        """Answer many designs at once (NumPy on all of them together: much faster per design).

        The first call has the C allocator keep freed arrays of up to 32 MB in
        the process for the next batch (:func:`~workbook.design.memory.keep_freed_memory`):
        the process's memory stays near its peak.

        Returns
        -------
        list of DesignAnswer or SimulationError
            In the order of *cases*; a design :meth:`evaluate` would raise for
            (:class:`OutsideDesignModel`, a buckled link, no stable preload,
            an undamped resonance) has its error in its place. Each answer's
            ``seconds`` is its share of the batch's wall time.
        """
        start = time.perf_counter()
        keep_freed_memory()
        outcomes: list = [None] * len(cases)
        rows = []
        for k, case in enumerate(cases):
            try:
                self.check(case)
                rows.append(k)
            except OutsideDesignModel as error:
                outcomes[k] = error
        if rows:
            designs = self._designs([cases[k] for k in rows])
            runs: list[list] = [[] for _ in rows]
            static: list[dict] = [{} for _ in rows]
            engine: list[dict] = [{} for _ in rows]
            failed: dict[int, SimulationError] = {}
            for position, item in enumerate(self.case.excitations):
                solved = _solve_item(designs, self.items[item.name])
                failed = {**solved.failures, **failed}
                for k, answered in enumerate(self._item_runs(designs.cases, position, solved.prepared, solved.model,
                                                             solved.rows, solved.failures)):
                    if isinstance(answered, SimulationError):
                        failed.setdefault(k, answered)
                        continue
                    runs[k].extend(answered)
                    static[k][item.name] = dict(zip(self.channels, solved.state.forces[k], strict=True))
                    engine[k][item.name] = (solved.prepared.expansion.state + solved.state.dq[k])[solved.prepared.engine]
            share = (time.perf_counter() - start) / len(cases)
            for k, row in enumerate(rows):
                outcomes[row] = failed[k] if k in failed else DesignAnswer(
                    MountResult(cases[row].name, runs[k]), static[k], share, engine[k])
        return outcomes

    def answer(self, case: Case, solutions: list["ItemSolution"], start: float) -> DesignAnswer:
        """The answers of the design *case* from its solved items (:meth:`solve_items`), begun at *start*
        (``time.perf_counter()``)."""
        runs, static, engine = [], {}, {}
        for position, (item, solution) in enumerate(zip(case.excitations, solutions, strict=True)):
            static[item.name] = dict(zip(self.channels, solution.state.forces, strict=True))
            engine[item.name] = solution.engine_static
            answered = self._item_runs([case], position, solution.prepared, solution.model.stacked(),
                                       np.zeros(1, dtype=int), {})[0]
            if isinstance(answered, SimulationError):
                raise answered
            runs.extend(answered)
        return DesignAnswer(MountResult(case.name, runs), static, time.perf_counter() - start, engine)

    def solve_items(self, case: Case) -> list["ItemSolution"]:
        """The preload and the linear model of every excitation item of the design *case*.

        Raises
        ------
        As :meth:`evaluate`.
        """
        self.check(case)
        designs = self._designs([case])
        solutions = []
        for item in case.excitations:
            solved = _solve_item(designs, self.items[item.name], keep_passes=True)
            if solved.failures:
                raise solved.failures[0]
            solutions.append(solved.design(0))
        return solutions

    def _designs(self, cases: list[Case]) -> "_Designs":
        """The fields of *cases* (checked) the evaluation takes, stacked."""
        base = self.case.engine
        casing = next(iter(self.items.values())).casing
        return _Designs(
            cases, designs_springs(cases, self.channels, self._frames),
            np.array([case.engine.mass - base.mass for case in cases], dtype=float),
            np.array([case.engine.inertia_matrix - base.inertia_matrix for case in cases], dtype=float),
            np.array([1.0 if casing is None else casing.scale(case) for case in cases]))

    def _item_runs(self, cases: list[Case], position: int, prepared: _Item, model: "Harmonic | BodyHarmonic | None",
                   solved: np.ndarray, failures: dict) -> list:
        """Per design *cases*, its excitation results of the item at *position* (its own excitations), or the
        error that stopped it.

        *model* holds the linear models of the designs *solved* (sorted positions among *designs*; None: none
        solved); *failures* the errors of the others."""
        results: list = [[] for _ in cases]
        excitations = [points_of(case.excitations[position]) for case in cases]
        pylon = [self.channels.index(name) for name in self.pylon]
        for point in range(max(len(e) for e in excitations)):
            rows = np.array([k for k, e in enumerate(excitations) if len(e) > point and k not in failures],
                            dtype=int)
            if not len(rows):
                continue
            assert model is not None, "designs left that solved"
            chosen = [excitations[k][point] for k in rows]
            omega = 2 * np.pi * np.array([e.frequency for e in chosen])
            positions = np.searchsorted(solved, rows)
            # every solved design (a study's batch): the models as they are, not copied
            models = model if np.array_equal(positions, np.arange(len(solved))) else model.take(positions)
            phasors: dict = {}                   # the designs of a study mostly share their excitations
            for e in chosen:
                if id(e) not in phasors:
                    phasors[id(e)] = point_phasors(e)
            loads = np.stack([models.load(e, k, phasors[id(e)]) for k, e in enumerate(chosen)])
            forces, singular = models.respond(omega, loads)
            for k, row in enumerate(rows):
                excitation = chosen[k]
                if singular[k]:
                    results[row] = ResonanceError(
                        f"{cases[row].name} / {excitation.name}: the design is excited on an undamped "
                        f"resonance at {excitation.frequency:g} Hz")
                    continue
                if isinstance(results[row], SimulationError):
                    continue
                run = ExcitationResult(
                    name=excitation.name, frequency_hz=excitation.frequency,
                    excitation_amplitude=excitation.force_amplitude,
                    pylon_amplitude=np.abs(forces[k, pylon].sum(axis=0)),
                    hinge_amplitudes=dict(zip(self.channels, np.abs(forces[k]), strict=True)),
                    pylon_hinges=list(self.pylon), steady_change=0.0,
                    steady_tolerance=cases[row].analysis.steady_tolerance,
                    warnings=list(prepared.warnings))
                run.model_card, run.preload = self._cards.get(run.name), self._preloads.get(run.name)
                results[row].append(run)
        for k, error in failures.items():
            results[k] = error
        return results


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
                float(stiffening.pinned_hz(0.0, 1)[0]), stiffening, ShiftBracket.of(stiffening)))
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
                np.ascontiguousarray(shapes.transpose(1, 0, 2)), _spectral_norms(shapes))
    unstiffened = StateLoads(_link_stiffness(flexible, np.zeros((1, len(flexible)))), [], np.zeros((1, size)))
    tangent = prepared_tangent(expansion, base_springs, unstiffened.take(0))
    return _Item(item.name, expansion, size, sign, base_force, compression, flexible, engine,
                 [names.index(link.name) for link in flexible], points, warnings,
                 prepared.modes, case.engine, seconds + time.perf_counter() - start, stressed,
                 _prepared_casing(case, scene), tangent)


def _spectral_norms(shapes: np.ndarray) -> np.ndarray:
    """The spectral norm of each of the matrices *shapes* (n, r, c): the square root of the largest eigenvalue
    of its ``S S^T`` (r by r: for the 6 stress components, half the time of the SVDs)."""
    return np.sqrt(np.maximum(np.linalg.eigvalsh(shapes @ shapes.swapaxes(1, 2))[:, -1], 0.0))


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
class _Designs:
    """The fields of B designs (checked against the prepared case) that the evaluation takes, stacked."""

    cases: list
    springs: ChannelSprings            # (B, C, 3, 3) each
    added_mass: np.ndarray             # (B,) engine mass minus the prepared one, kg
    added_inertia: np.ndarray          # (B, 3, 3) likewise, kg m^2
    casing_scale: np.ndarray           # (B,) E / E_0 of a flexible casing (1 without)

    @property
    def count(self) -> int:
        return len(self.cases)

    def take(self, rows: np.ndarray) -> "_Designs":
        """The designs *rows*."""
        return _Designs([self.cases[k] for k in rows], self.springs.take(rows), self.added_mass[rows],
                        self.added_inertia[rows], self.casing_scale[rows])


@dataclass(frozen=True)
class _State:
    """Preloaded states: of one design, or of several (leading axis)."""

    dq: np.ndarray             # (..., N)
    tensions: np.ndarray       # (..., L) per flexible link, used in K_r + P K_G,r (0: not stiffened)
    stiffened: np.ndarray      # (..., L) bool: the stress-stiffening passes chose the link
    forces: np.ndarray         # (..., C, 3) static channel forces, N
    loads: StateLoads
    passes: tuple = ()         # (dq, stiffened, loads) of each preload solve of one design, the last its state's

    def take(self, rows) -> "_State":
        """The designs *rows* (an index: one design without its axis)."""
        return _State(self.dq[rows], self.tensions[rows], self.stiffened[rows], self.forces[rows],
                      self.loads.take(rows))


def _state_loads(designs: _Designs, prepared: _Item, tensions: np.ndarray) -> StateLoads:
    """What the designs change in the rest of the scene, with the links' *tensions* (B, L) in their stiffness."""
    force = np.zeros((designs.count, prepared.size))
    mass = []
    if np.any(designs.added_mass) or np.any(designs.added_inertia):
        mass.append(AddedRigidMass(prepared.engine, designs.added_mass, designs.added_inertia))
        case = designs.cases[0]
        if case.effects.preload:
            for load in case.static_loads:
                if isinstance(load, Gravity):
                    force[:, prepared.engine[:3]] += designs.added_mass[:, None] * np.asarray(load.acceleration)
    modal = _link_stiffness(prepared.links, tensions)
    casing = prepared.casing
    if casing is not None and np.any(designs.casing_scale != 1.0):
        modal.append((casing.modal, (designs.casing_scale - 1.0)[:, None, None] * casing.stiffness))
    return StateLoads(modal, mass, force)


def _link_stiffness(links: list, tensions: np.ndarray) -> list:
    """The stiffness the flexible *links* add at the *tensions* (B, L) to the prepared scene's, as
    :attr:`StateLoads.modal_stiffness`."""
    return [(link.modal, (tensions[:, k] - link.base_tension)[:, None, None] * link.geometric)
            for k, link in enumerate(links) if np.any(tensions[:, k] != link.base_tension)]


def _channel_forces(prepared: _Item, springs: ChannelSprings, dq: np.ndarray) -> np.ndarray:
    separation = prepared.expansion.channels.state(total(prepared.expansion, dq), second=False).separation
    return prepared.sign * np.einsum("...cab,...cb->...ca", springs.stiffness, separation)


@dataclass(frozen=True)
class _SolvedItem:
    """An excitation item solved for B designs."""

    prepared: _Item
    designs: _Designs
    state: _State              # of every design (the rows of failed ones mean nothing)
    model: BodyHarmonic | Harmonic | None     # of the designs *rows* (None: none solved)
    rows: np.ndarray           # the designs solved, sorted
    failures: dict             # design -> SimulationError of the others
    passes: list               # (rows, dq, tensions, stiffened) of each preload solve, when kept

    def design(self, k: int) -> "ItemSolution":
        """Design *k* alone (solved)."""
        passes = []
        for rows, dq, tensions, stiffened in self.passes:
            position = np.flatnonzero(rows == k)
            if len(position):
                p = int(position[0])
                loads = _state_loads(self.designs.take(np.array([k])), self.prepared, tensions[p][None]).take(0)
                passes.append((dq[p], stiffened[p], loads))
        state = dataclasses.replace(self.state.take(k), passes=tuple(passes))
        assert self.model is not None, "design(k) of a design that solved"
        return ItemSolution(self.prepared, self.designs.springs.take(k), state,
                            self.model.take(int(np.searchsorted(self.rows, k))).dense())


def _beyond_reach(name: str, engine_change: np.ndarray) -> OutsideDesignModel | None:
    """The refusal of a design whose preload moves the engine (*engine_change*: its translation, m, and
    Rxyz rotation, rad, from the prepared design's preload) beyond :data:`REACH_M` or :data:`REACH_RAD`, or
    None."""
    move, turn = float(np.abs(engine_change[:3]).max()), float(np.abs(engine_change[3:]).max())
    if move <= REACH_M and turn <= REACH_RAD:
        return None
    return OutsideDesignModel(name, f"a preload that moves the engine {move * 1e3:.3g} mm and turns it "
                                    f"{turn * 1e3:.3g} mrad from the prepared design's (it follows up to "
                                    f"{REACH_M * 1e3:g} mm and {REACH_RAD * 1e3:g} mrad)")


def _solve_item(designs: _Designs, prepared: _Item, *, keep_passes: bool = False) -> _SolvedItem:
    """The designs' preloads with the stress-stiffening passes of the Exudyn pipeline, and their linear models."""
    from workbook.solve.stress_stiffening import AUTO_SHIFT, MAX_PASSES, TENSION_TOLERANCE

    count, links = designs.count, prepared.links
    dq = np.zeros((count, prepared.size))
    tensions = np.zeros((count, len(links)))
    stiffened = np.zeros((count, len(links)), dtype=bool)
    forces = np.zeros((count, prepared.compression.shape[1], 3))
    failures: dict[int, SimulationError] = {}
    passes: list = []
    # designs together: a chord iteration, each design's chord (and its renewals) kept between passes
    chord = ChordStiffness.of(prepared.tangent, designs.springs) \
        if count > 1 and prepared.tangent is not None else None

    def solve(rows: np.ndarray) -> np.ndarray:
        """Solve the designs *rows* from their current state and tensions; the ones that solved."""
        loads = _state_loads(designs.take(rows), prepared, tensions[rows])
        part = None if chord is None else chord.take(rows)
        solution = static_state(prepared.expansion, designs.springs.take(rows), prepared.base_force, loads, dq[rows],
                                part)
        for k, reason in solution.failures.items():
            failures[int(rows[k])] = UnstablePreloadError(
                f"{designs.cases[rows[k]].name}: the design's preload has no stable equilibrium ({reason})", [])
        for k in solution.unconverged:  # far from the prepared state, or a mechanism: the pipeline tells
            failures[int(rows[k])] = OutsideDesignModel(
                designs.cases[rows[k]].name, f"a preload its expansion does not bring to rest in {PRELOAD_STEPS} steps")
        dq[rows] = solution.dq
        forces[rows] = _channel_forces(prepared, designs.springs.take(rows), solution.dq)
        if keep_passes:
            passes.append((rows, solution.dq, tensions[rows].copy(), stiffened[rows].copy()))
        if chord is not None and part is not None:
            chord.put(rows, part)
        return np.delete(rows, [*solution.failures, *solution.unconverged])

    def link_tensions(rows: np.ndarray) -> np.ndarray:
        return -np.einsum("lcx,bcx->bl", prepared.compression, forces[rows])[:, prepared.flexible_positions]

    rows = solve(np.arange(count))
    if links and len(rows):
        found = link_tensions(rows)
        setting = designs.cases[0].effects.stress_stiffening
        for k, link in enumerate(links):
            for j in np.flatnonzero(-found[:, k] >= link.stiffening.buckling_load):
                failures.setdefault(int(rows[j]), BucklingError(designs.cases[rows[j]].name, link.name, -found[j, k],
                                                                link.stiffening.buckling_load, link.unloaded_hz))
            stiffened[rows, k] = True if setting == "on" else link.shift.shifted(found[:, k], AUTO_SHIFT)
        alive = np.array([k not in failures for k in rows], dtype=bool)
        rows, found = rows[alive], found[alive]
        tensions[rows] = np.where(stiffened[rows], found, 0.0)
        active = rows[stiffened[rows].any(axis=1)]
        solves = 1
        while len(active) and solves <= MAX_PASSES:
            active = solve(active)
            solves += 1
            new, used, chosen = link_tensions(active), tensions[active], stiffened[active]
            change = np.where(chosen, np.abs(new - used), 0.0).max(axis=1) / np.where(chosen, np.abs(used), 0.0).max(axis=1)
            going = ~((change <= TENSION_TOLERANCE) | (solves > MAX_PASSES))
            tensions[active[going]] = np.where(chosen, new, 0.0)[going]
            active = active[going]
    for k in sorted(set(range(count)) - set(failures)):
        far = _beyond_reach(designs.cases[k].name, dq[k, prepared.engine])
        if far is not None:
            failures[k] = far
    solved = np.array(sorted(set(range(count)) - set(failures)), dtype=int)
    state = _State(dq, tensions, stiffened, forces, _state_loads(designs, prepared, tensions))
    part = designs.take(solved)
    model = linear_model(prepared, part.springs, state.take(solved), part.casing_scale) if len(solved) else None
    return _SolvedItem(prepared, designs, state, model, solved, failures, passes)


@dataclass(frozen=True)
class ItemSolution:
    """One excitation item of a design, solved: what :mod:`workbook.design.sensitivity` differentiates."""

    prepared: _Item
    springs: ChannelSprings
    state: _State
    model: Harmonic

    @property
    def engine_static(self) -> np.ndarray:
        """The engine's static displacement at its centre of gravity (m) and its Rxyz rotation (rad)
        under the preload, shape (6,): its node coordinates, as ``mountwb loads`` gives them."""
        return (self.prepared.expansion.state + self.state.dq)[self.prepared.engine]


def linear_model(prepared: _Item, springs: ChannelSprings, state: _State, casing_scale) -> BodyHarmonic | Harmonic:
    """The projected linear model of the item *prepared* at the preloaded *state* (of one design or several,
    with their *springs* and casing moduli *casing_scale*, E / E_0), assembled body by body; kept body by
    body, or whole where the bodies' blocks would cost more
    (:attr:`~workbook.design.blocks.BodyLayout.by_body`)."""
    expansion, dq = prepared.expansion, state.dq
    channels, layout = expansion.channels, expansion.layout
    at = channels.state(total(expansion, dq))
    basis = projection(expansion, dq)
    mass, stiffness, damping = rest_matrices(expansion, dq, state.loads)
    add_tangent_terms(expansion, dq, stiffness, springs, at)
    structural = np.zeros_like(stiffness)
    for k, link in enumerate(prepared.links):
        added = (state.tensions[..., k] - link.base_tension)[..., None, None] * link.geometric
        block, positions = layout.locate(link.modal)
        damping[..., block, positions[:, None], positions] += link.stiffness_damping * added
        structural[..., block, positions[:, None], positions] += link.loss_factor * (link.reduced_stiffness + added)
    casing = prepared.casing
    if casing is not None:
        block, positions = layout.locate(casing.modal)
        damping[..., block, positions[:, None], positions] += \
            (np.sqrt(np.asarray(casing_scale, dtype=float)) - 1.0)[..., None, None] * casing.damping
    points = expansion.point_set
    points_state = points.state(total(expansion, dq), second=False)
    if not layout.by_body:
        jacobian = basis.columns(channels.jacobian(at))
        inputs = points.jacobian(points_state)
        return Harmonic(
            projected(expansion, mass, basis), projected(expansion, stiffness, basis)
            + spring_matrix(springs.stiffness, jacobian),
            projected(expansion, damping, basis) + spring_matrix(springs.damping, jacobian),
            projected(expansion, structural, basis) + prepared.sign * spring_matrix(springs.structural, jacobian),
            tuple(prepared.sign * spring_rows(spring, jacobian)
                  for spring in (springs.stiffness, springs.damping, springs.structural)),
            basis, {key: basis.rows(inputs[..., 3 * k:3 * k + 3, :].swapaxes(-1, -2))
                    for k, key in enumerate(expansion.points)})
    frames = layout.basis(basis.tangents)
    on_points = layout.point_jacobians(points, points_state, basis.tangents)
    bodies = layout.marker_rows(points)[0]
    return BodyHarmonic(
        layout, channels, expansion.coupling, layout.project(mass, frames), layout.project(stiffness, frames),
        layout.project(damping, frames), layout.project(structural, frames),
        layout.point_jacobians(channels, at, basis.tangents), springs, prepared.sign, basis,
        {key: (int(bodies[2 * k + 1]), on_points[..., 2 * k + 1, :, :]) for k, key in enumerate(expansion.points)})
