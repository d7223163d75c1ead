"""The linearised mount body by body: each body's matrices on its own independent coordinates.

Without its force channels a scene's bodies do not couple (the blocks of
:class:`~workbook.design.expansion.RestBlocks`), and the Euler-parameter
constraints only mix a node's own coordinates; so every term of the
projected linear model but the channels' ``J^T Z J`` is a matrix of one
body (on the reference mount, of 6 to 17 independent coordinates where the
whole mount has about a hundred). :class:`BodyLayout` says where each body's coordinates sit among
the full and the independent coordinates, projects the bodies' blocks
(:meth:`BodyLayout.project`) and places them in the whole matrix when one
is needed (:meth:`BodyLayout.dense`). :func:`channel_solve` solves the
harmonic response of designs together on the blocks
(``docs/design-evaluation.md``).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from workbook.design.channel_set import scatter_sum
from workbook.errors import SimulationError

if TYPE_CHECKING:
    from workbook.design.channel_set import ChannelSet, ChannelState
    from workbook.design.expansion import SceneExpansion

__all__ = ["BlockPlacement", "BodyLayout", "body_layout", "ChannelCoupling", "SolveGroup", "channel_solve",
           "BACKWARD_ERROR"]

_SIGNS = np.array([-1.0, 1.0])   # d = p_1 - p_0

#: Largest relative backward error of the body-by-body solve of a design; a design above it is solved whole.
BACKWARD_ERROR = 1e-12


@dataclass(frozen=True)
class BlockPlacement:
    """Where stacked blocks' entries go in a whole matrix.

    Attributes
    ----------
    size : int
        The whole matrix's order.
    positions : ndarray of int
        The flat positions in the whole matrix of the blocks' kept entries.
    kept : ndarray of int
        The blocks' flat entries that are placed (the others fall on the padding).
    """

    size: int
    positions: np.ndarray
    kept: np.ndarray

    @classmethod
    def of(cls, index: np.ndarray, size: int) -> "BlockPlacement":
        """The placement of blocks on the coordinates *index* (K, w) of a whole matrix of order *size*, padded
        with *size* (each coordinate in one block)."""
        rows = np.broadcast_to(index[:, :, None], index.shape + index.shape[-1:]).ravel()
        columns = np.broadcast_to(index[:, None, :], index.shape + index.shape[-1:]).ravel()
        kept = np.flatnonzero((rows < size) & (columns < size))
        return cls(size, rows[kept] * size + columns[kept], kept)

    def place(self, blocks: np.ndarray) -> np.ndarray:
        """The blocks (..., K, w, w) placed in the whole matrix (..., size, size)."""
        batch = blocks.shape[:-3]
        out = np.zeros(batch + (self.size * self.size,), dtype=blocks.dtype)
        out[..., self.positions] = blocks.reshape(batch + (-1,))[..., self.kept]
        return out.reshape(batch + (self.size, self.size))


@dataclass(frozen=True)
class BodyLayout:
    """Where each body block's coordinates sit.

    Attributes
    ----------
    size : int
        N, the full coordinates.
    count : int
        n, the independent coordinates: the free full coordinates, then three per Euler-parameter node.
    coordinates : ndarray of int, shape (K, b)
        Each block's full coordinates, padded with N.
    block, position : ndarray of int, shape (N + 1,)
        Each full coordinate's block and its position there (the padding coordinate N: block 0, position b).
    independent : ndarray of int, shape (K, w)
        Each block's independent coordinates, padded with n.
    free : tuple of ndarray of int
        (blocks, positions, columns) of the free coordinates: the basis's unit entries.
    euler : tuple of ndarray of int
        (blocks (E,), positions (E, 4), columns (E, 3)) of the Euler-parameter nodes.
    curvature : dict of str to (ndarray of int, ndarray of int)
        Per rotation kind, where the channels' curvature terms
        (:meth:`~workbook.design.channel_set.ChannelSet.curvature`) go: positions in the flat blocks (K b b)
        and the terms' flat entries placed there (a body's rotation and modal block twice, as it is and
        transposed; the entries of padded modes dropped).
    """

    size: int
    count: int
    coordinates: np.ndarray
    block: np.ndarray
    position: np.ndarray
    independent: np.ndarray
    free: tuple
    euler: tuple
    curvature: dict

    @property
    def width(self) -> int:
        """w, the most independent coordinates of a block."""
        return self.independent.shape[1]

    @property
    def by_body(self) -> bool:
        """Whether the bodies' blocks, all padded to the widest, cost less than the whole matrices (their
        inverses against one factorisation of the whole: ``K w^3 <= n^3``); a flexible engine casing of many
        modes beside small bodies makes them cost more."""
        return len(self.coordinates) * self.width ** 3 <= self.count ** 3

    def locate(self, indices: np.ndarray) -> tuple[int, np.ndarray]:
        """The block and positions of the full coordinates *indices*, all of one body."""
        blocks = np.unique(self.block[indices])
        assert len(blocks) == 1, "coordinates of several bodies"
        return int(blocks[0]), self.position[indices]

    def basis(self, tangents: np.ndarray) -> np.ndarray:
        """Each block's null-space basis ``B_k`` for the Euler-parameter nodes' tangents (..., E, 4, 3)
        (:func:`~workbook.design.assembly.projection`): shape (..., K, b + 1, w), the last row zero (the
        padding coordinate)."""
        blocks, width = self.coordinates.shape
        out = np.zeros(tangents.shape[:-3] + (blocks, width + 1, self.width))
        out[..., self.free[0], self.free[1], self.free[2]] = 1.0
        nodes, rows, columns = self.euler
        out[..., nodes[:, None, None], rows[:, :, None], columns[:, None, :]] = tangents
        return out

    def project(self, blocks: np.ndarray, basis: np.ndarray) -> np.ndarray:
        """``B_k^T A_k B_k`` of the blocks *blocks* (..., K, b, b) on the *basis* (:meth:`basis`), (..., K, w, w)."""
        frame = basis[..., :blocks.shape[-1], :]
        return frame.swapaxes(-1, -2) @ blocks @ frame

    def dense(self, blocks: np.ndarray) -> np.ndarray:
        """The projected blocks (..., K, w, w) placed in the whole matrix (..., n, n)."""
        return self._placement.place(blocks)

    def vector(self, blocks: np.ndarray) -> np.ndarray:
        """Vectors per block (..., K, w) as whole vectors (..., n)."""
        out = np.zeros(blocks.shape[:-2] + (self.count + 1,), dtype=blocks.dtype)
        out[..., self.independent] = blocks
        return out[..., :self.count]

    @functools.cached_property
    def _placement(self) -> "BlockPlacement":
        return BlockPlacement.of(self.independent, self.count)

    def add_curvature(self, out: np.ndarray, terms: dict[str, np.ndarray]) -> None:
        """Add the channels' curvature *terms* (:meth:`~workbook.design.channel_set.ChannelSet.curvature`) to
        the blocks *out* (..., K, b, b), in place (contiguous)."""
        target = out.reshape((-1, out.shape[-3] * out.shape[-2] * out.shape[-1]))
        assert np.may_share_memory(target, out), "the sums need a contiguous out"
        for kind, values in terms.items():
            positions, entries = self.curvature[kind]
            target[:, positions] += values.reshape((len(target), -1))[:, entries]

    @functools.cached_property
    def padding(self) -> np.ndarray:
        """Ones on the diagonal of each block's padding columns, zero elsewhere: (K, w, w)."""
        return np.eye(self.width) * (self.independent == self.count)[:, None, :]

    def marker_rows(self, channels: "ChannelSet") -> tuple[np.ndarray, np.ndarray]:
        """Each of the channels' points' block and the positions of its padded coordinates there, (P,) and
        (P, M) (a point on the ground: block 0, every position the padding's)."""
        positions = self.position[channels.coordinates]
        return self.block[channels.coordinates[:, 0]], positions

    def point_jacobians(self, channels: "ChannelSet", state: "ChannelState", tangents: np.ndarray) -> np.ndarray:
        """Each of the channels' points' position Jacobian on its block's independent coordinates, with the
        sign of the separation d: shape (..., P, 3, w).

        ``J B`` on the block's basis (:meth:`basis`) for the Euler-parameter nodes' *tangents* (..., E, 4, 3):
        a free coordinate's column is moved to its independent one, a node's four are turned by its tangent.
        """
        jacobian = state.jacobian                                            # (..., P, 3, M)
        batch, points = jacobian.shape[:-3], jacobian.shape[-3]
        count = int(np.prod(batch, dtype=int))
        source = jacobian.reshape(count, -1)
        out = np.zeros((count, points * 3 * self.width))
        moved, turned = self._point_columns(channels)
        out[:, moved[1]] = source[:, moved[0]]
        if len(turned[0]):
            picked, nodes, targets = turned
            rows = source[:, picked].reshape(count, len(nodes), 3, 4)
            turns = np.broadcast_to(tangents, batch + tangents.shape[-3:]).reshape((count,) + tangents.shape[-3:])
            out[:, targets] = (rows @ turns[:, nodes]).reshape(count, -1)
        signs = np.tile(_SIGNS, points // 2)[:, None, None]
        return signs * out.reshape(batch + (points, 3, self.width))

    @functools.cached_property
    def _columns_of(self) -> dict:
        """:meth:`_point_columns` of each point set asked, by its id (with the set: the id is its own)."""
        return {}

    def _point_columns(self, channels: "ChannelSet") -> tuple[tuple, tuple]:
        """Flat positions for :meth:`point_jacobians`: the free coordinates' (in the Jacobian (P, 3, M), in the
        result (P, 3, w)), and for each point on an Euler-parameter node its four columns' (P', 3, 4), its node
        (P',) and the node's three independent columns' (P', 3, 3); made once per point set."""
        known = self._columns_of.get(id(channels))
        if known is None or known[0] is not channels:
            known = self._columns_of[id(channels)] = (channels, self._find_columns(channels))
        return known[1]

    def _find_columns(self, channels: "ChannelSet") -> tuple[tuple, tuple]:
        blocks, positions = self.marker_rows(channels)
        points, width = positions.shape
        free = np.full((len(self.coordinates), self.coordinates.shape[1] + 1), -1)
        free[self.free[0], self.free[1]] = self.free[2]
        column = free[blocks[:, None], positions]                          # (P, M): -1 where not free
        point, entry = np.nonzero(column >= 0)
        rows = (3 * point[:, None] + np.arange(3))                         # (F, 3)
        moved = ((rows * width + entry[:, None]).ravel(), (rows * self.width + column[point, entry][:, None]).ravel())
        node_blocks, node_positions, node_columns = self.euler
        nodes, picked, targets = [], [], []
        for p in range(points):
            for e in np.flatnonzero(node_blocks == blocks[p]):
                where = [np.flatnonzero(positions[p] == position) for position in node_positions[e]]
                if all(len(found) for found in where):
                    places = np.array([found[0] for found in where])
                    prows = 3 * p + np.arange(3)
                    nodes.append(e)
                    picked.append((prows[:, None] * width + places).ravel())
                    targets.append((prows[:, None] * self.width + node_columns[e]).ravel())
        return moved, (np.array(picked, dtype=int).ravel(), np.array(nodes, dtype=int), np.array(targets, dtype=int).ravel())

    def channel_jacobian(self, channels: "ChannelSet", points: np.ndarray) -> np.ndarray:
        """The channels' stacked Jacobian ``J_c`` (..., 3 C, n) from their points' (:meth:`point_jacobians`)."""
        blocks, _ = self.marker_rows(channels)
        batch = points.shape[:-3]
        count = channels.count
        columns = self.independent[blocks]                                 # (P, w)
        rows = 3 * (np.arange(2 * count) // 2)[:, None, None] + np.arange(3)[None, :, None]   # (P, 3, 1)
        index = np.broadcast_to(rows * (self.count + 1) + columns[:, None, :], points.shape[-3:]).ravel()
        summed = scatter_sum(index, points.reshape(batch + (-1,)), 3 * count * (self.count + 1))
        return summed.reshape(batch + (3 * count, self.count + 1))[..., :self.count]


def body_layout(expansion: "SceneExpansion") -> BodyLayout:
    """The :class:`BodyLayout` of *expansion*'s bodies (:attr:`~workbook.design.expansion.RestBlocks.coordinates`)."""
    coordinates = expansion.rest.coordinates
    size = len(expansion.state)
    blocks, width = coordinates.shape
    block = np.zeros(size + 1, dtype=int)
    position = np.full(size + 1, width, dtype=int)
    for k, row in enumerate(coordinates):
        kept = row < size
        block[row[kept]], position[row[kept]] = k, np.flatnonzero(kept)
    if len(np.unique(coordinates[coordinates < size])) != size:
        raise SimulationError("the scene has coordinates of no body; the design evaluation does not know them")
    free, euler = expansion.free, expansion.euler_blocks
    count = len(free) + 3 * len(euler)
    index_of = np.full(size, -1)
    index_of[free] = np.arange(len(free))
    columns_of: list[list[int]] = [[] for _ in range(blocks)]
    free_parts: list[tuple[int, int, int]] = []
    for k, row in enumerate(coordinates):
        for p, coordinate in enumerate(row):
            if coordinate < size and index_of[coordinate] >= 0:
                free_parts.append((k, p, len(columns_of[k])))
                columns_of[k].append(int(index_of[coordinate]))
    euler_blocks = block[euler[:, 0]] if len(euler) else np.zeros(0, dtype=int)
    euler_columns = np.zeros((len(euler), 3), dtype=int)
    for e, k in enumerate(euler_blocks):
        euler_columns[e] = len(columns_of[k]) + np.arange(3)
        columns_of[k].extend(len(free) + 3 * e + np.arange(3))
    independent = np.full((blocks, max(len(c) for c in columns_of)), count, dtype=int)
    for k, found in enumerate(columns_of):
        independent[k, :len(found)] = found
    parts = np.array(free_parts, dtype=int).reshape(-1, 3)
    return BodyLayout(size, count, coordinates, block, position, independent, (parts[:, 0], parts[:, 1], parts[:, 2]),
                      (euler_blocks, position[euler] if len(euler) else np.zeros((0, 4), dtype=int), euler_columns),
                      _curvature_places(expansion.channels, block, position, width))


def _curvature_places(channels: "ChannelSet", block: np.ndarray, position: np.ndarray, width: int) -> dict:
    """:attr:`BodyLayout.curvature` of the channels' points, on the bodies' blocks of *width*."""
    out = {}
    for kind, (rotations, body) in channels.rotation_bodies.items():
        if not len(body):
            continue
        bodies, turn = rotations.shape
        modes = channels.modal.shape[-1]
        first = np.array([channels.kinds[kind][body == g][0] for g in range(bodies)])   # a point of each body
        turned = position[rotations]                                                     # (G, r)
        modal = position[channels.coordinates[first, 3 + turn:3 + turn + modes]]          # (G, K), padding: width
        base = (block[rotations[:, 0]] * width)[:, None, None]
        both = (base + turned[:, :, None]) * width + turned[:, None, :]                   # (G, r, r)
        across = (base + turned[:, :, None]) * width + modal[:, None, :]                  # (G, r, K)
        back = (base + modal[:, None, :]) * width + turned[:, :, None]
        entry = np.arange(bodies * turn * (turn + modes)).reshape(bodies, turn * (turn + modes))
        own, mixed = entry[:, :turn * turn].reshape(bodies, turn, turn), entry[:, turn * turn:].reshape(bodies, turn, modes)
        kept = np.broadcast_to(modal[:, None, :] < width, mixed.shape)
        out[kind] = (np.concatenate([both.ravel(), across[kept], back[kept]]),
                     np.concatenate([own.ravel(), mixed[kept], mixed[kept]]))
    return out


@dataclass(frozen=True)
class ChannelCoupling:
    """How the force channels join the bodies, for :func:`channel_solve`.

    Attributes
    ----------
    moving : ndarray of int, shape (P,)
        The channels' points that move with a body (the others are on the ground), among all 2 C.
    bodies : ndarray, shape (K, P)
        1 where a moving point is on a body, 0 elsewhere (sums over a body's points by a product).
    channels : ndarray, shape (C, P)
        1 where a moving point is a channel's, 0 elsewhere.
    coupled : ndarray of int, shape (2 L,)
        The moving points (positions in *moving*) of the L channels with both points moving: their first
        points, then their second.
    grounded : ndarray of int
        The other moving points: of the channels to the ground.
    groups : tuple of SolveGroup
        The bodies by their own number of independent coordinates, solved together.
    """

    moving: np.ndarray
    bodies: np.ndarray
    channels: np.ndarray
    coupled: np.ndarray
    grounded: np.ndarray
    groups: tuple

    @classmethod
    def of(cls, layout: BodyLayout, channels: "ChannelSet") -> "ChannelCoupling":
        """The coupling of *channels* on the bodies of *layout*."""
        blocks, positions = layout.marker_rows(channels)
        moving = np.flatnonzero((positions < layout.coordinates.shape[1]).any(axis=1))
        position = {int(point): k for k, point in enumerate(moving)}
        both = [c for c in range(channels.count) if 2 * c in position and 2 * c + 1 in position]
        coupled = np.array([position[2 * c] for c in both] + [position[2 * c + 1] for c in both], dtype=int)
        on = blocks[moving[coupled]]
        bodies = np.zeros((len(layout.coordinates), len(moving)))
        bodies[blocks[moving], np.arange(len(moving))] = 1.0
        by_channel = np.zeros((channels.count, len(moving)))
        by_channel[moving // 2, np.arange(len(moving))] = 1.0
        widths = (layout.independent < layout.count).sum(axis=1)
        groups = tuple(SolveGroup.of(np.flatnonzero(widths == width), int(width), on)
                       for width in np.unique(widths))
        return cls(moving, bodies, by_channel, coupled, np.setdiff1d(np.arange(len(moving)), coupled), groups)


@dataclass(frozen=True)
class SolveGroup:
    """Bodies of the same number of independent coordinates, and the coupled points on each.

    Attributes
    ----------
    blocks : ndarray of int, shape (G,)
        The bodies' blocks.
    width : int
        Their independent coordinates (a block's first; the rest is padding).
    points : ndarray of int, shape (G, m)
        Per body, the coupled points on it (positions among the 2 L coupled points), padded with -1.
    size : int
        3 L, the order of the L channels' receptance.
    targets : ndarray of int, shape (G, 3 m, 3 m)
        Where the products of two of a body's points' rows go in the flat receptance (a padding point's: one
        past its end).
    """

    blocks: np.ndarray
    width: int
    points: np.ndarray
    size: int
    targets: np.ndarray

    @classmethod
    def of(cls, blocks: np.ndarray, width: int, on: np.ndarray) -> "SolveGroup":
        """The group of the bodies *blocks* of *width* coordinates, *on* the body of each coupled point."""
        found = [np.flatnonzero(on == block) for block in blocks]
        points = np.full((len(blocks), max((len(f) for f in found), default=0)), -1, dtype=int)
        for k, mine in enumerate(found):
            points[k, :len(mine)] = mine
        links = len(on) // 2                                   # point p is on channel p mod L
        rows = np.where(points[..., None] >= 0, 3 * (points[..., None] % max(links, 1)) + np.arange(3), -1)
        rows = rows.reshape(len(blocks), -1)                   # (G, 3 m), -1: padding
        size = 3 * links
        targets = np.where((rows[:, :, None] >= 0) & (rows[:, None, :] >= 0),
                           rows[:, :, None] * size + rows[:, None, :], size * size)
        return cls(blocks, width, points, size, targets)

    def solve(self, held: np.ndarray, loads: np.ndarray, transposed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each body's response to its loads and to unit forces at its coupled points.

        Parameters
        ----------
        held : ndarray, complex, shape (D, K, w, w)
            Every body's held dynamic stiffness.
        loads : ndarray, complex, shape (D, K, w)
        transposed : ndarray, shape (D, 2 L, w, 3)
            The coupled points' Jacobians, transposed.

        Returns
        -------
        free : ndarray, complex, shape (D, G, width)
            ``A^-1 f`` of the group's bodies.
        reach : ndarray, complex, shape (D, G, width, 3 m)
            ``A^-1 J_p^T`` of their coupled points, three columns each (of the padding: meaningless).
        """
        count, (bodies, points), width = len(held), self.points.shape, self.width
        right = np.zeros((count, bodies, width, 1 + 3 * points), dtype=complex)
        right[..., 0] = loads[:, self.blocks, :width]
        forces = transposed[:, self.points, :width]          # (D, G, m, w, 3); the padding's solved, not kept
        right[..., 1:] = forces.transpose(0, 1, 3, 2, 4).reshape(count, bodies, width, 3 * points)
        solved = np.linalg.solve(held[:, self.blocks, :width, :width], right)
        return solved[..., 0], solved[..., 1:]

    def receptance(self, transposed: np.ndarray, reach: np.ndarray) -> np.ndarray:
        """The group's part of the L channels' receptance ``G = U A^-1 U^T``, flat: (D, 9 L^2).

        Parameters
        ----------
        transposed : ndarray, shape (D, 2 L, w, 3)
            The coupled points' Jacobians, transposed.
        reach : ndarray, complex, shape (D, G, width, 3 m)
            From :meth:`solve`.
        """
        count, (bodies, points), width = len(reach), self.points.shape, self.width
        rows = transposed[:, self.points, :width].transpose(0, 1, 2, 4, 3).reshape(count, bodies, 3 * points, width)
        products = (rows @ reach).reshape(count, -1)
        flat, length = self.targets.ravel(), self.size * self.size + 1
        return (scatter_sum(flat, products.real, length) + 1j * scatter_sum(flat, products.imag, length))[:, :-1]


def channel_solve(coupling: ChannelCoupling, dynamic: np.ndarray, points: np.ndarray, impedance: np.ndarray,
                  loads: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The channels' separation phasors of designs' harmonic responses, body by body.

    The whole dynamic stiffness is the bodies' blocks plus every channel's
    ``J_c^T Z_c J_c``, ``J_c`` the sum of its two points' Jacobians. A channel
    to the ground adds its term to its body's block (the body held by it); a
    channel between two moving bodies is a rank-3 update ``U_c^T Z_c U_c``
    (``U_c = J_c``, on both bodies), solved by the Woodbury identity: a
    system of 3 per such channel. A design whose solution leaves a backward
    error above :data:`BACKWARD_ERROR` (a body near a resonance of its own),
    or whose matrices are singular, is marked for a solve of the whole
    matrix.

    Parameters
    ----------
    coupling : ChannelCoupling
    dynamic : ndarray, complex, shape (D, K, w, w)
        Each design's bodies' blocks ``K - w^2 M + i (w D + H)`` (regular on their padding).
    points : ndarray, shape (D, 2 C, 3, w)
        The channels' points' Jacobians on their bodies' independent coordinates, with the sign of d.
    impedance : ndarray, complex, shape (D, C, 3, 3)
        ``Z_c`` of each channel.
    loads : ndarray, complex, shape (D, K, w)
        The generalised force phasors on each body.

    Returns
    -------
    separation : ndarray, complex, shape (D, C, 3)
        ``J_c x`` of each channel.
    trouble : ndarray of bool, shape (D,)
        The designs to solve whole (their separations mean nothing).
    """
    count = len(dynamic)
    jacobian = points[:, coupling.moving]                                    # (D, P, 3, w)
    transposed = jacobian.swapaxes(-1, -2)
    on_points = (coupling.channels.T @ impedance.reshape(count, impedance.shape[1], 9)).reshape(
        count, len(coupling.moving), 3, 3)                                  # Z of each point's channel
    grounded = coupling.grounded
    own = transposed[:, grounded] @ (on_points[:, grounded] @ jacobian[:, grounded])        # (D, G, w, w)
    held = dynamic + (coupling.bodies[:, grounded] @ own.reshape(count, len(grounded), -1)).reshape(dynamic.shape)
    failed = np.ones(count, dtype=bool)
    coupled = coupling.coupled
    links = len(coupled) // 2
    free = np.zeros(loads.shape, dtype=complex)                              # A^-1 f, (D, K, w)
    reach = np.zeros((count, 2 * links) + transposed.shape[-2:], dtype=complex)   # A^-1 J^T, (D, 2 L, w, 3)
    at_coupled = transposed[:, coupled]
    flat_receptance = np.zeros((count, 9 * links * links), dtype=complex)
    for group in coupling.groups:
        try:
            free[:, group.blocks, :group.width], on_bodies = group.solve(held, loads, at_coupled)
        except np.linalg.LinAlgError:
            return np.zeros((count, impedance.shape[1], 3), dtype=complex), failed
        kept = group.points >= 0
        columns = on_bodies.reshape(on_bodies.shape[:3] + (-1, 3)).transpose(0, 1, 3, 2, 4)    # (D, G, m, w, 3)
        reach[:, group.points[kept], :group.width] = columns[:, kept]
        if links:
            flat_receptance += group.receptance(at_coupled, on_bodies)
    body = coupling.bodies.argmax(axis=0)                                    # each moving point's body
    motion = free
    if links:
        # G = U A^-1 U^T, U_c the sum of a channel's two points' rows: summed body by body (the products of
        # points on different bodies are not G's)
        receptance = flat_receptance.reshape(count, 3 * links, 3 * links)
        springs = np.zeros((count, links, 3, links, 3), dtype=complex)           # Z_c of the L channels, block diagonal
        springs[:, np.arange(links), :, np.arange(links), :] = \
            impedance[:, coupling.moving[coupled[:links]] // 2].transpose(1, 0, 2, 3)
        spring = springs.reshape(count, 3 * links, 3 * links)
        moved = (jacobian[:, coupled] @ free[:, body[coupled], :, None]).reshape(count, 2, 3 * links).sum(axis=1)
        try:
            spread = np.linalg.solve(np.eye(3 * links) + spring @ receptance, (spring @ moved[..., None]))
        except np.linalg.LinAlgError:
            return np.zeros((count, impedance.shape[1], 3), dtype=complex), failed
        both = np.concatenate([spread, spread], axis=1).reshape(count, 2 * links, 3, 1)   # U^T: on both points
        motion = free - coupling.bodies[:, coupled] @ (reach @ both)[..., 0]   # (D, K, w)
    on_moving = (jacobian @ motion[:, body, :, None])[..., 0]                # (D, P, 3)
    separation = coupling.channels @ on_moving                               # (D, C, 3)
    force = on_points @ (coupling.channels.T @ separation)[..., None]
    residual = (dynamic @ motion[..., None])[..., 0] + coupling.bodies @ (transposed @ force)[..., 0] - loads
    matrices = np.abs(held).max(axis=(1, 2, 3)) + np.abs(on_points).max(axis=(1, 2, 3)) * np.abs(jacobian).max(
        axis=(1, 2, 3)) ** 2
    scale = matrices * np.abs(motion).max(axis=(1, 2)) + np.abs(loads).max(axis=(1, 2))
    error = np.abs(residual).max(axis=(1, 2)) / np.where(scale > 0, scale, 1.0)
    return separation, ~np.isfinite(error) | (error > BACKWARD_ERROR)
