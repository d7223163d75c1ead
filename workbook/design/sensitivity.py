"""Derivatives of a design's T and hinge forces with respect to its parameters (the direct method).

A parameter (a name of :func:`workbook.studies.parametric.parameter`:
hinge stiffness, damping or loss factor, per hinge group and direction,
transducer stiffness, engine mass, a flexible casing's modulus) changes the
channel springs, the engine's mass and the casing's modulus E linearly;
those changes are exact differences at two values. The casing's reduced
stiffness is ``E / E_0 K_r`` and its modal damping ``sqrt(E / E_0) D_r``,
so ``dK/dE = K_r / E_0`` and ``dD/dE = D_r / (2 sqrt(E E_0))``. Through
them it moves, in order:

1. each preload solve of the stress-stiffening passes: ``dq = -K_t^-1
   (dR/dp + dR/dP dP/dp)``, the tensions P of a pass being the previous
   pass's link forces (``dP = -compression . dF``);
2. the linear model at the final state: its explicit change, the change of
   the links' stiffening with the tensions, and its change along ``dq``
   (the one part differenced: forward, a state step of
   :data:`STATE_STEP`, from the model at the state; central differences
   agree to 1e-7 and cost one more model per parameter);
3. each answer: ``du = Z^-1 (df - dZ u)``, ``dy = dC u + C du`` and
   ``d|y| = Re(conj(y) dy) / |y|``.

:func:`difference_sensitivity` differences whole evaluations, the check
of :func:`design_sensitivity` (``tests/test_design_sensitivity.py``).
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from workbook.design.assembly import (
    ChannelSprings,
    projection,
    rest_stiffness,
    tangent_stiffness,
    total,
    without_normal,
)
from workbook.design.channel_set import spring_matrix, spring_rows
from workbook.design.linear_mount import DesignAnswer, ItemSolution, LinearMount, linear_model, points_of
from workbook.model.case import DIRECTIONS, Case, Gravity

__all__ = ["DesignSensitivity", "design_sensitivity", "difference_sensitivity", "design_case", "point_change",
           "amplitude_change", "STATE_STEP"]

#: Largest coordinate change (m, rad, modal coordinates) of the forward difference along the state change.
STATE_STEP = 1e-6


@dataclass(frozen=True)
class DesignSensitivity:
    """A design's answers and their derivatives with respect to its parameters.

    Attributes
    ----------
    parameters : list of str
    values : ndarray, shape (P,)
        The design's parameter values (SI units).
    answer : DesignAnswer
    runs : list of str
    channels : list of str
        Force channels (hinges, then transducers).
    transmissibility : ndarray, shape (R, 3)
        T per run and direction.
    gradient : ndarray, shape (R, 3, P)
        dT/dp, per unit of each parameter.
    hinge_amplitudes : ndarray, shape (R, C, 3)
        ``|F|`` per run, channel and direction, N.
    hinge_gradient : ndarray, shape (R, C, 3, P)
        ``d|F|/dp``.
    method : str
        ``"direct"`` or ``"central differences"``.
    seconds : float
        Wall time, s.
    solutions : list of ItemSolution
        The direct method's solved excitation items (empty for differences).
    changes : list of list of (model, ndarray)
        Per item and parameter, the derivative of the item's linear model
        (a model of the same form) and of its state ``dq`` (empty for
        differences): what :mod:`workbook.design.optimise` differentiates
        the engine's static displacement and the mounted modes with.
    motions : list of (ndarray, ndarray)
        Per run, the projected motion phasor (n,) and its derivative (n, P)
        (empty for differences).
    """

    parameters: list
    values: np.ndarray
    answer: DesignAnswer
    runs: list
    channels: list
    transmissibility: np.ndarray
    gradient: np.ndarray
    hinge_amplitudes: np.ndarray
    hinge_gradient: np.ndarray
    method: str
    seconds: float
    solutions: list = dataclasses.field(default_factory=list)
    changes: list = dataclasses.field(default_factory=list)
    motions: list = dataclasses.field(default_factory=list)

    def to_pandas(self):
        """dT/dp as a table: one row per run and direction, one column per parameter."""
        import pandas as pd

        index = pd.MultiIndex.from_product([self.runs, [f"T {d}" for d in DIRECTIONS]], names=["run", "answer"])
        return pd.DataFrame(self.gradient.reshape(-1, len(self.parameters)), index=index,
                            columns=[f"d/d {name}" for name in self.parameters])


def design_case(mount: LinearMount, values: dict) -> Case:
    """The prepared case with the parameter *values* put in (its name kept)."""
    from workbook.studies.parametric import parameter

    case = mount.case
    for name, value in values.items():
        case = parameter(name).apply(case, value)
    return case


def _answers(answer: DesignAnswer, channels: list) -> tuple[list, np.ndarray, np.ndarray]:
    runs = answer.result.runs
    return ([run.name for run in runs], np.array([run.transmissibility for run in runs]),
            np.array([[run.hinge_amplitudes[name] for name in channels] for run in runs]))


def difference_sensitivity(mount: LinearMount, values: dict, relative_step: float = 1e-4) -> DesignSensitivity:
    """The derivatives by central differences of whole evaluations (step *relative_step* of each value,
    or of 1 where the value is 0)."""
    start = time.perf_counter()
    answer = mount.evaluate(design_case(mount, values))
    runs, t, hinges = _answers(answer, mount.channels)
    gradient = np.zeros(t.shape + (len(values),))
    hinge_gradient = np.zeros(hinges.shape + (len(values),))
    for j, (name, value) in enumerate(values.items()):
        step = relative_step * (abs(value) or 1.0)
        sides = [_answers(mount.evaluate(design_case(mount, {**values, name: value + sign * step})), mount.channels)
                 for sign in (1.0, -1.0)]
        gradient[..., j] = (sides[0][1] - sides[1][1]) / (2 * step)
        hinge_gradient[..., j] = (sides[0][2] - sides[1][2]) / (2 * step)
    return DesignSensitivity(list(values), np.array(list(values.values()), dtype=float), answer, runs,
                             list(mount.channels), t, gradient, hinges, hinge_gradient, "central differences",
                             time.perf_counter() - start)


def design_sensitivity(mount: LinearMount, values: dict) -> DesignSensitivity:
    """The design with the parameter *values* (name to SI value) answered, with dT/dp and d|F|/dp.

    Raises
    ------
    OutsideDesignModel
        A parameter the prepared mount does not follow.
    workbook.errors.SimulationError
        As :meth:`LinearMount.evaluate`.
    """
    start = time.perf_counter()
    case = design_case(mount, values)
    solutions = mount.solve_items(case)
    changes = [_parameter_change(mount, values, name, case, solutions[0].springs if solutions else None)
               for name in values]
    answer = mount.answer(case, solutions, start)
    runs, t, hinges = _answers(answer, mount.channels)
    gradient = np.zeros(t.shape + (len(values),))
    hinge_gradient = np.zeros(hinges.shape + (len(values),))
    pylon = [mount.channels.index(name) for name in mount.pylon]
    row = 0
    item_changes: list = []
    motions: list = []
    for item, solution in zip(case.excitations, solutions, strict=True):
        states = _state_changes(case, solution, changes)
        item_changes.append([_model_change(case, solution, change, state)
                             for change, state in zip(changes, states, strict=True)])
        models = [model for model, _ in item_changes[-1]]
        for excitation in points_of(item):
            motion, d_motion, forces, d_forces = point_change(solution, models, excitation)
            motions.append((motion, d_motion))
            pylon_force, d_pylon = forces[pylon].sum(axis=0), d_forces[pylon].sum(axis=0)
            hinge_gradient[row] = amplitude_change(forces[..., None], d_forces)
            gradient[row] = amplitude_change(pylon_force[:, None], d_pylon) / excitation.force_amplitude
            row += 1
    return DesignSensitivity(list(values), np.array(list(values.values()), dtype=float), answer, runs,
                             list(mount.channels), t, gradient, hinges, hinge_gradient, "direct",
                             time.perf_counter() - start, solutions, item_changes, motions)


def point_change(solution: ItemSolution, models: list, excitation) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                                              np.ndarray]:
    """One single-frequency excitation of a solved item and its derivatives along the model changes *models*.

    Returns
    -------
    motion : ndarray, complex, shape (n,)
        The projected motion phasor.
    d_motion : ndarray, complex, shape (n, P)
    forces : ndarray, complex, shape (C, 3)
        The channel force phasors, N.
    d_forces : ndarray, complex, shape (C, 3, P)
    """
    omega = 2 * np.pi * excitation.frequency
    model = solution.model
    lu = sla.lu_factor(model.dynamic(omega), check_finite=False)
    motion = sla.lu_solve(lu, model.load(excitation), check_finite=False)
    output = model.output(omega)
    forces = (output @ motion).reshape(-1, 3)
    d_motion = np.zeros((len(motion), len(models)), dtype=complex)
    d_forces = np.zeros(forces.shape + (len(models),), dtype=complex)
    for j, change in enumerate(models):
        d_motion[:, j] = sla.lu_solve(lu, change.load(excitation) - change.dynamic(omega) @ motion,
                                      check_finite=False)
        d_forces[..., j] = (change.output(omega) @ motion + output @ d_motion[:, j]).reshape(-1, 3)
    return motion, d_motion, forces, d_forces


def amplitude_change(phasor: np.ndarray, change: np.ndarray) -> np.ndarray:
    """``d|y| = Re(conj(y) dy) / |y|`` (0 where y is 0), broadcast (e.g. *phasor* (..., 1), *change* (..., P))."""
    shape = np.broadcast_shapes(phasor.shape, change.shape)
    size = np.broadcast_to(np.abs(phasor), shape)
    return np.divide(np.real(np.conj(phasor) * change), size, out=np.zeros(shape), where=size > 0)


@dataclass(frozen=True)
class _Change:
    """What one parameter changes, per unit of it: the springs, the engine's mass (kg) and the casing's modulus
    (Pa)."""

    springs: ChannelSprings
    mass: float
    modulus: float


def _parameter_change(mount: LinearMount, values: dict, name: str, case: Case, springs: ChannelSprings | None
                      ) -> _Change:
    """d(springs)/dp, d(engine mass)/dp and d(casing modulus)/dp: exact forward differences from the design
    *case* and its *springs* (None: found here), all being linear in each parameter."""
    from workbook.design.linear_mount import channel_springs

    value = values[name]
    step = 1e-3 * (abs(value) or 1.0)
    changed = design_case(mount, {**values, name: value + step})
    base = channel_springs(case, mount.channels) if springs is None else springs
    change = ChannelSprings(*((a - b) / step for a, b in zip(
        dataclasses.astuple(channel_springs(changed, mount.channels)), dataclasses.astuple(base),
        strict=True)))
    casing, other = case.engine.casing, changed.engine.casing
    modulus = 0.0 if casing is None or other is None else \
        (other.material.youngs_modulus - casing.material.youngs_modulus) / step
    return _Change(change, (changed.engine.mass - case.engine.mass) / step, modulus)


def _casing_stiffness_change(solution: ItemSolution, case: Case, modulus: float) -> tuple[np.ndarray, np.ndarray]:
    """The casing's modal coordinates and the change of its reduced stiffness by the modulus change *modulus*
    (Pa per unit of the parameter; coordinates empty without a casing)."""
    casing = solution.prepared.casing
    if casing is None or modulus == 0.0:
        return np.zeros(0, dtype=int), np.zeros((0, 0))
    return casing.modal, modulus / casing.modulus * casing.stiffness


def _state_changes(case: Case, solution: ItemSolution, changes: list) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per parameter change (:class:`_Change`): d(dq)/dp of the final preload solve and d(tension)/dp of
    each stiffened link, in pass order (each pass's tangent stiffness factorised once for all of them)."""
    prepared, base = solution.prepared, solution.springs
    expansion = prepared.expansion
    channels = expansion.channels
    gravity = np.zeros(prepared.size)
    if case.effects.preload:
        for load in case.static_loads:
            if isinstance(load, Gravity):
                gravity[prepared.engine[:3]] += np.asarray(load.acceleration)
    d_tension = [np.zeros(len(prepared.links)) for _ in changes]
    d_state = [np.zeros(prepared.size) for _ in changes]
    d_forces: list = [None for _ in changes]
    for dq, stiffened, loads in solution.state.passes:
        at = channels.state(total(expansion, dq))
        q = total(expansion, dq)
        basis = projection(expansion, dq)
        channel_jacobian = channels.jacobian(at)
        factor = sla.lu_factor(tangent_stiffness(expansion, dq, rest_stiffness(expansion, dq, loads), base, at, basis,
                                                 basis.columns(channel_jacobian)), check_finite=False)
        force_rows = spring_rows(base.stiffness, channel_jacobian)       # the channel forces per state change
        for j, change in enumerate(changes):
            springs = change.springs
            if d_forces[j] is not None:
                by_link = -np.einsum("lcx,cx->l", prepared.compression, d_forces[j])
                d_tension[j] = np.where(stiffened, by_link[prepared.flexible_positions], 0.0)
            residual = without_normal(expansion, dq, channels.force(at, springs.stiffness)) - change.mass * gravity
            for link, tension in zip(prepared.links, d_tension[j], strict=True):
                residual[link.modal] += tension * (link.geometric @ q[link.modal])
            modal, casing = _casing_stiffness_change(solution, case, change.modulus)
            residual[modal] += casing @ q[modal]
            d_state[j] = basis.expand(sla.lu_solve(factor, -basis.rows(residual), check_finite=False))
            d_forces[j] = prepared.sign * (np.einsum("cab,cb->ca", springs.stiffness, at.separation)
                                           + (force_rows @ d_state[j]).reshape(-1, 3))
    return list(zip(d_state, d_tension, strict=True))


def _model_change(case: Case, solution: ItemSolution, change: _Change, state_change: tuple):
    """The derivative of the item's linear model (a model of the same form: Z, C and f are linear in it)
    and of its state ``dq``, given the parameter's *change* and the derivative of the state and tensions
    (:func:`_state_changes`)."""
    prepared, state, model = solution.prepared, solution.state, solution.model
    springs, mass = change.springs, change.mass
    expansion = prepared.expansion
    d_state, d_tension = state_change
    # along the state change: a forward difference of the whole linear model
    step = STATE_STEP / max(np.abs(d_state).max(), 1e-300)
    scale = 1.0 if prepared.casing is None else prepared.casing.scale(case)
    moved = linear_model(prepared, solution.springs, dataclasses.replace(state, dq=state.dq + step * d_state),
                         scale).dense()
    basis = model.basis
    at = expansion.channels.state(total(expansion, state.dq))
    channels = expansion.channels
    jacobian = basis.columns(channels.jacobian(at))
    stiffness = tangent_stiffness(expansion, state.dq, np.zeros(expansion.rest.stiffness.shape), springs, at, basis,
                                  jacobian)
    damping = spring_matrix(springs.damping, jacobian)
    structural = prepared.sign * spring_matrix(springs.structural, jacobian)
    engine_mass = np.zeros((prepared.size,) * 2)
    engine_mass[prepared.engine[:3], prepared.engine[:3]] = mass
    added_mass = basis.both(engine_mass)
    for link, tension in zip(prepared.links, d_tension, strict=True):
        geometric = np.zeros((prepared.size,) * 2)
        geometric[np.ix_(link.modal, link.modal)] = tension * link.geometric
        projected = basis.both(geometric)
        stiffness = stiffness + projected
        damping = damping + link.stiffness_damping * projected
        structural = structural + link.loss_factor * projected
    modal, casing_stiffness = _casing_stiffness_change(solution, case, change.modulus)
    if len(modal):
        casing = prepared.casing
        assert casing is not None
        block = np.ix_(modal, modal)
        full = np.zeros((prepared.size,) * 2)
        full[block] = casing_stiffness
        stiffness = stiffness + basis.both(full)
        full[block] = change.modulus / (2.0 * np.sqrt(casing.scale(case)) * casing.modulus) * casing.damping
        damping = damping + basis.both(full)
    outputs = tuple(prepared.sign * spring_rows(spring, jacobian)
                    for spring in (springs.stiffness, springs.damping, springs.structural))

    def along(field: str):
        return (getattr(moved, field) - getattr(model, field)) / step

    return dataclasses.replace(
        model, mass=added_mass + along("mass"), stiffness=stiffness + along("stiffness"),
        damping=damping + along("damping"), structural=structural + along("structural"),
        outputs=tuple(o + (a - b) / step for o, a, b in zip(outputs, moved.outputs, model.outputs, strict=True)),
        inputs={key: (moved.inputs[key] - model.inputs[key]) / step for key in model.inputs}), d_state
