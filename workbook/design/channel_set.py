"""Every force channel's marker kinematics at once, and the channels' force, stiffness and outputs.

The two marker points of every channel are evaluated together, kind by
kind (:mod:`workbook.design.kinematics`), on coordinates padded to one
length with a spare coordinate (index N, always zero) that collects the
padding. A channel with stiffness S (3x3) adds ``J^T S d`` to the
generalised force, ``J^T S J + (S d) . H`` to the tangent stiffness and
``S J`` to its force output. The channels' Jacobians J (3 rows each) are
scattered into the full coordinates by one ``bincount``; the curvature
terms, summed per body, go onto the bodies' blocks (:mod:`workbook.design.blocks`); the
products with the springs (:func:`spring_rows`, :func:`spring_matrix`) are
then formed on J as it is, or on J projected on the independent
coordinates (fewer columns, no N x N scatter).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from workbook.design.kinematics import EULER, PointKinematics

__all__ = ["ChannelSet", "ChannelState", "spring_rows", "spring_matrix", "scatter_sum"]

_SIGNS = np.array([-1.0, 1.0])   # d = p_1 - p_0
_EULER_ROWS = EULER.reshape(36, 4)                                # (a b i, j)


@dataclass(frozen=True)
class _Pose:
    """The points of one rotation kind at a state: what their position derivatives are made of.

    Attributes
    ----------
    kind : str
        ``"euler"`` or ``"rxyz"``.
    index : ndarray of int, shape (p,)
        The points, among all.
    turned : int
        Their padded coordinates' first modal one (3 + rotation coordinates).
    shapes : ndarray, shape (p, 3, K)
        Their modal rows.
    local : ndarray, shape (c, p, 3)
        ``w + Phi q_f``, each point's place in its body's frame.
    rotation : ndarray, shape (c, p, 3, 3)
    body : ndarray of int, shape (p,)
        Each point's body among the G bodies of this kind (the points of a body share its rotation).
    body_firsts : ndarray, shape (c, G, r, 3, 3)
        The derivatives of each body's rotation with respect to its r coordinates.
    body_seconds : ndarray, shape (c, G, r, r, 3, 3), or None
        Its second derivatives, when asked for.
    """

    kind: str
    index: np.ndarray
    turned: int
    shapes: np.ndarray
    local: np.ndarray
    rotation: np.ndarray
    body: np.ndarray
    body_firsts: np.ndarray
    body_seconds: np.ndarray | None

    @functools.cached_property
    def firsts(self) -> np.ndarray:
        """The derivatives of each point's rotation, (c, p, r, 3, 3)."""
        return self.body_firsts[:, self.body]

    @functools.cached_property
    def summing(self) -> np.ndarray:
        """1 where a point (column) is on a body (row), (G, p): sums over a body's points by a product."""
        out = np.zeros((self.body_firsts.shape[1], len(self.index)))
        out[self.body, np.arange(len(self.index))] = 1.0
        return out

    @functools.cached_property
    def first_points(self) -> np.ndarray:
        """A point of each body (positions among all points), (G,)."""
        return self.index[np.unique(self.body, return_index=True)[1]]


@dataclass(frozen=True)
class ChannelState:
    """The channels at one state (or one per design: leading axes).

    Attributes
    ----------
    separation : ndarray, shape (..., C, 3)
        d of every channel, m.
    points : ChannelSet
        The channels' points.
    poses : tuple of _Pose
        The points of each rotation kind at the state.
    second : bool
        Whether the rotations' second derivatives were asked for (:meth:`ChannelSet.curvature` needs them).

    Its :attr:`jacobian` (..., 2 C, 3, M) on the points' padded coordinates is formed when first read.
    """

    separation: np.ndarray
    points: "ChannelSet" = field(repr=False)
    poses: tuple = field(repr=False)          # _Pose of each rotation kind
    second: bool = field(repr=False)

    @property
    def _count(self) -> int:
        """The designs (states), all leading axes together."""
        return int(np.prod(self.separation.shape[:-2], dtype=int))

    @functools.cached_property
    def jacobian(self) -> np.ndarray:
        """Each marker's position Jacobian, (..., 2 C, 3, M)."""
        count, (points, width) = self._count, self.points.coordinates.shape
        jacobian = np.zeros((count, points, 3, width))
        jacobian[:, :, :, :3] = np.eye(3)
        jacobian[:, self.points.kinds["ground"]] = 0.0
        for pose in self.poses:
            turned, modes = pose.turned, pose.shapes.shape[-1]
            jacobian[:, pose.index, :, 3:turned] = (pose.firsts @ pose.local[:, :, None, :, None])[..., 0].swapaxes(-1, -2)
            jacobian[:, pose.index, :, turned:turned + modes] = pose.rotation @ pose.shapes
        return jacobian.reshape(self.separation.shape[:-2] + (points, 3, width))

    def generalised(self, on_points: np.ndarray) -> np.ndarray:
        """``f_p . J_p`` of forces *on_points* (..., 2 C, 3) on each point, on its padded coordinates:
        (..., 2 C, M), without forming J. The terms on a body's rotation coordinates, which its points
        share, are summed over its points and given to one of them (``f^T A' w = A' : f w^T``)."""
        count, (points, width) = self._count, self.points.coordinates.shape
        force = on_points.reshape(count, points, 3)
        out = np.zeros((count, points, width))
        out[:, :, :3] = force
        out[:, self.points.kinds["ground"]] = 0.0
        for pose in self.poses:
            turned, modes = pose.turned, pose.shapes.shape[-1]
            own = force[:, pose.index]                                                   # (c, p, 3)
            bodies, rotations = pose.body_firsts.shape[1:3]
            with_place = pose.summing @ (own[..., :, None] * pose.local[..., None, :]).reshape(count, len(pose.index), 9)
            out[:, pose.first_points, 3:turned] = \
                (pose.body_firsts.reshape(count, bodies, rotations, 9) @ with_place[..., None])[..., 0]
            out[:, pose.index, turned:turned + modes] = (own[:, :, None, :] @ pose.rotation @ pose.shapes)[:, :, 0]
        return out.reshape(self.separation.shape[:-2] + (points, width))


@dataclass(frozen=True)
class ChannelSet:
    """The marker points of C channels, marker 0 and 1 of channel c at rows 2c and 2c + 1.

    Attributes
    ----------
    size : int
        N, the full coordinates.
    coordinates : ndarray of int, shape (2 C, M)
        Each point's coordinates (position, rotation, modal), padded with N.
    local : ndarray, shape (2 C, 3)
    modal : ndarray, shape (2 C, 3, K)
        Modal rows, padded with zero columns.
    kinds : dict of str to ndarray of int
        The points of each kind (``"ground"``, ``"none"``, ``"euler"``, ``"rxyz"``).
    """

    size: int
    coordinates: np.ndarray
    local: np.ndarray
    modal: np.ndarray
    kinds: dict

    @classmethod
    def of(cls, pairs: list[tuple[PointKinematics, PointKinematics]], size: int) -> "ChannelSet":
        """The set of the channels whose marker points are *pairs*, on *size* full coordinates."""
        points = [point for pair in pairs for point in pair]
        modes = max((p.modal.shape[1] for p in points), default=0)
        width = max((3 + p.rotations + modes for p in points if len(p.coordinates)), default=3)
        coordinates = np.full((len(points), width), size, dtype=int)
        modal = np.zeros((len(points), 3, modes))
        kinds: dict[str, list[int]] = {"ground": [], "none": [], "euler": [], "rxyz": []}
        for k, point in enumerate(points):
            count = len(point.coordinates)
            if count == 0:
                kinds["ground"].append(k)
                continue
            kinds[point.kind].append(k)
            coordinates[k, :3 + point.rotations] = point.coordinates[:3 + point.rotations]
            start = 3 + point.rotations
            coordinates[k, start:count] = point.coordinates[start:]
            modal[k, :, :point.modal.shape[1]] = point.modal
        return cls(size, coordinates, np.array([p.local for p in points], dtype=float).reshape(-1, 3), modal,
                   {kind: np.array(indices, dtype=int) for kind, indices in kinds.items()})

    @property
    def count(self) -> int:
        """C, the number of channels."""
        return len(self.coordinates) // 2

    def state(self, q: np.ndarray, *, second: bool = True) -> ChannelState:
        """Separations and the points' poses (Jacobians formed when read; with *second*, what
        :meth:`curvature` needs) at the total coordinates *q* (..., N): any leading axes are designs, answered
        at once."""
        batch = q.shape[:-1]
        count = int(np.prod(batch, dtype=int))
        points = len(self.coordinates)
        padded = np.concatenate([q.reshape(count, -1), np.zeros((count, 1))], axis=1)
        values = padded[:, self.coordinates]                                     # (count, P, M)
        position = np.zeros((count, points, 3))
        ground, free = self.kinds["ground"], self.kinds["none"]
        position[:, ground] = self.local[ground]
        position[:, free] = values[:, free, :3] + self.local[free]
        poses = []
        for kind, moved in (("euler", _euler), ("rxyz", _rxyz)):
            index = self.kinds[kind]
            if not len(index):
                continue
            rotations, group = self.rotation_bodies[kind]
            shapes = self.modal[index]
            turned = 3 + rotations.shape[1]
            modal = values[:, index, turned:turned + shapes.shape[-1]]
            local = self.local[index] + (shapes @ modal[..., None])[..., 0]         # w of every point, (c, p, 3)
            rotation, firsts, seconds = moved(padded[:, rotations], second)
            pose = _Pose(kind, index, turned, shapes, local, rotation[:, group], group, firsts, seconds)
            position[:, index] = values[:, index, :3] + (pose.rotation @ local[..., None])[..., 0]
            poses.append(pose)
        placed = position.reshape(batch + (points, 3))
        return ChannelState(placed[..., 1::2, :] - placed[..., 0::2, :], self, tuple(poses), second)

    @functools.cached_property
    def rotation_bodies(self) -> dict:
        """Per rotation kind (``"euler"``, ``"rxyz"``): the rotation coordinates of each distinct body (G, r)
        and each point's body among them (p,): the points of a body share its rotation."""
        out = {}
        for kind, count in (("euler", 4), ("rxyz", 3)):
            rotations, group = np.unique(self.coordinates[self.kinds[kind], 3:3 + count], axis=0, return_inverse=True)
            out[kind] = (rotations.reshape(-1, count), group.ravel())
        return out

    def force(self, state: ChannelState, stiffness: np.ndarray) -> np.ndarray:
        """``sum_c J_c^T S_c d_c`` (..., N) for the springs *stiffness* (..., C, 3, 3), N/m."""
        generalised = state.generalised(_on_points((stiffness @ state.separation[..., None])[..., 0]))
        flat = generalised.reshape(generalised.shape[:-2] + (-1,))
        return scatter_sum(self.coordinates.ravel(), flat, self.size + 1)[..., :self.size]

    def jacobian(self, state: ChannelState) -> np.ndarray:
        """The Jacobians of the separations d of every channel stacked, ``J_c``: shape (..., 3 C, N)."""
        jacobian = self._channel_jacobians(state)                                # (..., C, 2, 3, M)
        rows = 3 * np.arange(self.count).reshape(-1, 1, 1, 1) + np.arange(3).reshape(1, 1, 3, 1)
        columns = self.coordinates.reshape(self.count, 2, 1, -1)
        index = np.broadcast_to(rows * (self.size + 1) + columns, jacobian.shape[-4:]).ravel()
        full = scatter_sum(index, jacobian.reshape(jacobian.shape[:-4] + (-1,)), 3 * self.count * (self.size + 1))
        return full.reshape(jacobian.shape[:-4] + (3 * self.count, self.size + 1))[..., :self.size]

    def curvature(self, state: ChannelState, stiffness: np.ndarray) -> dict[str, np.ndarray]:
        """``sum_c (S_c d_c) . H``, the tangent stiffness's term of the markers' curvature for the springs
        *stiffness* (..., C, 3, 3), summed per body: by rotation kind, each body's terms on its rotation
        coordinates and its rotation and modal ones, (..., G, r r + r K) (the r x r block, then the r x K
        one; :meth:`workbook.design.blocks.BodyLayout.add_curvature` places them on the bodies' blocks).

        A point's position ``r + A w`` has second derivatives only in the rotation: ``A'' w`` and
        ``A' Phi``; a body's points share A, so their forces are summed with their w and Phi first."""
        count = state._count
        on_points = _on_points((stiffness @ state.separation[..., None])[..., 0]).reshape(count, -1, 3)
        out = {}
        for pose in state.poses:
            assert pose.body_seconds is not None, "the curvature needs the rotations' second derivatives"
            bodies, rotations = pose.body_firsts.shape[1:3]
            modes = pose.shapes.shape[-1]
            force, summing, points = on_points[:, pose.index], pose.summing, len(pose.index)   # (c, p, 3), (G, p)
            with_place = summing @ (force[..., :, None] * pose.local[..., None, :]).reshape(count, points, 9)
            with_shape = summing @ (force[..., :, None, None] * pose.shapes[:, None]).reshape(count, points, 9 * modes)
            turning = pose.body_seconds.reshape(count, bodies, rotations * rotations, 9) @ with_place[..., None]
            mixed = pose.body_firsts.reshape(count, bodies, rotations, 9) @ with_shape.reshape(count, bodies, 9, modes)
            terms = np.concatenate([turning.reshape(count, bodies, rotations * rotations),
                                    mixed.reshape(count, bodies, rotations * modes)], axis=-1)
            out[pose.kind] = terms.reshape(state.separation.shape[:-2] + terms.shape[-2:])
        return out

    def _channel_jacobians(self, state: ChannelState) -> np.ndarray:
        """Each channel's two marker Jacobians with the sign of d: shape (..., C, 2, 3, M)."""
        jacobian = state.jacobian
        return jacobian.reshape(jacobian.shape[:-3] + (self.count, 2, 3, -1)) * _SIGNS[:, None, None]


def spring_rows(springs: np.ndarray, jacobian: np.ndarray) -> np.ndarray:
    """``S_c J_c`` of every channel stacked, (..., 3 C, n), of the springs *springs* (..., C, 3, 3) and the
    channels' Jacobians *jacobian* (..., 3 C, n) (:meth:`ChannelSet.jacobian`, or projected)."""
    rows = jacobian.reshape(jacobian.shape[:-2] + (-1, 3, jacobian.shape[-1]))
    product = springs @ rows
    return product.reshape(product.shape[:-3] + (-1, jacobian.shape[-1]))


def spring_matrix(springs: np.ndarray, jacobian: np.ndarray) -> np.ndarray:
    """``sum_c J_c^T S_c J_c`` (..., n, n) of the springs *springs* (..., C, 3, 3) and the channels'
    Jacobians *jacobian* (..., 3 C, n), as :func:`spring_rows`."""
    return jacobian.swapaxes(-1, -2) @ spring_rows(springs, jacobian)


def _on_points(channel_force: np.ndarray) -> np.ndarray:
    """A force per channel (..., C, 3) as the force on each marker's Jacobian row (..., 2 C, 3)."""
    return (channel_force[..., :, None, :] * _SIGNS[:, None]).reshape(channel_force.shape[:-2] + (-1, 3))


def scatter_sum(index: np.ndarray, values: np.ndarray, length: int) -> np.ndarray:
    """Sums of *values* (..., K) at the positions *index* (K,) in [0, length): shape (..., length)."""
    batch = values.shape[:-1]
    count = int(np.prod(batch, dtype=int))
    flat = (index[None, :] + length * np.arange(count)[:, None]).ravel()
    return np.bincount(flat, values.reshape(-1), count * length).reshape(batch + (length,))


def _euler(parameters: np.ndarray, second: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """The rotation A (..., 3, 3) of Euler parameters (..., 4), its derivatives (..., 4, 3, 3) and (with
    *second*) its second derivatives (..., 4, 4, 3, 3) (constant: A is quadratic in them)."""
    a = (parameters @ _EULER_ROWS.T).reshape(parameters.shape[:-1] + (3, 3, 4))          # A = I + a . e
    rotation = np.eye(3) + np.einsum("...abi,...i->...ab", a, parameters)
    firsts = 2 * np.moveaxis(a, -1, -3)
    seconds = np.broadcast_to(2 * EULER.transpose(2, 3, 0, 1), parameters.shape[:-1] + (4, 4, 3, 3)) if second \
        else None
    return rotation, firsts, seconds


def _rxyz(angles: np.ndarray, second: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Exudyn's Tait-Bryan rotation ``R_x R_y R_z`` of the angles (..., 3), its derivatives (..., 3, 3, 3) and
    (with *second*) its second derivatives (..., 3, 3, 3, 3)."""
    batch = angles.shape[:-1]
    x, y, z = np.moveaxis(_axis_derivatives(angles.reshape(-1, 3)), 1, 0)   # (p, order, 3, 3) each

    def product(orders: tuple[int, int, int]) -> np.ndarray:
        # d^i R_x d^j R_y d^k R_z of the derivative orders (i, j, k)
        return (x[:, orders[0]] @ y[:, orders[1]] @ z[:, orders[2]]).reshape(batch + (3, 3))

    firsts = np.stack([product((1, 0, 0)), product((0, 1, 0)), product((0, 0, 1))], axis=-3)
    if not second:
        return product((0, 0, 0)), firsts, None
    seconds = np.zeros(batch + (3, 3, 3, 3))
    for i in range(3):
        for j in range(i, 3):
            seconds[..., i, j, :, :] = seconds[..., j, i, :, :] = product(
                tuple(int(k == i) + int(k == j) for k in range(3)))  # type: ignore[arg-type]
    return product((0, 0, 0)), firsts, seconds


def _axis_derivatives(angles: np.ndarray) -> np.ndarray:
    """``d^k R_axis / d angle^k`` for the angles (p, 3): shape (p, 3 axes, 3 orders, 3, 3)."""
    c, s = np.cos(angles), np.sin(angles)
    cosines = np.stack([c, -s, -c], axis=-1)          # (p, axis, order)
    sines = np.stack([s, c, -s], axis=-1)
    one = np.array([1.0, 0.0, 0.0])
    out = np.zeros(angles.shape + (3, 3, 3))
    for axis, (i, j) in enumerate(((1, 2), (0, 2), (0, 1))):
        out[:, axis, :, axis, axis] = one
        out[:, axis, :, i, i] = cosines[:, axis]
        out[:, axis, :, j, j] = cosines[:, axis]
        sign = 1.0 if axis == 1 else -1.0            # R_y has +s above the diagonal
        out[:, axis, :, i, j] = sign * sines[:, axis]
        out[:, axis, :, j, i] = -sign * sines[:, axis]
    return out
