"""The preload equilibrium of designs: Newton, or a chord iteration on the prepared tangent.

Designs answered together take a chord iteration (:func:`static_state`):
its matrix is the prepared design's tangent stiffness ``T_0`` with each
design's own channel springs, ``T_0 + J_0^T (S - S_0) J_0`` on the
prepared channel Jacobian ``J_0`` (:class:`ChordStiffness`), solved by the
Woodbury identity. ``T_0`` is inverted once per prepared item; a design then
costs a solve of the size of its channels' 3 C coordinates, not of its n
independent coordinates. What the chord leaves out (the state's change, the
channels' curvature, other link tensions or casing moduli) only slows the
convergence; a design whose updates shrink too slowly has its own tangent
inverted at its current state.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbook.design.assembly import (
    ChannelSprings,
    Projection,
    StateLoads,
    projection,
    rest_stiffness,
    solve_each,
    static_residual,
    tangent_stiffness,
    total,
)
from workbook.design.expansion import SceneExpansion

__all__ = ["ChordStiffness", "PreparedTangent", "prepared_tangent", "static_state", "StaticSolution",
           "NEWTON_TOLERANCE", "CHORD_TOLERANCE", "PRELOAD_STEPS", "RENEWAL_RATE"]

#: Newton ends when an update is below the square root of this (relative to the state change): the error
#: left, of the order of the update's square.
NEWTON_TOLERANCE = 1e-10
#: The chord iteration ends when the error its updates leave is below this (relative to the state change):
#: it converges linearly, a step for each factor of about 100, and a state this close changes T far less
#: than the 1e-6 the evaluation answers to (``benchmarks/bench_design_evaluation.py`` compares designs
#: together with the same designs alone, solved by Newton).
CHORD_TOLERANCE = 1e-7
#: Smallest state change the tolerance is relative to (m, rad, modal coordinates).
STATE_SCALE = 1e-3
#: Most steps of one preload solve.
PRELOAD_STEPS = 40
#: A design's chord stiffness is renewed (its own tangent) when its updates shrink by less than this factor per step.
RENEWAL_RATE = 0.1


@dataclass(frozen=True)
class PreparedTangent:
    """The prepared design's projected tangent stiffness at the prepared state, inverted once.

    Attributes
    ----------
    inverse : ndarray, shape (n, n)
        ``T_0^-1``.
    jacobian : ndarray, shape (3 C, n)
        ``J_0``, the channels' projected Jacobian.
    reach : ndarray, shape (n, 3 C)
        ``T_0^-1 J_0^T``.
    coupling : ndarray, shape (3 C, 3 C)
        ``J_0 T_0^-1 J_0^T``.
    springs : ndarray, shape (C, 3, 3)
        ``S_0``, the prepared channel stiffness, N/m.
    """

    inverse: np.ndarray
    jacobian: np.ndarray
    reach: np.ndarray
    coupling: np.ndarray
    springs: np.ndarray


def prepared_tangent(expansion: SceneExpansion, springs: ChannelSprings, loads: StateLoads) -> PreparedTangent | None:
    """The :class:`PreparedTangent` of the prepared state (one design's *springs* and *loads*), or None when
    that tangent is singular."""
    failures: dict[int, str] = {}
    dq = np.zeros((1, len(expansion.state)))
    inverse = _tangent_inverse(expansion, springs.take(np.newaxis), loads.take(np.newaxis), dq, failures)[0]
    if failures:
        return None
    state = expansion.channels.state(total(expansion, dq[0]), second=False)
    jacobian = projection(expansion, dq[0]).columns(expansion.channels.jacobian(state))
    reach = inverse @ jacobian.T
    return PreparedTangent(inverse, jacobian, reach, jacobian @ reach, springs.stiffness)


@dataclass(frozen=True)
class ChordStiffness:
    """The chord matrices of B designs: the prepared tangent with each design's springs, or its own tangent.

    Only the channels whose springs some design changes enter the Woodbury
    update (a study that varies the front hinges updates their 12
    coordinates, not all 3 C).

    Attributes
    ----------
    prepared : PreparedTangent
    changed : ndarray of int
        The channels' coordinates (of the 3 C) whose springs any of the designs changes.
    capacitance : ndarray, shape (B, m, m)
        ``(I + dS G)^-1 dS`` of each design's spring change ``dS = S - S_0`` and ``G = J_0 T_0^-1 J_0^T``, on
        the *changed* coordinates (m of them): the chord's inverse is ``T_0^-1 - T_0^-1 J_0^T capacitance J_0
        T_0^-1`` (Woodbury).
    own : dict of int to ndarray, shape (n, n)
        The inverse tangent of each design renewed at its own state, by its position.
    singular : ndarray of bool, shape (B,)
        The designs whose chord is singular: :func:`static_state` starts them with their own tangent.
    """

    prepared: PreparedTangent
    changed: np.ndarray
    capacitance: np.ndarray
    own: dict
    singular: np.ndarray

    @classmethod
    def of(cls, prepared: PreparedTangent, springs: ChannelSprings) -> "ChordStiffness":
        """The chords of designs with the channel springs *springs* (leading axis B)."""
        change = springs.stiffness - prepared.springs
        moved = np.flatnonzero(np.any(change != 0.0, axis=(0, 2, 3)))        # the channels some design changes
        count, channels = len(change), len(moved)
        blocks = np.zeros((count, channels, 3, channels, 3))
        blocks[:, np.arange(channels), :, np.arange(channels), :] = change[:, moved].transpose(1, 0, 2, 3)
        spring_change = blocks.reshape(count, 3 * channels, 3 * channels)
        changed = (3 * moved[:, None] + np.arange(3)).ravel()
        capacitance, singular = solve_each(np.eye(3 * channels) + spring_change @ prepared.coupling[np.ix_(changed, changed)],
                                           spring_change)
        return cls(prepared, changed, capacitance, {}, singular)

    def take(self, rows: np.ndarray) -> "ChordStiffness":
        """The designs *rows*."""
        own = {k: self.own[int(row)] for k, row in enumerate(rows) if int(row) in self.own}
        return ChordStiffness(self.prepared, self.changed, self.capacitance[rows], own, self.singular[rows])

    def put(self, rows: np.ndarray, part: "ChordStiffness") -> None:
        """Keep the renewals of the chords *part* of the designs *rows*."""
        self.own.update({int(rows[k]): inverse for k, inverse in part.own.items()})

    def solve(self, rows: np.ndarray, residual: np.ndarray) -> np.ndarray:
        """The chord's solution for the designs *rows* with the right-hand sides *residual* (len(rows), n)."""
        prepared, changed = self.prepared, self.changed
        plain = residual @ prepared.inverse.T
        spread = (self.capacitance[rows] @ (plain @ prepared.jacobian[changed].T)[..., None])[..., 0]
        solution = plain - spread @ prepared.reach[:, changed].T
        for k, row in enumerate(rows):
            if int(row) in self.own:
                solution[k] = self.own[int(row)] @ residual[k]
        return solution


def static_state(expansion: SceneExpansion, springs: ChannelSprings, base_force: np.ndarray, loads: StateLoads,
                 start: np.ndarray, chord: ChordStiffness | None = None) -> "StaticSolution":
    """The preload equilibrium's state change from the prepared state of each design, from *start*.

    With a *chord*, a chord iteration (for designs together): a design's
    chord is renewed with its own tangent at its current state when its
    updates shrink by less than :data:`RENEWAL_RATE` per step; a design has
    converged when the error its updates leave (``rate / (1 - rate)`` times
    the last update) is below :data:`CHORD_TOLERANCE` of its state change.
    Without, Newton with a tangent per step (for one design, whose cost is
    mostly NumPy's per call: fewer steps win), converged when an update is
    below the square root of :data:`NEWTON_TOLERANCE` (quadratic convergence
    leaves an error of the order of its square).

    Parameters
    ----------
    springs, loads
        Per design (leading axis B).
    start : ndarray, shape (B, N)
    chord : ChordStiffness, optional
        The designs' chords (a renewal changes it).
    """
    dq = start.copy()
    count = len(dq)
    steps = np.zeros(count, dtype=int)
    failures: dict[int, str] = {}
    if chord is not None:
        _renew(chord, np.array([k for k in np.flatnonzero(chord.singular) if int(k) not in chord.own], dtype=int),
               expansion, springs, loads, dq, failures)
    last = np.full(count, np.inf)
    active = np.array([k for k in range(count) if k not in failures], dtype=int)
    for step in range(1, PRELOAD_STEPS + 1):
        part, part_springs, part_loads = dq[active], springs.take(active), loads.take(active)
        state = expansion.channels.state(total(expansion, part), second=chord is None)
        basis = projection(expansion, part)
        residual = basis.rows(static_residual(expansion, part, part_springs, base_force, part_loads, state))
        if chord is not None:
            update = -chord.solve(active, residual)
        else:
            tangent = tangent_stiffness(expansion, part, rest_stiffness(expansion, part, part_loads), part_springs,
                                        state, basis, basis.columns(expansion.channels.jacobian(state)))
            update, singular = solve_each(tangent, -residual)
            for k in np.flatnonzero(singular):
                failures[int(active[k])] = "its tangent stiffness is singular"
        full_update = basis.expand(update)
        q = total(expansion, part + full_update)
        q[..., expansion.euler_blocks] /= np.linalg.norm(q[..., expansion.euler_blocks], axis=-1)[..., None]
        moved = q - expansion.reference - expansion.state
        dq[active] = moved
        size = np.abs(full_update).max(axis=-1) / np.maximum(np.abs(moved).max(axis=-1), STATE_SCALE)
        known = np.isfinite(last[active])
        rate = np.where(known, size / np.where(known, last[active], 1.0), np.inf)
        last[active] = size
        shrinking = rate < 1.0
        left = np.full(len(rate), np.inf)                 # the error the updates leave
        left[shrinking] = rate[shrinking] * size[shrinking] / (1.0 - rate[shrinking])
        converged = (size <= np.sqrt(NEWTON_TOLERANCE)) if chord is None else \
            (size <= CHORD_TOLERANCE) | (left <= CHORD_TOLERANCE)
        steps[active[converged]] = step
        going = ~converged & np.array([int(k) not in failures for k in active], dtype=bool)
        renew = active[going & known & (rate > RENEWAL_RATE)] if chord is not None else np.zeros(0, dtype=int)
        active = active[going]
        if len(renew):
            assert chord is not None
            _renew(chord, renew, expansion, springs, loads, dq, failures)
            last[renew] = np.inf
            active = np.array([k for k in active if k not in failures], dtype=int)
        if not len(active):
            break
    return StaticSolution(dq, steps, failures, tuple(int(k) for k in active))


def _renew(chord: ChordStiffness, rows: np.ndarray, expansion: SceneExpansion, springs: ChannelSprings,
           loads: StateLoads, dq: np.ndarray, failures: dict) -> None:
    """Give the designs *rows* of *chord* their own tangent at their states *dq*; a singular one is noted in
    *failures*."""
    if not len(rows):
        return
    found: dict[int, str] = {}
    inverses = _tangent_inverse(expansion, springs.take(rows), loads.take(rows), dq[rows], found)
    chord.own.update({int(k): inverse for k, inverse in zip(rows, inverses, strict=True)})
    failures.update({int(rows[k]): reason for k, reason in found.items()})


@dataclass(frozen=True)
class StaticSolution:
    """The preload equilibria of B designs (:func:`static_state`).

    Attributes
    ----------
    dq : ndarray, shape (B, N)
    steps : ndarray of int, shape (B,)
        Steps each design took.
    failures : dict of int to str
        The designs whose tangent stiffness was singular, with the reason
        (their rows of *dq* mean nothing).
    unconverged : tuple of int
        The designs not brought to rest in :data:`PRELOAD_STEPS` steps
        (their rows of *dq* mean nothing).
    """

    dq: np.ndarray
    steps: np.ndarray
    failures: dict
    unconverged: tuple = ()


def _tangent_inverse(expansion: SceneExpansion, springs: ChannelSprings, loads: StateLoads, dq: np.ndarray,
                     failures: dict) -> np.ndarray:
    """The inverse projected tangent stiffness at *dq* (B, N) per design, (B, n, n); a singular one is noted
    in *failures* (its inverse is zero). Designs all at the prepared state share its kinematics."""
    at = dq[0] if not dq.any() else dq
    state = expansion.channels.state(total(expansion, at))
    basis = projection(expansion, at)
    jacobian = basis.columns(expansion.channels.jacobian(state))
    basis = Projection(basis.free, basis.euler, np.broadcast_to(basis.tangents, dq.shape[:-1] + basis.tangents.shape[-3:]),
                       basis.size)
    rest = rest_stiffness(expansion, at, loads)
    rest = np.array(np.broadcast_to(rest, dq.shape[:-1] + rest.shape[-3:]))
    tangent = tangent_stiffness(expansion, at, rest, springs, state, basis, jacobian)
    inverse, singular = solve_each(tangent, np.broadcast_to(np.eye(tangent.shape[-1]), tangent.shape))
    for k in np.flatnonzero(singular):
        failures[int(k)] = "its tangent stiffness is singular"
    return inverse
