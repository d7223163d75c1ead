"""The preloaded scene as a Taylor expansion that NumPy can re-solve.

A design evaluation (:mod:`workbook.design.linear_mount`) moves the mount
only a little from the preloaded state the scene was prepared at (static
displacements of micrometres against link lengths of decimetres), but
changes its springs, the engine's mass properties and the loads a lot. So
the scene is split into the parts the design sets and the parts it does not:

- every force channel (hinge or test-rig transducer) is an Exudyn Cartesian
  spring-damper between two markers; its marker separation
  ``d(q) = p_1(q) - p_0(q)`` is kept with its Jacobian and Hessian in the
  coordinates of its two bodies (central differences of Exudyn's marker
  positions), and its force ``F = S d + S_d d'`` takes any 3x3 stiffness
  ``S`` and damping ``S_d`` of the design;
- the rest of the scene (bodies, static loads, rotors, the links' spin
  restraints) is the system with every channel's spring and damper set to
  zero: Exudyn's M, K and D of it and their first derivatives with respect
  to the coordinates of each body (the bodies do not couple without the
  channels, so one round of central differences serves every body);
- the engine's excitation points keep their position Jacobians and Hessians.

The expansion is exact in the design's springs at a fixed state and of second
order (channels) or first order (the rest) in the change of state; the
neglected terms are of the order of the squared rotations, about 1e-8.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbook.design.kinematics import identify
from workbook.errors import OutsideDesignModel, SimulationError
from workbook.scene.build import Scene
from workbook.solve.guards import solver_output
from workbook.solve.modes import body_coordinates as _body_coordinates

__all__ = ["ChannelGeometry", "BodyBlock", "SceneExpansion", "expand_scene"]

#: Coordinate step of the position derivatives (m, rad, Euler parameters,
#: modal coordinates: all of order 1 or below).
POSITION_STEP = 1e-4
#: Coordinate step of the derivatives of the rest's M, K and D.
MATRIX_STEP = 1e-5


@dataclass(frozen=True)
class ChannelGeometry:
    """A force channel's two marker points; its separation is ``d = p_1 - p_0``.

    Attributes
    ----------
    name : str
    coordinates : ndarray of int, shape (m,)
        Full ODE2 coordinates of its two markers' bodies.
    points : tuple of PointKinematics
        Marker 0 and marker 1.
    """

    name: str
    coordinates: np.ndarray
    points: tuple

    def separation(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """d (m), its Jacobian (3, m) and Hessian (3, m, m) at the total coordinates *q* (full)."""
        m = len(self.coordinates)
        separation = np.zeros(3)
        jacobian = np.zeros((3, m))
        hessian = np.zeros((3, m, m))
        for sign, point in zip((-1.0, 1.0), self.points, strict=True):
            p, j, h = point.expand(q[point.coordinates])
            at = np.searchsorted(self.coordinates, point.coordinates)
            separation += sign * p
            jacobian[:, at] += sign * j
            hessian[np.ix_(range(3), at, at)] += sign * h
        return separation, jacobian, hessian


@dataclass(frozen=True)
class BodyBlock:
    """M, K and D of one body of the rest of the scene, with their slopes.

    Attributes
    ----------
    coordinates : ndarray of int, shape (m,)
    mass, stiffness, damping : ndarray, shape (m, m)
        At the prepared state.
    mass_slope, stiffness_slope, damping_slope : ndarray, shape (m, m, m)
        ``[:, :, j]`` is the derivative with respect to coordinate j.
    """

    coordinates: np.ndarray
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    mass_slope: np.ndarray
    stiffness_slope: np.ndarray
    damping_slope: np.ndarray


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
    channels : dict of str to ChannelGeometry
        Every force channel, in the scene's order.
    blocks : list of BodyBlock
        The rest of the scene, one block per body.
    euler_blocks : list of ndarray of int, shape (4,)
        Coordinates of each Euler-parameter node (one constraint each).
    points : dict of tuple to PointKinematics
        The engine's excitation points by their rounded coordinates.
    """

    state: np.ndarray
    reference: np.ndarray
    channels: dict
    blocks: list
    euler_blocks: list
    points: dict


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


def _rest_matrices(mbs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    import exudyn as exu

    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    with solver_output():
        matrices = mbs.ComputeLinearizedSystem(settings, projectIntoConstraintNullspace=False)
    return tuple(np.asarray(m) for m in matrices[:3])  # type: ignore[return-value]


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


def _rest_blocks(scene: Scene, set_state, base: np.ndarray) -> list[BodyBlock]:
    restore = _channels_released(scene)
    try:
        set_state(base)
        mass, stiffness, damping = _rest_matrices(scene.mbs)
        blocks = list(_body_coordinates(scene).values())
        largest = max(len(block) for block in blocks)
        slopes = [[np.zeros((len(b), len(b), len(b))) for b in blocks] for _ in range(3)]
        for i in range(largest):
            shifted = []
            for sign in (1.0, -1.0):
                state = base.copy()
                for block in blocks:
                    if i < len(block):
                        state[block[i]] += sign * MATRIX_STEP
                set_state(state)
                shifted.append(_rest_matrices(scene.mbs))
            for k, block in enumerate(blocks):
                if i < len(block):
                    rows = np.ix_(block, block)
                    for m in range(3):
                        slopes[m][k][:, :, i] = (shifted[0][m][rows] - shifted[1][m][rows]) / (2 * MATRIX_STEP)
    finally:
        set_state(base)
        restore()
    return [BodyBlock(block, mass[np.ix_(block, block)], stiffness[np.ix_(block, block)],
                      damping[np.ix_(block, block)], slopes[0][k], slopes[1][k], slopes[2][k])
            for k, block in enumerate(blocks)]


def _euler_blocks(scene: Scene) -> list[np.ndarray]:
    import exudyn as exu

    mbs = scene.mbs
    if mbs.systemData.AEsize() == 0:
        return []
    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    with solver_output():
        jacobian = np.asarray(mbs.ComputeLinearizedSystem(settings, projectIntoConstraintNullspace=False,
                                                          returnConstraintJacobian=True)[3])
    blocks = []
    for row in jacobian.T:  # Exudyn gives it transposed: (coordinates, constraints)
        support = np.flatnonzero(row)
        if len(support) != 4 or not np.allclose(support, support[0] + np.arange(4)):
            raise SimulationError(f"scene of {scene.case.name!r}: a constraint other than an Euler-parameter "
                                  "normalisation; the design evaluation does not know it")
        blocks.append(support)
    return blocks


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
    channels = {}
    for k, (name, _) in enumerate(channel_markers):
        pair = (kinematics[2 * k], kinematics[2 * k + 1])
        channels[name] = ChannelGeometry(name, np.union1d(pair[0].coordinates, pair[1].coordinates), pair)
    offset = 2 * len(channel_markers)
    point_geometry = {tuple(np.round(np.asarray(p, dtype=float), 12)): kinematics[offset + k]
                      for k, p in enumerate(points)}
    return SceneExpansion(base, reference, channels, _rest_blocks(scene, set_state, base), _euler_blocks(scene), point_geometry)
