"""Assemble and solve the linearised mount of a design from a scene expansion.

The arithmetic of :mod:`workbook.design.linear_mount`, on plain arrays:
:func:`static_residual`, the preload's residual that
:mod:`workbook.design.equilibrium` solves; :func:`tangent_stiffness`,
:func:`rest_matrices` and :func:`projection`, the linearisation at a state,
projected on the independent coordinates (Euler parameters renormalised).

A channel with stiffness S (3x3, N/m) has the potential ``d^T S d / 2``:
generalised force ``J^T S d`` and tangent stiffness
``J^T S J + sum_k (S d)_k H_k``; its force output is ``sign S d`` with the
sign of Exudyn's ``Force`` output.

Every function takes one state, ``dq`` of shape (N,), or one per design,
shape (B, N), with the design-dependent arguments (springs, loads) likewise.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbook.design.channel_set import ChannelState, spring_matrix
from workbook.design.expansion import SceneExpansion

__all__ = ["ChannelSprings", "AddedRigidMass", "StateLoads", "Projection", "total", "rest_stiffness",
           "rest_matrices", "turned_mass", "static_residual", "normal_components", "without_normal",
           "tangent_stiffness", "projected", "solve_each", "projection"]

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

    def take(self, rows: np.ndarray | int | None) -> "ChannelSprings":
        """The designs *rows* of springs given per design (leading axis; an index: one design without it;
        None: one design as a batch of one)."""
        return ChannelSprings(self.stiffness[rows], self.damping[rows], self.structural[rows])


@dataclass(frozen=True)
class AddedRigidMass:
    """Mass and inertia added to a rigid body whose node has Tait-Bryan (Rxyz) angles, per design.

    Attributes
    ----------
    coordinates : ndarray of int, shape (6,)
        The node's position and angles among the full coordinates.
    mass : ndarray, shape (...)
        kg.
    inertia : ndarray, shape (..., 3, 3)
        About the centre of gravity, body axes, kg m^2.
    """

    coordinates: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray

    def matrix(self, q: np.ndarray) -> np.ndarray:
        """The added M (..., 6, 6) at the node's total coordinates *q* (..., 6)."""
        rotation = _angular_velocity_map(q[..., 3:6])
        block = np.zeros(q.shape[:-1] + (6, 6))
        block[..., :3, :3] = np.asarray(self.mass)[..., None, None] * np.eye(3)
        block[..., 3:, 3:] = rotation.swapaxes(-1, -2) @ self.inertia @ rotation
        return block

    def take(self, rows: np.ndarray | int | None) -> "AddedRigidMass":
        """The designs *rows*."""
        return AddedRigidMass(self.coordinates, self.mass[rows], self.inertia[rows])


def _angular_velocity_map(angles: np.ndarray) -> np.ndarray:
    """``G`` of Exudyn's Tait-Bryan (Rxyz) angles (..., 3): body angular velocity = G @ angle rates, (..., 3, 3)."""
    b, c = angles[..., 1], angles[..., 2]
    out = np.zeros(angles.shape[:-1] + (3, 3))
    out[..., 0, 0], out[..., 0, 1] = np.cos(b) * np.cos(c), np.sin(c)
    out[..., 1, 0], out[..., 1, 1] = -np.cos(b) * np.sin(c), np.cos(c)
    out[..., 2, 0], out[..., 2, 2] = np.sin(b), 1.0
    return out


@dataclass(frozen=True)
class StateLoads:
    """What a design changes in the rest of the scene.

    Attributes
    ----------
    modal_stiffness : list of (ndarray of int, ndarray)
        Added stiffness on modal coordinates: (indices, matrix (..., m, m)) per stiffened link.
    mass : list of AddedRigidMass
        Added rigid-body mass.
    force : ndarray, shape (..., N)
        Added applied force (e.g. the weight of added engine mass), N.
    """

    modal_stiffness: list
    mass: list
    force: np.ndarray

    def take(self, rows: np.ndarray | int | None) -> "StateLoads":
        """The designs *rows* of loads given per design (leading axis; an index: one design without it)."""
        return StateLoads([(indices, added[rows] if added.ndim == 3 else added)
                           for indices, added in self.modal_stiffness],
                          [added.take(rows) for added in self.mass], self.force[rows])


def total(expansion: SceneExpansion, dq: np.ndarray) -> np.ndarray:
    """The total coordinates (reference plus state) at the state change *dq*."""
    return expansion.reference + expansion.state + dq


def rest_stiffness(expansion: SceneExpansion, dq: np.ndarray, loads: StateLoads) -> np.ndarray:
    """K of the rest of the scene at the state change *dq* (..., N), per body: blocks (..., K, b, b)."""
    stiffness = expansion.rest.at("stiffness", dq)
    layout = expansion.layout
    for indices, added in loads.modal_stiffness:
        if added.ndim - 2 > stiffness.ndim - 3:           # one state for designs of their own loads
            stiffness = np.repeat(stiffness[None], len(added), axis=0)
        block, positions = layout.locate(indices)
        stiffness[..., block, positions[:, None], positions] += added
    return stiffness


def rest_matrices(expansion: SceneExpansion, dq: np.ndarray, loads: StateLoads
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, K, D of the rest of the scene at the state change *dq* (..., N), per body: blocks (..., K, b, b) (M
    with each Euler-parameter body's rotation exact, :func:`turned_mass`)."""
    mass, damping = turned_mass(expansion, dq), expansion.rest.at("damping", dq)
    q = total(expansion, dq)
    for added in loads.mass:
        block, positions = expansion.layout.locate(added.coordinates)
        mass[..., block, positions[:, None], positions] += added.matrix(q[..., added.coordinates])
    return mass, rest_stiffness(expansion, dq, loads), damping


def _rotation(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A (..., E, 3, 3) and the local ``G`` (..., E, 3, 4) of unit Euler parameters *theta* (..., E, 4), as
    Exudyn's rigid-body nodes have them: body angular velocity ``G theta'``, global vector ``A v`` of a local v."""
    p0, pv = theta[..., 0, None, None], theta[..., 1:]
    skew = np.zeros(theta.shape[:-1] + (3, 3))
    skew[..., 0, 1], skew[..., 0, 2], skew[..., 1, 2] = -pv[..., 2], pv[..., 1], -pv[..., 0]
    skew -= skew.swapaxes(-1, -2)
    rotation = (2 * p0 ** 2 - 1) * np.eye(3) + 2 * (pv[..., :, None] * pv[..., None, :] + p0 * skew)
    local = 2 * np.concatenate([-pv[..., :, None], p0 * np.eye(3) - skew], axis=-1)
    return rotation, local


def turned_mass(expansion: SceneExpansion, dq: np.ndarray) -> np.ndarray:
    """The rest's M at the state change *dq*, per body (blocks (..., K, b, b)), each Euler-parameter body's
    rotation exact.

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
        return expansion.rest.at("mass", dq)
    nodes = np.concatenate([euler[:, :1] - 3 + np.arange(3), euler], axis=1)      # (E, 7): position, parameters
    unturned = dq.copy()
    unturned[..., nodes] = 0.0
    mass = expansion.rest.at("mass", unturned)
    at = [total(expansion, change)[..., euler] for change in (np.zeros_like(dq), dq)]
    (base_rotation, base_local), (rotation, local) = (_rotation(theta / np.linalg.norm(theta, axis=-1)[..., None])
                                                      for theta in at)
    turn = np.zeros(dq.shape[:-1] + (len(euler), 7, 7))
    turn[..., :3, :3] = base_rotation @ rotation.swapaxes(-1, -2)
    turn[..., 3:, 3:] = base_local.swapaxes(-1, -2) @ local / 4
    for k, index in enumerate(nodes):
        block, positions = expansion.layout.locate(index)
        own = mass[..., block, :, :]
        step = turn[..., k, :, :]
        own[..., :, positions] = own[..., :, positions] @ step
        own[..., positions, :] = step.swapaxes(-1, -2) @ own[..., positions, :]
    return mass


def normal_components(expansion: SceneExpansion, dq: np.ndarray, force: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Per Euler-parameter node: its unit parameters (..., E, 4) and ``theta . force / |theta|`` (..., E).

    Exudyn applies a force to such a node through ``G^T``, which has no
    component along the parameters themselves; the true Jacobian of a
    position does. The difference is this normal component (removed from the
    force) and its derivative, ``-(theta . f) / |theta|^2`` on the tangent
    directions (added to the stiffness): the same linearisation as Exudyn's.
    """
    theta = total(expansion, dq)[..., expansion.euler_blocks]
    norm = np.linalg.norm(theta, axis=-1)
    return theta / norm[..., None], np.einsum("...ei,...ei->...e", theta, force[..., expansion.euler_blocks]) / norm


def without_normal(expansion: SceneExpansion, dq: np.ndarray, force: np.ndarray) -> np.ndarray:
    """*force* (..., N) with its normal components on the Euler parameters removed (:func:`normal_components`)."""
    unit, normal = normal_components(expansion, dq, force)
    out = force.copy()
    out[..., expansion.euler_blocks] -= normal[..., None] * unit
    return out


def static_residual(expansion: SceneExpansion, dq: np.ndarray, springs: ChannelSprings, base_force: np.ndarray,
                    loads: StateLoads, state: ChannelState) -> np.ndarray:
    """Internal minus applied generalised force at the state change *dq* (..., N), full coordinates.

    *base_force* is the rest's internal force at the prepared state (minus the
    channels' there). The rest's force grows with its stiffness at the mid
    state (second order)."""
    residual = base_force - loads.force + expansion.rest.force_change(dq)
    q = total(expansion, dq)
    for indices, added in loads.modal_stiffness:
        residual[..., indices] += (added @ q[..., indices, None])[..., 0]
    return residual + without_normal(expansion, dq, expansion.channels.force(state, springs.stiffness))


def add_tangent_terms(expansion: SceneExpansion, dq: np.ndarray, blocks: np.ndarray, springs: ChannelSprings,
                      state: ChannelState) -> None:
    """Add the channels' curvature ``sum_c (S d) . H`` and Exudyn's term of the normal force components
    (:func:`normal_components`) to the bodies' stiffness blocks *blocks* (..., K, b, b), in place (contiguous):
    with the channels' ``J^T S J``, the tangent stiffness."""
    channels, layout = expansion.channels, expansion.layout
    layout.add_curvature(blocks, channels.curvature(state, springs.stiffness))
    _, normal = normal_components(expansion, dq, channels.force(state, springs.stiffness))
    theta = total(expansion, dq)[..., expansion.euler_blocks]
    nodes, positions, _ = layout.euler
    blocks[..., nodes[:, None], positions, positions] -= (normal / np.linalg.norm(theta, axis=-1))[..., None]


def tangent_stiffness(expansion: SceneExpansion, dq: np.ndarray, rest: np.ndarray, springs: ChannelSprings,
                      state: ChannelState, basis: "Projection", jacobian: np.ndarray) -> np.ndarray:
    """The tangent stiffness projected on the independent coordinates *basis*, (..., n, n).

    The bodies' blocks (the rest's stiffness blocks *rest*, :func:`rest_stiffness`, plus
    :func:`add_tangent_terms`, added to *rest* in place: a contiguous array of the caller's, not used after)
    projected, plus every channel's ``J^T S J`` on the projected channel Jacobians *jacobian* (..., 3 C, n).
    """
    add_tangent_terms(expansion, dq, rest, springs, state)
    return projected(expansion, rest, basis) + spring_matrix(springs.stiffness, jacobian)


def projected(expansion: SceneExpansion, blocks: np.ndarray, basis: "Projection") -> np.ndarray:
    """The bodies' blocks (..., K, b, b) projected on the independent coordinates *basis*, whole (..., n, n):
    block by block, or (bodies of very unequal size, :attr:`~workbook.design.blocks.BodyLayout.by_body`)
    placed in the full matrix and projected there."""
    layout = expansion.layout
    if layout.by_body:
        return layout.dense(layout.project(blocks, layout.basis(basis.tangents)))
    return basis.both(expansion.rest.full(blocks))


@dataclass(frozen=True)
class Projection:
    """The null space of the Euler-parameter constraints at a state (or one per design): ``q = B x``.

    B keeps the free coordinates as they are and gives each Euler-parameter
    node three tangent directions; it is applied block by block, never formed.

    Attributes
    ----------
    free : ndarray of int, shape (f,)
        The coordinates that are independent as they are.
    euler : ndarray of int, shape (E, 4)
        Each Euler-parameter node's coordinates.
    tangents : ndarray, shape (..., E, 4, 3)
        Each node's orthonormal tangent basis (leading axes: designs).
    size : int
        N, the full coordinates.
    """

    free: np.ndarray
    euler: np.ndarray
    tangents: np.ndarray
    size: int

    @property
    def _batch(self) -> tuple:
        return self.tangents.shape[:-3]

    def take(self, rows) -> "Projection":
        """The designs *rows* (an index: one design without its axis)."""
        return Projection(self.free, self.euler, self.tangents[rows], self.size)

    def expand(self, independent: np.ndarray) -> np.ndarray:
        """``B @ independent`` of vectors (..., f + 3 E): (..., N)."""
        count = len(self.free)
        full = np.zeros(independent.shape[:-1] + (self.size,), dtype=independent.dtype)
        full[..., self.free] = independent[..., :count]
        nodes = independent[..., count:].reshape(independent.shape[:-1] + (len(self.euler), 3, 1))
        full[..., self.euler] = (self.tangents @ nodes)[..., 0]
        return full

    def columns(self, matrix: np.ndarray) -> np.ndarray:
        """``matrix @ B`` of matrices (..., r, N): (..., r, f + 3 E)."""
        return self.rows(matrix.swapaxes(-1, -2)).swapaxes(-1, -2)     # gathering rows is the faster

    def rows(self, matrix: np.ndarray) -> np.ndarray:
        """``B.T @ matrix`` of a vector (design axes + (N,)) or matrix (design axes + (N, k))."""
        batch = self._batch
        trailing = matrix.shape[len(batch) + 1:]
        flat = matrix.reshape(batch + (self.size, -1))
        nodes = self.tangents.swapaxes(-1, -2) @ flat[..., self.euler, :]     # (..., E, 3, k)
        out = np.concatenate([flat[..., self.free, :], nodes.reshape(batch + (-1, flat.shape[-1]))], axis=-2)
        return out.reshape(batch + (-1,) + trailing)

    def both(self, matrix: np.ndarray) -> np.ndarray:
        """``B.T @ matrix @ B`` of matrices (..., N, N)."""
        return self.rows(self.columns(matrix))

    def place(self, indices: np.ndarray) -> np.ndarray:
        """The positions among the independent coordinates of the free full coordinates *indices*."""
        lookup = np.full(self.size, -1)
        lookup[self.free] = np.arange(len(self.free))
        placed = lookup[indices]
        assert (placed >= 0).all(), "coordinates of Euler parameters have no independent position"
        return placed


def projection(expansion: SceneExpansion, dq: np.ndarray) -> Projection:
    """The independent coordinates at the state change *dq* (..., N)."""
    q = total(expansion, dq)
    euler = expansion.euler_blocks
    unit = q[..., euler] / np.linalg.norm(q[..., euler], axis=-1)[..., None]
    t0, t1, t2, t3 = np.moveaxis(unit, -1, 0)
    # an orthonormal basis (4, 3) of the directions normal to the unit parameters, per node
    tangents = np.stack([np.stack([-t1, t0, t3, -t2], axis=-1), np.stack([-t2, -t3, t0, t1], axis=-1),
                         np.stack([-t3, t2, -t1, t0], axis=-1)], axis=-1)
    return Projection(expansion.free, euler, tangents, q.shape[-1])


def solve_each(matrices: np.ndarray, right: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``matrices[k] x[k] = right[k]`` for every k, and which matrices are singular (their x is zero).

    Parameters
    ----------
    matrices : ndarray, shape (B, n, n)
    right : ndarray, shape (B, n) or (B, n, m)

    Returns
    -------
    x : ndarray, shape of *right*
    singular : ndarray of bool, shape (B,)
    """
    vector = right.ndim == 2
    try:
        solution = np.linalg.solve(matrices, right[..., None] if vector else right)
        solution = solution[..., 0] if vector else solution
        return solution, np.asarray(~np.isfinite(solution).reshape(len(matrices), -1).all(axis=-1))
    except np.linalg.LinAlgError:                 # one of them at least: find which
        solution = np.zeros(right.shape, dtype=np.result_type(matrices, right))
        singular = np.zeros(len(matrices), dtype=bool)
        for k, (matrix, vector) in enumerate(zip(matrices, right, strict=True)):
            try:
                solution[k] = np.linalg.solve(matrix, vector)
            except np.linalg.LinAlgError:
                singular[k] = True
        return solution, np.asarray(singular | ~np.isfinite(solution).reshape(len(matrices), -1).all(axis=-1))
