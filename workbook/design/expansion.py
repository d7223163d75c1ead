"""The preloaded scene as a Taylor expansion that NumPy can re-solve.

A design evaluation (:mod:`workbook.design.linear_mount`) moves the mount
a little from the preloaded state the scene was prepared at (static
displacements of millimetres against link lengths of decimetres: the links
turn by up to a few hundredths of a radian), but changes its springs, the
engine's mass properties and the loads a lot. So the scene is split into
the parts the design sets and the parts it does not:

- every force channel (hinge or test-rig transducer) is an Exudyn Cartesian
  spring-damper between two markers; its marker separation
  ``d(q) = p_1(q) - p_0(q)`` is kept with its Jacobian and Hessian in the
  coordinates of its two bodies (central differences of Exudyn's marker
  positions), and its force ``F = S d + S_d d'`` takes any 3x3 stiffness
  ``S`` and damping ``S_d`` of the design;
- the rest of the scene (bodies, static loads, rotors, the links' spin
  restraints, a flexible engine's bearings and spin restraint) is the system
  with every channel's spring and damper set to zero: its M, K and D as the
  pipeline linearises it (:func:`workbook.solve.modes.linearized_matrices`:
  K the central differences of Exudyn's equations, so that a design's
  preload is Exudyn's) and their first derivatives with respect to the
  coordinates of each block of bodies (a body alone, or the bodies the rest
  joins: a flexible engine's core and casing; blocks do not couple, so one
  round of central differences serves every block), and K's second derivatives with respect
  to the blocks' Euler parameters (the links' spin restraints turn with
  them);
- the engine's excitation points keep their position Jacobians and Hessians.

The expansion is exact in the design's springs at a fixed state and of second
order (channels) in the change of state; the rest's K is of second order in
the Euler parameters and of first order in the other coordinates, its M is
turned exactly with each body's rotation
(:func:`workbook.design.assembly.turned_mass`) and of first order in the
other coordinates, its D of first order. ``benchmarks/bench_design_evaluation.py``
prints how far the answers then are from the pipeline's for designs far
from the prepared one.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy import sparse

from workbook.design.blocks import BlockPlacement, BodyLayout, ChannelCoupling, body_layout
from workbook.design.channel_set import ChannelSet
from workbook.design.kinematics import PointKinematics, identify
from workbook.errors import OutsideDesignModel, SimulationError
from workbook.scene.build import Scene
from workbook.solve.modes import body_coordinates as _body_coordinates
from workbook.solve.modes import linearized_matrices

__all__ = ["RestBlocks", "SceneExpansion", "expand_scene"]

#: Coordinate step of the position derivatives (m, rad, Euler parameters,
#: modal coordinates: all of order 1 or below).
POSITION_STEP = 1e-4
#: Coordinate step of the derivatives of the rest's M, K and D.
MATRIX_STEP = 1e-5
#: Step in the Euler parameters of the second derivatives of the rest's K (larger than
#: :data:`MATRIX_STEP`: a second difference divides the round-off of K by its square).
CURVATURE_STEP = 1e-3


@dataclass(frozen=True)
class _BlockOperator:
    """Tensors (K, b, b, ...), mostly zero, as a sparse operator from vectors (..., K, m) (m: the tensors'
    trailing axes flattened) to the K products ``tensors[k] @ vectors[..., k, :]``, each a (b, b) matrix, of
    which it keeps the entries that are not zero.

    The slopes and the curvature of the bodies' matrices are mostly zero: few entries of a body's matrices
    change with few of its coordinates.
    """

    rows: np.ndarray              # the entries kept, among K b b
    operator: sparse.csr_array    # (rows, K m)
    columns: sparse.csr_array     # (rows, K b): picks the coordinate of each kept entry's column
    sums: sparse.csr_array        # (K b, rows): sums each kept entry into its row

    @classmethod
    def of(cls, tensors: np.ndarray) -> "_BlockOperator":
        """The operator of *tensors* (K, b, b, ...)."""
        blocks, width = tensors.shape[:2]
        whole = sparse.csr_array(sparse.block_diag(list(tensors.reshape(blocks, width * width, -1)), format="csr"))
        whole.eliminate_zeros()
        rows = np.flatnonzero(np.diff(whole.indptr))
        block, entry = np.divmod(rows, width * width)
        ones, kept = np.ones(len(rows)), np.arange(len(rows))
        columns = sparse.csr_array((ones, (kept, block * width + entry % width)), shape=(len(rows), blocks * width))
        sums = sparse.csr_array((ones, (block * width + entry // width, kept)), shape=(blocks * width, len(rows)))
        return cls(rows, whole[rows], columns, sums)

    def products(self, vectors: np.ndarray) -> np.ndarray:
        """The kept entries of the products with *vectors* (..., K, m): (len(rows), prod(...))."""
        return self.operator @ vectors.reshape((-1, vectors.shape[-2] * vectors.shape[-1])).T

    def add_to(self, out: np.ndarray, vectors: np.ndarray, weight: float) -> None:
        """Add *weight* times the products with *vectors* (..., K, m) to *out* (..., K b b) (its kept entries)."""
        target = out.reshape((-1, out.shape[-1]))
        assert np.may_share_memory(target, out), "the sums need a contiguous out"
        target[:, self.rows] += weight * self.products(vectors).T

    def applied(self, vectors: np.ndarray, local: np.ndarray) -> np.ndarray:
        """The products with *vectors* (..., K, m), each a (b, b) matrix, applied to *local* (..., K, b):
        (K b, prod(...))."""
        flat = local.reshape((-1, local.shape[-2] * local.shape[-1])).T
        return self.sums @ (self.products(vectors) * (self.columns @ flat))


@dataclass(frozen=True)
class RestBlocks:
    """M, K and D of the rest of the scene, one block per body, with their slopes.

    The blocks are stacked and padded with the spare coordinate N (zero
    entries), so that every block is evaluated at once.

    Attributes
    ----------
    size : int
        N, the full coordinates.
    coordinates : ndarray of int, shape (B, b)
    mass, stiffness, damping : ndarray, shape (B, b, b)
        At the prepared state.
    mass_slope, stiffness_slope, damping_slope : ndarray, shape (B, b, b, b)
        ``[..., j]`` is the derivative with respect to the block's coordinate j.
    turning : ndarray of int, shape (B, S)
        Each block's Euler parameters (positions in the block, padded with
        b: none).
    stiffness_curvature : ndarray, shape (B, b, b, S, S)
        The second derivatives of K with respect to them (a link's spin
        restraint turns with the link: of first order, K would miss 1e-4 of
        its entries at a hundredth of a radian).
    """

    size: int
    coordinates: np.ndarray
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    mass_slope: np.ndarray
    stiffness_slope: np.ndarray
    damping_slope: np.ndarray
    turning: np.ndarray
    stiffness_curvature: np.ndarray

    def _local(self, dq: np.ndarray) -> np.ndarray:
        """*dq* (..., N) per block: (..., B, b)."""
        return np.concatenate([dq, np.zeros(dq.shape[:-1] + (1,))], axis=-1)[..., self.coordinates]

    def _pairs(self, local: np.ndarray) -> np.ndarray:
        """The products of every two Euler parameters of each block of *local* (..., B, b): (..., B, S S)."""
        blocks = len(self.coordinates)
        padded = np.concatenate([local, np.zeros(local.shape[:-1] + (1,))], axis=-1)
        turned = padded[..., np.arange(blocks)[:, None], self.turning]
        return (turned[..., :, None] * turned[..., None, :]).reshape(local.shape[:-2] + (blocks, -1))

    def _curved(self, out: np.ndarray, local: np.ndarray, weight: float) -> None:
        """Add *weight* times the curvature term of K along the Euler parameters of *local* (..., B, b) to the
        blocks *out* (..., B, b, b)."""
        self._operators["curvature"].add_to(out.reshape(out.shape[:-3] + (-1,)), self._pairs(local), weight)

    def full(self, blocks: np.ndarray) -> np.ndarray:
        """The blocks (..., B, b, b) scattered into a full matrix (..., N, N)."""
        return self._placement.place(blocks)

    @functools.cached_property
    def _placement(self) -> BlockPlacement:
        return BlockPlacement.of(self.coordinates, self.size)

    @functools.cached_property
    def _operators(self) -> dict:
        """The slopes and the curvature of K as :class:`_BlockOperator`, by name."""
        operators = {name: _BlockOperator.of(getattr(self, f"{name}_slope")) for name in ("mass", "stiffness", "damping")}
        operators["curvature"] = _BlockOperator.of(self.stiffness_curvature)
        return operators

    def _sloped(self, name: str, local: np.ndarray, weight: float = 1.0) -> np.ndarray:
        """``matrix + weight slope . local`` per block of the matrix *name* (``"mass"``, ``"stiffness"``,
        ``"damping"``) at *local* (..., B, b): (..., B, b, b)."""
        matrix = getattr(self, name)
        out = np.repeat(matrix[None], int(np.prod(local.shape[:-2], dtype=int)), axis=0)
        self._operators[name].add_to(out.reshape(len(out), -1), local, weight)
        return out.reshape(local.shape[:-2] + matrix.shape)

    def at(self, name: str, dq: np.ndarray) -> np.ndarray:
        """The blocks (..., B, b, b) of the matrix *name* (``"mass"``, ``"stiffness"``, ``"damping"``) at the
        state change *dq* (..., N): K of second order in the Euler parameters and of first in the rest, M and
        D of first order (:meth:`full` places them in the whole matrix)."""
        local = self._local(dq)
        blocks = self._sloped(name, local)
        if name == "stiffness":
            self._curved(blocks, local, 0.5)
        return blocks

    def force_change(self, dq: np.ndarray) -> np.ndarray:
        """The change of the rest's internal force over *dq* (..., N): ``(K + K' dq / 2 + K'' dq dq / 6) dq``."""
        local = self._local(dq)
        operators = self._operators
        terms = 0.5 * operators["stiffness"].applied(local, local) \
            + operators["curvature"].applied(self._pairs(local), local) / 6.0
        change = np.einsum("kij,...kj->...ki", self.stiffness, local) + terms.T.reshape(local.shape)
        out = np.zeros(dq.shape[:-1] + (self.size + 1,))
        out[..., self.coordinates] = change           # each coordinate is in one block; the padding goes to N
        return out[..., :self.size]


@dataclass(frozen=True)
class SceneExpansion:
    """The prepared scene as the parts a design evaluation re-assembles.

    Attributes
    ----------
    state : ndarray, shape (N,)
        ODE2 coordinates of the prepared (preloaded) state (Exudyn's
        coordinates: relative to the reference ones).
    reference : ndarray, shape (N,)
        Exudyn's reference coordinates; a node's configuration is their sum.
    channel_names : list of str
        Every force channel, in the scene's order.
    channels : ChannelSet
        Their marker points.
    rest : RestBlocks
        The rest of the scene.
    euler_blocks : ndarray of int, shape (E, 4)
        Coordinates of each Euler-parameter node (one constraint each).
    points : dict of tuple to PointKinematics
        The engine's excitation points by their rounded coordinates.
    """

    state: np.ndarray
    reference: np.ndarray
    channel_names: list
    channels: ChannelSet
    rest: RestBlocks
    euler_blocks: np.ndarray
    points: dict

    @functools.cached_property
    def free(self) -> np.ndarray:
        """The coordinates that are not Euler parameters (independent as they are)."""
        return np.setdiff1d(np.arange(len(self.state)), self.euler_blocks.ravel())

    @functools.cached_property
    def layout(self) -> BodyLayout:
        """Where each body's coordinates sit among the full and the independent coordinates."""
        return body_layout(self)

    @functools.cached_property
    def coupling(self) -> ChannelCoupling:
        """How the force channels join the bodies."""
        return ChannelCoupling.of(self.layout, self.channels)

    @functools.cached_property
    def point_set(self) -> ChannelSet:
        """The excitation points as channels from the ground (at the origin) to each point, in the order of
        :attr:`points`: a channel's Jacobian is its point's."""
        ground = PointKinematics(np.zeros(0, dtype=int), "none", np.zeros(3), np.zeros((3, 0)))
        return ChannelSet.of([(ground, point) for point in self.points.values()], len(self.state))


def _marker_coordinates(mbs, marker: int) -> np.ndarray:
    """ODE2 coordinates a marker moves with (none on the ground)."""
    import exudyn as exu

    data = mbs.GetMarker(marker)
    if "nodeNumber" in data and "bodyNumber" not in data:
        nodes = [data["nodeNumber"]]
    else:
        body = mbs.GetObject(data["bodyNumber"])
        nodes = body.get("nodeNumbers", [body["nodeNumber"]] if "nodeNumber" in body else [])
    indices: list[int] = []
    for node in nodes:
        size = len(mbs.GetNodeOutput(node, exu.OutputVariableType.Coordinates))
        if size:
            start = mbs.GetNodeODE2Index(node)
            indices.extend(range(start, start + size))
    return np.array(indices, dtype=int)


def _position_expansion(set_state, base: np.ndarray, positions, coordinates: list[np.ndarray]
                        ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Position, Jacobian and Hessian of several points at once by central differences.

    *positions()* returns the points' positions, shape (p, 3); point i moves
    with *coordinates[i]*. Points on different coordinates are perturbed
    together (a point's position does not depend on other coordinates).
    """
    h = POSITION_STEP
    set_state(base)
    centre = positions()
    sizes = [len(c) for c in coordinates]
    largest = max(sizes, default=0)
    jacobians = [np.zeros((3, s)) for s in sizes]
    hessians = [np.zeros((3, s, s)) for s in sizes]

    def shifted(steps: dict[int, float]) -> np.ndarray:
        # steps: local coordinate -> step, applied to every point's coordinates
        state = base.copy()
        touched = set()
        for index in coordinates:
            for local, step in steps.items():
                if local < len(index) and index[local] not in touched:
                    state[index[local]] += step
                    touched.add(index[local])
        set_state(state)
        return positions()

    for i in range(largest):
        plus, minus = shifted({i: h}), shifted({i: -h})
        for k, size in enumerate(sizes):
            if i < size:
                jacobians[k][:, i] = (plus[k] - minus[k]) / (2 * h)
                hessians[k][:, i, i] = (plus[k] - 2 * centre[k] + minus[k]) / h ** 2
        for j in range(i + 1, largest):
            corners = [shifted({i: si * h, j: sj * h}) for si, sj in ((1, 1), (1, -1), (-1, 1), (-1, -1))]
            mixed = (corners[0] - corners[1] - corners[2] + corners[3]) / (4 * h ** 2)
            for k, size in enumerate(sizes):
                if j < size:
                    hessians[k][:, i, j] = hessians[k][:, j, i] = mixed[k]
    set_state(base)
    return [(centre[k], jacobians[k], hessians[k]) for k in range(len(sizes))]


def _rest_matrices(scene: Scene, blocks: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return linearized_matrices(scene, blocks)[:3]


def _channels_released(scene: Scene):
    """Set every force channel's spring, damper and law to zero; returns the restore function."""
    mbs = scene.mbs
    saved = []
    for items in scene.force_channels.values():
        connector = items.connector
        data = mbs.GetObject(connector)
        saved.append((connector, list(data["stiffness"]), list(data["damping"]), getattr(items, "law", None)))
        mbs.SetObjectParameter(connector, "stiffness", [0.0] * 3)
        mbs.SetObjectParameter(connector, "damping", [0.0] * 3)
        if getattr(items, "law", None) is not None:
            mbs.SetObjectParameter(connector, "springForceUserFunction", 0)

    def restore() -> None:
        for connector, stiffness, damping, law in saved:
            mbs.SetObjectParameter(connector, "stiffness", stiffness)
            mbs.SetObjectParameter(connector, "damping", damping)
            if law is not None:
                mbs.SetObjectParameter(connector, "springForceUserFunction", law)

    return restore


def _coupled_blocks(blocks: list[np.ndarray], matrices) -> list[np.ndarray]:
    """*blocks* (each body's coordinates) joined where any of *matrices* (N, N) couples them.

    Without the channels, bodies couple only through the connectors of the
    rest: a flexible engine's bearings and spin restraint join its core to its
    casing. Bodies so joined make one block of their coordinates.
    """
    coupled = np.zeros((len(blocks), len(blocks)), dtype=bool)
    for matrix in matrices:
        for i, rows in enumerate(blocks):
            for j, columns in enumerate(blocks):
                coupled[i, j] |= i != j and bool(np.any(matrix[np.ix_(rows, columns)]))
    groups: list[set[int]] = []
    for i in range(len(blocks)):
        group = {i} | set(np.flatnonzero(coupled[i] | coupled[:, i]).tolist())
        for other in [g for g in groups if g & group]:
            groups.remove(other)
            group |= other
        groups.append(group)
    return [np.concatenate([blocks[i] for i in sorted(group)]) for group in sorted(groups, key=min)]


def _rest_blocks(scene: Scene, set_state, base: np.ndarray) -> RestBlocks:
    size = len(base)
    restore = _channels_released(scene)
    try:
        set_state(base)
        at_base = _rest_matrices(scene)
        blocks = _coupled_blocks(list(_body_coordinates(scene).values()), at_base)
        width = max(len(block) for block in blocks)
        coordinates = np.full((len(blocks), width), size, dtype=int)
        for k, block in enumerate(blocks):
            coordinates[k, :len(block)] = block
        rows, columns = coordinates[:, :, None], coordinates[:, None, :]

        def padded(matrix: np.ndarray) -> np.ndarray:
            full = np.zeros((size + 1, size + 1))
            full[:size, :size] = matrix
            return full[rows, columns]

        matrices = [padded(m) for m in at_base]
        slopes = [np.zeros((len(blocks), width, width, width)) for _ in range(3)]
        for i in range(width):
            shifted = []
            for sign in (1.0, -1.0):
                state = base.copy()
                for block in blocks:
                    if i < len(block):
                        state[block[i]] += sign * MATRIX_STEP
                set_state(state)
                shifted.append([padded(m) for m in _rest_matrices(scene, coordinates)])
            for m in range(3):
                slopes[m][:, :, :, i] = (shifted[0][m] - shifted[1][m]) / (2 * MATRIX_STEP)
        turning = _turning(blocks, _rotation_coordinates(scene), width)
        curvature = _stiffness_curvature(scene, set_state, base, coordinates, turning, matrices[1], padded)
    finally:
        set_state(base)
        restore()
    return RestBlocks(size, coordinates, matrices[0], matrices[1], matrices[2], slopes[0], slopes[1], slopes[2],
                      turning, curvature)


def _rotation_coordinates(scene: Scene) -> np.ndarray:
    """The rotation coordinates of every rigid-body node: Euler parameters and Tait-Bryan angles."""
    mbs = scene.mbs
    found: list[int] = []
    for node in range(mbs.systemData.NumberOfNodes()):
        kind = str(mbs.GetNode(node)["nodeType"])
        count = {"RigidBodyEP": 4, "RigidBodyRxyz": 3}.get(kind, 0)
        if count:
            start = mbs.GetNodeODE2Index(node) + 3
            found.extend(range(start, start + count))
    return np.array(found, dtype=int)


def _turning(blocks: list[np.ndarray], rotations: np.ndarray, width: int) -> np.ndarray:
    """Each block's rotation coordinates as positions in the block, padded with *width*: (B, S)."""
    positions = [np.flatnonzero(np.isin(block, rotations)) for block in blocks]
    turning = np.full((len(blocks), max((len(p) for p in positions), default=0)), width, dtype=int)
    for k, found in enumerate(positions):
        turning[k, :len(found)] = found
    return turning


def _stiffness_curvature(scene: Scene, set_state, base: np.ndarray, coordinates: np.ndarray, turning: np.ndarray,
                         stiffness: np.ndarray, padded) -> np.ndarray:
    """The second derivatives of the rest's K along each block's Euler parameters: (B, b, b, S, S).

    Central differences of step :data:`CURVATURE_STEP`, every block at once
    (blocks do not couple without the channels)."""
    count, width = turning.shape[1], coordinates.shape[1]
    curvature = np.zeros((len(coordinates), width, width, count, count))
    h = CURVATURE_STEP

    def at(steps: dict[int, float]) -> np.ndarray:
        state = base.copy()
        for slot, step in steps.items():
            for block, position in zip(coordinates, turning[:, slot], strict=True):
                if position < width:
                    state[block[position]] += step
        set_state(state)
        return padded(_rest_matrices(scene, coordinates)[1])

    for s in range(count):
        curvature[..., s, s] = (at({s: h}) - 2 * stiffness + at({s: -h})) / h ** 2
        for t in range(s + 1, count):
            mixed = (at({s: h, t: h}) - at({s: h, t: -h}) - at({s: -h, t: h}) + at({s: -h, t: -h})) / (4 * h ** 2)
            curvature[..., s, t] = curvature[..., t, s] = mixed
    return curvature


def _euler_blocks(scene: Scene) -> np.ndarray:
    mbs = scene.mbs
    if mbs.systemData.AEsize() == 0:
        return np.zeros((0, 4), dtype=int)
    jacobian = linearized_matrices(scene)[3]
    blocks = []
    for row in jacobian.T:  # Exudyn gives it transposed: (coordinates, constraints)
        support = np.flatnonzero(row)
        if len(support) != 4 or not np.allclose(support, support[0] + np.arange(4)):
            raise SimulationError(f"scene of {scene.case.name!r}: a constraint other than an Euler-parameter "
                                  "normalisation; the design evaluation does not know it")
        blocks.append(support)
    return np.array(blocks, dtype=int).reshape(-1, 4)


def expand_scene(scene: Scene, points: list) -> SceneExpansion:
    """Expand *scene*, solved for its preload, about its current state.

    Parameters
    ----------
    scene : Scene
    points : list of array_like, shape (3,)
        Points of the engine (global, reference state, m) where excitations act.

    Returns
    -------
    SceneExpansion
    """
    import exudyn as exu

    mbs = scene.mbs
    data = mbs.systemData
    current = exu.ConfigurationType.Current
    base = np.array(data.GetODE2Coordinates(configuration=current))
    reference = np.array(data.GetODE2Coordinates(configuration=exu.ConfigurationType.Reference))

    def set_state(q: np.ndarray) -> None:
        # the initial configuration too: Exudyn linearises there
        data.SetODE2Coordinates(list(q), configuration=current)
        data.SetODE2Coordinates(list(q), configuration=exu.ConfigurationType.Initial)

    channel_markers = [(name, items.markers) for name, items in scene.force_channels.items()]
    markers = [marker for _, pair in channel_markers for marker in pair]
    marker_coordinates = [_marker_coordinates(mbs, marker) for marker in markers]
    engine_body = scene.engine.body
    centre = np.asarray(scene.case.engine.center_of_mass)
    engine_coordinates = _marker_coordinates(mbs, scene.engine.marker_rigid)

    def positions() -> np.ndarray:
        at_markers = [mbs.GetMarkerOutput(m, exu.OutputVariableType.Position, configuration=current)
                      for m in markers]
        at_points = [mbs.GetObjectOutputBody(engine_body, exu.OutputVariableType.Position,
                                             localPosition=list(np.subtract(p, centre)), configuration=current)
                     for p in points]
        return np.array(at_markers + at_points, dtype=float).reshape(-1, 3)

    # one expansion per point; points on the same body are perturbed together
    expanded = _position_expansion(set_state, base, positions, marker_coordinates + [engine_coordinates] * len(points))
    total = reference + base
    try:
        kinematics = [identify(c, total[c], *e) for c, e in
                      zip(marker_coordinates + [engine_coordinates] * len(points), expanded, strict=True)]
    except ValueError as error:
        raise OutsideDesignModel(scene.case.name, f"a marker it does not know ({error})") from None
    pairs = [(kinematics[2 * k], kinematics[2 * k + 1]) for k in range(len(channel_markers))]
    offset = 2 * len(channel_markers)
    point_geometry = {tuple(np.round(np.asarray(p, dtype=float), 12)): kinematics[offset + k]
                      for k, p in enumerate(points)}
    return SceneExpansion(base, reference, [name for name, _ in channel_markers], ChannelSet.of(pairs, len(base)),
                          _rest_blocks(scene, set_state, base), _euler_blocks(scene), point_geometry)
