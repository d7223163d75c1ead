"""Assemble and solve the linearised mount of a design from a scene expansion.

The arithmetic of :mod:`workbook.design.linear_mount`, on plain arrays:

- :func:`channel_state`: each force channel's marker separation and its
  Jacobian at a change of state ``dq`` (second order);
- :func:`static_state`: Newton on the preload equilibrium in the
  independent coordinates (Euler parameters renormalised);
- :func:`linear_matrices`: M, K, D, H, the channel outputs and the
  excitation inputs at a state, projected on the independent coordinates.

A channel with stiffness S (3x3, N/m) has the potential ``d^T S d / 2``:
generalised force ``J^T S d`` and tangent stiffness
``J^T S J + sum_k (S d)_k H_k``; its force output is ``sign S d`` with the
sign of Exudyn's ``Force`` output.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from workbook.design.expansion import SceneExpansion

__all__ = ["ChannelSprings", "StateLoads", "Projection", "channel_state", "rest_matrices", "static_residual",
           "channel_force", "normal_components",
           "tangent_stiffness", "static_state", "projection", "NEWTON_TOLERANCE", "NEWTON_STEPS"]

#: Newton on the preload ends when the update is below this (relative to the state change).
NEWTON_TOLERANCE = 1e-10
#: Smallest state change the tolerance is relative to (m, rad, modal coordinates).
STATE_SCALE = 1e-3
#: Most Newton steps of one preload solve.
NEWTON_STEPS = 20


@dataclass(frozen=True)
class ChannelSprings:
    """The design's springs of every force channel, global coordinates.

    Attributes
    ----------
    stiffness, damping, structural : ndarray, shape (c, 3, 3)
        S (N/m), S_d (N s/m) and the hysteretic matrix ``E S`` of the loss
        factors (N/m; zero without).
    """

    stiffness: np.ndarray
    damping: np.ndarray
    structural: np.ndarray


@dataclass(frozen=True)
class StateLoads:
    """What a design changes in the rest of the scene.

    Attributes
    ----------
    modal_stiffness : list of (ndarray of int, ndarray)
        Added stiffness on modal coordinates: (indices, matrix) per stiffened link.
    mass : list of (ndarray of int, callable)
        Added mass on coordinates: (indices, ``f(q) -> matrix``).
    force : ndarray, shape (N,)
        Added applied force (e.g. the weight of added engine mass), N.
    """

    modal_stiffness: list
    mass: list
    force: np.ndarray


def channel_state(expansion: SceneExpansion, dq: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Marker separation (m), its Jacobian and Hessian of every channel at the state change *dq*."""
    q = expansion.reference + expansion.state + dq
    return [geometry.separation(q) for geometry in expansion.channels.values()]


def rest_matrices(expansion: SceneExpansion, dq: np.ndarray, size: int, loads: StateLoads
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, K, D of the rest of the scene at the state change *dq*, full coordinates."""
    mass, stiffness, damping = (np.zeros((size, size)) for _ in range(3))
    for block in expansion.blocks:
        local = dq[block.coordinates]
        rows = np.ix_(block.coordinates, block.coordinates)
        mass[rows] = block.mass + block.mass_slope @ local
        stiffness[rows] = block.stiffness + block.stiffness_slope @ local
        damping[rows] = block.damping + block.damping_slope @ local
    for indices, added in loads.modal_stiffness:
        stiffness[np.ix_(indices, indices)] += added
    q = expansion.reference + expansion.state + dq
    for indices, added in loads.mass:
        mass[np.ix_(indices, indices)] += added(q[indices])
    return mass, stiffness, damping


def channel_force(expansion: SceneExpansion, springs: ChannelSprings, states) -> np.ndarray:
    """``sum_c J_c^T S_c d_c``: the channels' generalised force with the true position Jacobians, full coordinates."""
    force = np.zeros(len(expansion.state))
    for (separation, jacobian, _), geometry, stiffness in zip(states, expansion.channels.values(), springs.stiffness,
                                                              strict=True):
        force[geometry.coordinates] += jacobian.T @ (stiffness @ separation)
    return force


def normal_components(expansion: SceneExpansion, dq: np.ndarray, force: np.ndarray) -> list[tuple]:
    """Per Euler-parameter node: its coordinates, unit parameters and ``theta . force / |theta|``.

    Exudyn applies a force to such a node through ``G^T``, which has no
    component along the parameters themselves; the true Jacobian of a
    position does. The difference is this normal component (removed from the
    force) and its derivative, ``-(theta . f) / |theta|^2`` on the tangent
    directions (added to the stiffness): the same linearisation as Exudyn's.
    """
    q = expansion.reference + expansion.state + dq
    parts = []
    for indices in expansion.euler_blocks:
        norm = np.linalg.norm(q[indices])
        parts.append((indices, q[indices] / norm, float(q[indices] @ force[indices]) / norm))
    return parts


def static_residual(expansion: SceneExpansion, dq: np.ndarray, springs: ChannelSprings, base_force: np.ndarray,
                    loads: StateLoads, states) -> np.ndarray:
    """Internal minus applied generalised force at the state change *dq*, full coordinates.

    *base_force* is the rest's internal force at the prepared state (minus the
    channels' there). The rest's force grows with its stiffness at the mid
    state (second order)."""
    residual = base_force - loads.force
    for block in expansion.blocks:
        local = dq[block.coordinates]
        residual[block.coordinates] += (block.stiffness + 0.5 * (block.stiffness_slope @ local)) @ local
    q = expansion.reference + expansion.state + dq
    for indices, added in loads.modal_stiffness:
        residual[indices] += added @ q[indices]
    force = channel_force(expansion, springs, states)
    for indices, unit, normal in normal_components(expansion, dq, force):
        force[indices] -= normal * unit
    return residual + force


def tangent_stiffness(expansion: SceneExpansion, dq: np.ndarray, rest_stiffness: np.ndarray,
                      springs: ChannelSprings, states) -> np.ndarray:
    """The rest's stiffness plus every channel's ``J^T S J + (S d) . H``, full coordinates, with
    Exudyn's term of the normal force components (:func:`normal_components`)."""
    stiffness = rest_stiffness.copy()
    for indices, _, normal in normal_components(expansion, dq, channel_force(expansion, springs, states)):
        stiffness[np.ix_(indices, indices)] -= normal / np.linalg.norm(
            (expansion.reference + expansion.state + dq)[indices]) * np.eye(4)
    for (separation, jacobian, hessian), geometry, spring in zip(states, expansion.channels.values(),
                                                                 springs.stiffness, strict=True):
        force = spring @ separation
        rows = np.ix_(geometry.coordinates, geometry.coordinates)
        stiffness[rows] += jacobian.T @ spring @ jacobian + np.tensordot(force, hessian, axes=1)
    return stiffness


@dataclass(frozen=True)
class Projection:
    """The null space of the Euler-parameter constraints at a state: ``q = basis @ x``.

    Attributes
    ----------
    free : ndarray of int
        Coordinates that are independent as they are.
    euler : list of (ndarray of int, ndarray (4, 3))
        Each Euler-parameter node's coordinates and its tangent basis.
    size : int
        Number of independent coordinates.
    """

    free: np.ndarray
    euler: list
    size: int

    def columns(self, matrix: np.ndarray) -> np.ndarray:
        """``matrix @ basis`` for a matrix with the full coordinates as columns."""
        parts = [matrix[:, self.free]] + [matrix[:, indices] @ tangent for indices, tangent in self.euler]
        return np.concatenate(parts, axis=1)

    def rows(self, matrix: np.ndarray) -> np.ndarray:
        """``basis.T @ matrix`` for a matrix (or vector) with the full coordinates as rows."""
        parts = [matrix[self.free]] + [tangent.T @ matrix[indices] for indices, tangent in self.euler]
        return np.concatenate(parts, axis=0)

    def both(self, matrix: np.ndarray) -> np.ndarray:
        """``basis.T @ matrix @ basis``."""
        return self.rows(self.columns(matrix))


def _euler_tangent(theta: np.ndarray) -> np.ndarray:
    """An orthonormal basis (4, 3) of the directions normal to *theta* (unit Euler parameters)."""
    t0, t1, t2, t3 = theta
    return np.array([[-t1, t0, t3, -t2], [-t2, -t3, t0, t1], [-t3, t2, -t1, t0]]).T


def projection(expansion: SceneExpansion, dq: np.ndarray) -> Projection:
    """The independent coordinates at the state change *dq*."""
    q = expansion.reference + expansion.state + dq
    constrained = np.concatenate(expansion.euler_blocks) if expansion.euler_blocks else np.zeros(0, dtype=int)
    free = np.setdiff1d(np.arange(len(q)), constrained)
    euler = [(indices, _euler_tangent(q[indices])) for indices in expansion.euler_blocks]
    return Projection(free, euler, len(free) + 3 * len(euler))


def static_state(expansion: SceneExpansion, springs: ChannelSprings, base_force: np.ndarray, loads: StateLoads,
                 start: np.ndarray) -> tuple[np.ndarray, int]:
    """The preload equilibrium's state change from the prepared state, by Newton from *start*.

    Returns
    -------
    dq : ndarray, shape (N,)
    steps : int
        Newton steps taken.

    Raises
    ------
    numpy.linalg.LinAlgError
        The projected tangent stiffness is singular or Newton did not converge.
    """
    dq = start.copy()
    size = len(dq)
    for step in range(1, NEWTON_STEPS + 1):
        states = channel_state(expansion, dq)
        _, rest_stiffness, _ = rest_matrices(expansion, dq, size, loads)
        basis = projection(expansion, dq)
        stiffness = basis.both(tangent_stiffness(expansion, dq, rest_stiffness, springs, states))
        residual = basis.rows(static_residual(expansion, dq, springs, base_force, loads, states))
        update = sla.solve(stiffness, -residual, assume_a="sym", check_finite=False)
        full_update = _expand(basis, update, size)
        dq = dq + full_update
        q = expansion.reference + expansion.state + dq
        for indices in expansion.euler_blocks:
            q[indices] /= np.linalg.norm(q[indices])
        dq = q - expansion.reference - expansion.state
        if np.abs(full_update).max() <= NEWTON_TOLERANCE * max(np.abs(dq).max(), STATE_SCALE):
            return dq, step
    raise np.linalg.LinAlgError(f"the preload did not converge in {NEWTON_STEPS} Newton steps")


def _expand(basis: Projection, independent: np.ndarray, size: int) -> np.ndarray:
    """``basis @ independent``: the full coordinates of an independent vector."""
    full = np.zeros(size)
    full[basis.free] = independent[:len(basis.free)]
    column = len(basis.free)
    for indices, tangent in basis.euler:
        full[indices] += tangent @ independent[column:column + 3]
        column += 3
    return full
