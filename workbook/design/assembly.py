"""Assemble and solve the linearised mount of a design from a scene expansion.

The arithmetic of :mod:`workbook.design.linear_mount`, on plain arrays:

- :func:`static_state`: Newton on the preload equilibrium in the
  independent coordinates (Euler parameters renormalised);
- :func:`tangent_stiffness`, :func:`rest_matrices` and :func:`projection`:
  the linearisation at a state, projected on the independent coordinates.

A channel with stiffness S (3x3, N/m) has the potential ``d^T S d / 2``:
generalised force ``J^T S d`` and tangent stiffness
``J^T S J + sum_k (S d)_k H_k``; its force output is ``sign S d`` with the
sign of Exudyn's ``Force`` output.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbook.design.channel_set import ChannelState
from workbook.design.expansion import SceneExpansion

__all__ = ["ChannelSprings", "StateLoads", "Projection", "total", "rest_stiffness", "rest_matrices", "turned_mass", "static_residual",
           "normal_components", "without_normal", "tangent_stiffness", "static_state", "projection",
           "NEWTON_TOLERANCE", "NEWTON_STEPS"]

#: Newton on the preload ends when the error it leaves is below this (relative to the state change):
#: when the last update is below its square root (quadratic convergence leaves an error of order its square).
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


def total(expansion: SceneExpansion, dq: np.ndarray) -> np.ndarray:
    """The total coordinates (reference plus state) at the state change *dq*."""
    return expansion.reference + expansion.state + dq


def rest_stiffness(expansion: SceneExpansion, dq: np.ndarray, loads: StateLoads) -> np.ndarray:
    """K of the rest of the scene at the state change *dq*, full coordinates."""
    stiffness = expansion.rest.stiffness_at(dq)
    for indices, added in loads.modal_stiffness:
        stiffness[np.ix_(indices, indices)] += added
    return stiffness


def rest_matrices(expansion: SceneExpansion, dq: np.ndarray, loads: StateLoads
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, K, D of the rest of the scene at the state change *dq*, full coordinates (M with each
    Euler-parameter body's rotation exact, :func:`turned_mass`)."""
    mass, damping = turned_mass(expansion, dq), expansion.rest.damping_at(dq)
    q = total(expansion, dq)
    for indices, added in loads.mass:
        mass[np.ix_(indices, indices)] += added(q[indices])
    return mass, rest_stiffness(expansion, dq, loads), damping


def _rotation(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A (E, 3, 3) and the local ``G`` (E, 3, 4) of unit Euler parameters *theta* (E, 4), as Exudyn's
    rigid-body nodes have them: body angular velocity ``G theta'``, global vector ``A v`` of a local v."""
    p0, pv = theta[:, 0], theta[:, 1:]
    skew = np.zeros((len(theta), 3, 3))
    skew[:, 0, 1], skew[:, 0, 2], skew[:, 1, 2] = -pv[:, 2], pv[:, 1], -pv[:, 0]
    skew -= skew.transpose(0, 2, 1)
    rotation = (2 * p0 ** 2 - 1)[:, None, None] * np.eye(3) + 2 * (np.einsum("ei,ej->eij", pv, pv)
                                                                  + p0[:, None, None] * skew)
    local = 2 * np.concatenate([-pv[:, :, None], p0[:, None, None] * np.eye(3) - skew], axis=2)
    return rotation, local


def turned_mass(expansion: SceneExpansion, dq: np.ndarray) -> np.ndarray:
    """The rest's M at the state change *dq*, full coordinates, each Euler-parameter body's rotation exact.

    A floating-frame body's kinetic energy depends on its velocities only
    through the local ones, ``A^T r'``, ``G theta'`` and the modal rates, and
    on its coordinates only through the modal ones; so its M at another
    rotation is ``S^T M S`` of its M at the prepared rotation, ``S_r = A_0 A^T``
    and ``S_theta = G_0^T G / 4`` on its position and parameters (identity
    elsewhere). The other coordinates change M to first order (the expansion's
    slopes). Without it M is of first order in the rotation: 1e-4 of a link's
    M at a hundredth of a radian, and the answers of a design far from the
    prepared one differ from the pipeline's by as much.
    """
    euler = expansion.euler_blocks
    if not len(euler):
        return expansion.rest.mass_at(dq)
    nodes = np.concatenate([euler[:, :1] - 3 + np.arange(3), euler], axis=1)      # (E, 7): position, parameters
    unturned = dq.copy()
    unturned[nodes] = 0.0
    mass = expansion.rest.mass_at(unturned)
    at = [total(expansion, change)[euler] for change in (np.zeros_like(dq), dq)]
    (base_rotation, base_local), (rotation, local) = (_rotation(theta / np.linalg.norm(theta, axis=1)[:, None])
                                                      for theta in at)
    turn = np.zeros((len(euler), 7, 7))
    turn[:, :3, :3] = base_rotation @ rotation.transpose(0, 2, 1)
    turn[:, 3:, 3:] = base_local.transpose(0, 2, 1) @ local / 4
    for index, block in zip(nodes, turn, strict=True):
        mass[:, index] = mass[:, index] @ block
        mass[index, :] = block.T @ mass[index, :]
    return mass


def normal_components(expansion: SceneExpansion, dq: np.ndarray, force: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Per Euler-parameter node: its unit parameters (E, 4) and ``theta . force / |theta|`` (E,).

    Exudyn applies a force to such a node through ``G^T``, which has no
    component along the parameters themselves; the true Jacobian of a
    position does. The difference is this normal component (removed from the
    force) and its derivative, ``-(theta . f) / |theta|^2`` on the tangent
    directions (added to the stiffness): the same linearisation as Exudyn's.
    """
    theta = total(expansion, dq)[expansion.euler_blocks]
    norm = np.linalg.norm(theta, axis=1)
    return theta / norm[:, None], np.einsum("ei,ei->e", theta, force[expansion.euler_blocks]) / norm


def without_normal(expansion: SceneExpansion, dq: np.ndarray, force: np.ndarray) -> np.ndarray:
    """*force* (N,) with its normal components on the Euler parameters removed (:func:`normal_components`)."""
    unit, normal = normal_components(expansion, dq, force)
    out = force.copy()
    out[expansion.euler_blocks] -= normal[:, None] * unit
    return out


def static_residual(expansion: SceneExpansion, dq: np.ndarray, springs: ChannelSprings, base_force: np.ndarray,
                    loads: StateLoads, state: ChannelState) -> np.ndarray:
    """Internal minus applied generalised force at the state change *dq*, full coordinates.

    *base_force* is the rest's internal force at the prepared state (minus the
    channels' there). The rest's force grows with its stiffness at the mid
    state (second order)."""
    residual = base_force - loads.force + expansion.rest.force_change(dq)
    q = total(expansion, dq)
    for indices, added in loads.modal_stiffness:
        residual[indices] += added @ q[indices]
    return residual + without_normal(expansion, dq, expansion.channels.force(state, springs.stiffness))


def tangent_stiffness(expansion: SceneExpansion, dq: np.ndarray, rest: np.ndarray,
                      springs: ChannelSprings, state: ChannelState) -> np.ndarray:
    """The rest's stiffness plus every channel's ``J^T S J + (S d) . H``, full coordinates, with
    Exudyn's term of the normal force components (:func:`normal_components`)."""
    channels = expansion.channels
    stiffness = rest + channels.matrix(state, springs.stiffness, stiffness=springs.stiffness)
    _, normal = normal_components(expansion, dq, channels.force(state, springs.stiffness))
    theta = total(expansion, dq)[expansion.euler_blocks]
    diagonal = expansion.euler_blocks
    stiffness[diagonal, diagonal] -= (normal / np.linalg.norm(theta, axis=1))[:, None]
    return stiffness


@dataclass(frozen=True)
class Projection:
    """The null space of the Euler-parameter constraints at a state: ``q = B x``.

    B keeps the free coordinates as they are and gives each Euler-parameter
    node three tangent directions; it is applied block by block, never formed.

    Attributes
    ----------
    free : ndarray of int, shape (f,)
        The coordinates that are independent as they are.
    euler : ndarray of int, shape (E, 4)
        Each Euler-parameter node's coordinates.
    tangents : ndarray, shape (E, 4, 3)
        Each node's orthonormal tangent basis.
    size : int
        N, the full coordinates.
    """

    free: np.ndarray
    euler: np.ndarray
    tangents: np.ndarray
    size: int

    def expand(self, independent: np.ndarray) -> np.ndarray:
        """``B @ independent`` (first axis: the f + 3 E independent coordinates)."""
        count = len(self.free)
        full = np.zeros((self.size,) + independent.shape[1:], dtype=independent.dtype)
        full[self.free] = independent[:count]
        nodes = independent[count:].reshape((len(self.euler), 3) + independent.shape[1:])
        full[self.euler] = np.einsum("eki,ei...->ek...", self.tangents, nodes)
        return full

    def columns(self, matrix: np.ndarray) -> np.ndarray:
        """``matrix @ B``."""
        nodes = np.einsum("mek,eki->mei", matrix[:, self.euler], self.tangents)
        return np.concatenate([matrix[:, self.free], nodes.reshape(len(matrix), -1)], axis=1)

    def rows(self, matrix: np.ndarray) -> np.ndarray:
        """``B.T @ matrix`` for a matrix (or vector) with the full coordinates as rows."""
        nodes = np.einsum("eki,ek...->ei...", self.tangents, matrix[self.euler])
        return np.concatenate([matrix[self.free], nodes.reshape((-1,) + matrix.shape[1:])], axis=0)

    def both(self, matrix: np.ndarray) -> np.ndarray:
        """``B.T @ matrix @ B``."""
        return self.rows(self.columns(matrix))


def projection(expansion: SceneExpansion, dq: np.ndarray) -> Projection:
    """The independent coordinates at the state change *dq*."""
    q = total(expansion, dq)
    euler = expansion.euler_blocks
    t0, t1, t2, t3 = (q[euler] / np.linalg.norm(q[euler], axis=1)[:, None]).T
    # an orthonormal basis (4, 3) of the directions normal to the unit parameters, per node
    tangents = np.stack([np.stack([-t1, t0, t3, -t2], axis=1), np.stack([-t2, -t3, t0, t1], axis=1),
                         np.stack([-t3, t2, -t1, t0], axis=1)], axis=2)
    return Projection(expansion.free, euler, tangents, len(q))


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
    for step in range(1, NEWTON_STEPS + 1):
        state = expansion.channels.state(total(expansion, dq))
        basis = projection(expansion, dq)
        stiffness = basis.both(tangent_stiffness(expansion, dq, rest_stiffness(expansion, dq, loads), springs, state))
        residual = basis.rows(static_residual(expansion, dq, springs, base_force, loads, state))
        update = np.linalg.solve(stiffness, -residual)
        full_update = basis.expand(update)
        q = total(expansion, dq + full_update)
        q[expansion.euler_blocks] /= np.linalg.norm(q[expansion.euler_blocks], axis=1)[:, None]
        dq = q - expansion.reference - expansion.state
        if np.abs(full_update).max() <= np.sqrt(NEWTON_TOLERANCE) * max(np.abs(dq).max(), STATE_SCALE):
            return dq, step
    raise np.linalg.LinAlgError(f"the preload did not converge in {NEWTON_STEPS} Newton steps")
