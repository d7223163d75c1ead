"""Linearised modes of a scene: free motions (mechanisms) and mounted modes.

The system is linearised at its initial state: M, D and the constraint
Jacobian are Exudyn's (its static solver's, as ``ComputeLinearizedSystem``
takes them); K is the central difference of Exudyn's ODE2 right-hand side,
the derivative of the equations Exudyn solves. Exudyn's own Jacobian
leaves out part of the connectors' second-order terms on rotation nodes
(the hinge forces turning with the engine's Tait-Bryan angles, the links'
spin restraints): on the reference mount some of its entries are 4e-6 off,
which moved T by up to 1e-6 and, carried over a design's change of preload
by the design evaluation's expansion (:mod:`workbook.design.expansion`),
its static hinge forces by up to 1e-4 (``tests/test_linear_mount.py``).
The mechanism and stability checks take Exudyn's own K (``exact=False``,
about 15 times cheaper: the sign of a mode does not see it). K holds the geometric stiffness of the preload for the bodies'
rigid-body motion (the hinge forces turning with a link or the engine); a
flexible link's modal coordinates have the stiffness of its reduced body,
which holds its own stress stiffening only when that effect built it in
(:mod:`workbook.solve.stress_stiffening`). Euler-parameter nodes of the links add
one algebraic constraint each; the matrices are projected onto the null
space of the constraint Jacobian. Then

- a *free motion* is an eigenvector of ``K x = w^2 M x`` with w close to zero:
  the scene is a mechanism; it is described by the engine's motion (heading,
  lateral, vertical translation; roll, pitch, yaw) or, when the engine does
  not move, by the links that do;
- a *mounted mode* is a mode in which most of the kinetic energy is in the
  engine: the engine's rigid-body modes on its mount. Their modal decay
  rates ``sigma = phi^T D phi / (2 phi^T M phi)`` set the settle time.

Spinning rotors (``Case.rotors``, built as an ``ObjectGenericODE2`` on the
engine node, see :func:`workbook.scene.build.exudyn_gyroscopic_function`) make D
skew-symmetric in the engine's rotation coordinates: Exudyn differentiates
the rotor force with respect to the velocities, so its D already holds the
gyroscopic matrix ``G`` (exactly, at the preloaded rotation; about the
reference state ``G = -[h]x`` with h the rotors' spin angular momentum).
The linearisation records G separately, and the modes are then those of the
undamped gyroscopic system ``M x'' + G x' + K x = 0``: eigenvalues
``+-i w``, split by the spin into forward and backward whirl.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from workbook.errors import SimulationError
from workbook.model.case import ENGINE
from workbook.scene.build import Scene
from workbook.solve.guards import solver_output

__all__ = ["Linearization", "Mode", "linearize", "linearized_matrices", "STIFFNESS_STEP",
           "body_coordinates", "eigenpairs", "modes_from", "modes_of", "free_motions", "unstable_modes", "mounted_modes",
           "describe_engine_motion", "FREE_FREQUENCY_HZ", "ENGINE_MOTIONS"]

#: Modes below this frequency count as free motions (mechanisms), Hz. The
#: links' spin restraints add modes at about 1 Hz and more.
FREE_FREQUENCY_HZ = 0.05
#: Names of the engine's six motions, in the order of its node coordinates.
ENGINE_MOTIONS = ("heading translation (x)", "lateral translation (y)", "vertical translation (z)",
                  "roll (rotation about x)", "pitch (rotation about y)", "yaw (rotation about z)")
#: A mode is a mounted mode when at least this share of its kinetic energy is in the engine.
ENGINE_SHARE = 0.5
#: Coordinate step of the stiffness's central differences (m, rad, Euler parameters, modal coordinates).
STIFFNESS_STEP = 1e-6


@dataclass(frozen=True)
class Linearization:
    """Linearised equations ``M x'' + D x' + K x = f`` in independent coordinates.

    Attributes
    ----------
    mass, stiffness, damping : ndarray, shape (n, n)
        Projected matrices (kg, N/m, N s/m in the coordinates' units).
    basis : ndarray, shape (N, n)
        Full ODE2 coordinates from independent ones: ``q = basis @ x``.
    full_mass : ndarray, shape (N, N)
        Unprojected mass matrix.
    body_coordinates : dict of str to ndarray of int
        Full ODE2 coordinate indices of each body.
    gyroscopic : ndarray, shape (n, n), or None
        The rotors' gyroscopic matrix G (skew-symmetric, N m s), projected;
        *damping* already contains it. None when no rotor is built.
    structural : ndarray, shape (n, n), or None
        Structural damping H of loss factors (complex stiffness K + i H,
        N/m ...; :mod:`workbook.solve.harmonic`), when the frequency domain
        adds it; a mode of circular frequency w counts it as the viscous
        damping H / w.
    """

    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    basis: np.ndarray
    full_mass: np.ndarray
    body_coordinates: dict
    gyroscopic: np.ndarray | None = None
    structural: np.ndarray | None = None


@dataclass(frozen=True)
class Mode:
    """One linearised mode.

    Attributes
    ----------
    frequency_hz : float
        Undamped natural frequency, Hz.
    decay_rate : float
        Modal decay rate sigma, 1/s (free vibration decays as exp(-sigma t)).
    engine_share : float
        Share of the modal kinetic energy in the engine, 0 to 1.
    engine_shape : ndarray, shape (6,)
        The engine's motion (x, y, z in m; rotations about x, y, z in rad),
        largest component 1 in magnitude.
    body_shares : dict of str to float
        Share of the modal kinetic energy per body.
    omega_squared : float
        Signed squared circular frequency, rad^2/s^2: negative for a
        direction in which the stiffness is negative (a buckling or tipping
        mount), whose *frequency_hz* is then 0.
    """

    frequency_hz: float
    decay_rate: float
    engine_share: float
    engine_shape: np.ndarray
    body_shares: dict
    omega_squared: float = 0.0

    @property
    def mounted(self) -> bool:
        """Most of the kinetic energy in the engine (:data:`ENGINE_SHARE`)."""
        return self.engine_share >= ENGINE_SHARE

    @property
    def damping_ratio(self) -> float:
        """Modal damping ratio zeta = sigma / w."""
        omega = 2 * np.pi * self.frequency_hz
        return self.decay_rate / omega if omega > 0 else float("inf")

    @property
    def description(self) -> str:
        """The engine's dominant motions, or the moving links when the engine is still."""
        if self.engine_share >= 0.1:
            return describe_engine_motion(self.engine_shape)
        moving = sorted(self.body_shares.items(), key=lambda item: -item[1])
        names = [name for name, share in moving if share >= 0.1 * moving[0][1]][:3]
        return "motion of " + ", ".join(repr(name) for name in names) + " with the engine still"


def body_coordinates(scene: Scene) -> dict[str, np.ndarray]:
    import exudyn as exu

    mbs = scene.mbs
    indices = {}
    for body, nodes in scene.body_nodes().items():
        coordinates: list[int] = []
        for node in nodes:
            start = mbs.GetNodeODE2Index(node)
            size = len(mbs.GetNodeOutput(node, exu.OutputVariableType.Coordinates))
            coordinates.extend(range(start, start + size))
        indices[body] = np.array(coordinates, dtype=int)
    return indices


def linearized_matrices(scene: Scene, blocks: np.ndarray | None = None, *, exact: bool = True
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """M, K, D and the constraint Jacobian ``C`` (ODE2 rows, one column per algebraic equation) of
    *scene* at its initial state, the excitation paused.

    M, D and C are Exudyn's (its static solver's mass matrix and Jacobians, as
    ``ComputeLinearizedSystem(returnConstraintJacobian=True)`` takes them). K
    is ``-df/dq`` by central differences (step :data:`STIFFNESS_STEP`) of
    Exudyn's ODE2 right-hand side f: the derivative of the equations Exudyn
    solves (see the module text).

    Parameters
    ----------
    scene : Scene
    blocks : ndarray of int, shape (B, b), optional
        Coordinates of bodies that no force couples, padded with N: the
        same position of every block is differenced at once (2 b evaluations
        of f instead of 2 N), and K has no entries between blocks.
    exact : bool
        False takes Exudyn's own K (about 15 times cheaper, 4e-6 of some entries
        off: enough for the sign of a mode, as the mechanism and stability
        checks ask it).
    """
    import exudyn as exu

    mbs = scene.mbs
    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    settings.solution.sensors.active = False
    settings.staticSolver.verboseMode = 0
    solver: Any = exu.MainSolverStatic()    # Any: Exudyn's stubs declare the solver's methods without self
    with solver_output(), scene.excitation_paused():
        solver.InitializeSolver(mbs, settings)
        ode2, ode1 = solver.GetODE2size(), solver.GetODE1size()
        solver.ComputeMassMatrix(mbs)
        mass = np.asarray(solver.GetSystemMassMatrix())[:ode2, :ode2]
        # the ODE2 part first: it sets up the system Jacobian the constraints' part is added to
        solver.ComputeJacobianODE2RHS(mbs, scalarFactor_ODE2=-1, scalarFactor_ODE2_t=0, scalarFactor_ODE1=0)
        if solver.GetAEsize() > 0:
            solver.ComputeJacobianAE(mbs, scalarFactor_ODE2=1.0, scalarFactor_ODE2_t=0.0, scalarFactor_ODE1=0.0,
                                     velocityLevel=False)
        jacobian = np.asarray(solver.GetSystemJacobian())
        solver.ComputeJacobianODE2RHS(mbs, scalarFactor_ODE2=0, scalarFactor_ODE2_t=-1, scalarFactor_ODE1=0)
        damping = np.asarray(solver.GetSystemJacobian())[:ode2, :ode2]
        stiffness = _stiffness(mbs, solver, ode2, blocks) if exact else jacobian[:ode2, :ode2]
        solver.FinalizeSolver(mbs, settings)
    return mass, stiffness, damping, jacobian[:ode2, ode2 + ode1:]


def _stiffness(mbs, solver: Any, size: int, blocks: np.ndarray | None) -> np.ndarray:
    """``-df/dq`` (size, size) of Exudyn's ODE2 right-hand side f at the current state by central differences;
    *blocks* as :func:`linearized_matrices` takes them (None: every coordinate alone)."""
    import exudyn as exu

    data = mbs.systemData
    current = exu.ConfigurationType.Current
    base = np.array(data.GetODE2Coordinates(configuration=current))
    groups = np.arange(size)[:, None] if blocks is None else np.asarray(blocks).T     # (positions, blocks)
    owner = np.full(size + 1, -1)
    if blocks is not None:
        for k, block in enumerate(np.asarray(blocks)):
            owner[block] = k
        owner[size] = -1

    def force(state: np.ndarray) -> np.ndarray:
        data.SetODE2Coordinates(list(state), configuration=current)
        solver.ComputeODE2RHS(mbs)
        return np.array(solver.GetSystemResidual())[:size]

    stiffness = np.zeros((size, size))
    try:
        for columns in groups:
            columns = columns[columns < size]
            shifted = []
            for sign in (1.0, -1.0):
                state = base.copy()
                state[columns] += sign * STIFFNESS_STEP
                shifted.append(force(state))
            change = -(shifted[0] - shifted[1]) / (2 * STIFFNESS_STEP)
            if blocks is None:
                stiffness[:, columns[0]] = change
            else:
                for column in columns:
                    rows = owner[:size] == owner[column]
                    stiffness[rows, column] = change[rows]
    finally:
        data.SetODE2Coordinates(list(base), configuration=current)
    return stiffness


def linearize(scene: Scene, *, exact: bool = True) -> Linearization:
    """Linearise *scene* at its initial state (after a static solve with
    ``updateInitialValues=True``: the preloaded state); *exact* as
    :func:`linearized_matrices` takes it.

    With rotors built (``scene.gyroscopics``), the gyroscopic matrix is the
    skew-symmetric part of Exudyn's D in the engine's rotation coordinates
    (the only skew-symmetric damping of the scene: hinge and Rayleigh damping
    are symmetric).
    """
    mass, stiffness, damping, jacobian = linearized_matrices(scene, exact=exact)
    size = mass.shape[0]
    if jacobian.shape[1] > 0:
        left, singular, _ = np.linalg.svd(jacobian)
        rank = int((singular > 1e-12 * max(singular.max(), 1.0)).sum())
        basis = left[:, rank:]
    else:
        basis = np.eye(size)
    project = lambda matrix: basis.T @ matrix @ basis  # noqa: E731
    coordinates = body_coordinates(scene)
    gyroscopic = None
    if scene.gyroscopics is not None:
        rotations = np.ix_(coordinates[ENGINE][3:], coordinates[ENGINE][3:])
        gyroscopic = np.zeros_like(damping)
        gyroscopic[rotations] = (damping[rotations] - damping[rotations].T) / 2
        gyroscopic = project(gyroscopic)
    return Linearization(project(mass), project(stiffness), project(damping), basis, mass, coordinates,
                         gyroscopic)


def eigenpairs(lin: Linearization) -> tuple[np.ndarray, np.ndarray]:
    """Squared circular frequencies (rad^2/s^2) and mode vectors, by ascending frequency.

    Without rotors: ``K x = w^2 M x``. With rotors: the undamped gyroscopic
    system ``(lambda^2 M + lambda G + K) x = 0`` in first-order form; its
    eigenvalues come in pairs ``+-i w`` and the one with ``Im lambda > 0``
    of each pair is kept; of the real ones (free motions near zero, or a
    negative-stiffness pair ``+-lambda`` counting as ``w^2 = -lambda^2``)
    the larger half.

    Raises
    ------
    SimulationError
        M is not positive definite (a motion without mass).
    """
    # M = L L^T (every coordinate has mass): a standard eigenproblem in y = L^T x
    try:
        factor = np.linalg.cholesky(lin.mass)
    except np.linalg.LinAlgError:
        raise SimulationError("the linearised mass matrix is not positive definite: the scene has a motion "
                              "without mass, whose modes are undefined") from None

    def whitened(matrix):
        """``L^-1 A L^-T``."""
        return np.linalg.solve(factor, np.linalg.solve(factor, matrix).T).T

    stiffness = whitened(lin.stiffness)
    if lin.gyroscopic is None:
        eigenvalues, vectors = np.linalg.eig(stiffness)
        order = np.argsort(eigenvalues.real)
        return eigenvalues.real[order], np.linalg.solve(factor.T, vectors[:, order])
    size = lin.mass.shape[0]
    identity, zero = np.eye(size), np.zeros((size, size))
    eigenvalues, vectors = np.linalg.eig(np.block([[zero, identity], [-stiffness, -whitened(lin.gyroscopic)]]))
    tolerance = 1e-9 * np.abs(eigenvalues).max()
    half_plane = np.where(eigenvalues.imag > tolerance, 0, np.where(eigenvalues.imag < -tolerance, 2, 1))
    keep = np.lexsort((-eigenvalues.real, half_plane))[:size]
    squared = -(eigenvalues[keep] ** 2).real
    order = np.argsort(squared)
    return squared[order], np.linalg.solve(factor.T, vectors[:size, keep[order]])


def modes_of(linearization: Linearization, *, gyroscopic: bool = True) -> list[Mode]:
    """All modes of a linearisation, by ascending frequency.

    Parameters
    ----------
    linearization : Linearization
    gyroscopic : bool
        False: the modes of ``K x = w^2 M x`` even with rotors built. Only
        stiffness restrains a motion, so mechanisms and instabilities are
        judged on these (a fast rotor drives its backward whirl towards
        0 Hz although nothing is free).
    """
    lin = linearization if gyroscopic else dataclasses.replace(linearization, gyroscopic=None)
    return modes_from(lin, *eigenpairs(lin))


def modes_from(lin: Linearization, squared_frequencies: np.ndarray, vectors: np.ndarray) -> list[Mode]:
    """The modes of the eigenpairs of *lin* (:func:`eigenpairs`): their energies, shares and shapes."""

    def energy(matrix, shapes):
        """``Re(x^H A x)`` of every column x of *shapes*."""
        return np.real(np.sum(np.conj(shapes) * (matrix @ shapes), axis=0))

    full = lin.basis @ vectors
    kinetic = energy(lin.mass, vectors)
    shares = {body: energy(lin.full_mass[np.ix_(coordinates, coordinates)], full[coordinates]) / kinetic
              for body, coordinates in lin.body_coordinates.items()}
    decay = energy(lin.damping, vectors) / (2 * kinetic)
    if lin.structural is not None:
        stiff = squared_frequencies > 0
        decay[stiff] += energy(lin.structural, vectors[:, stiff]) / (2 * kinetic[stiff] * np.sqrt(squared_frequencies[stiff]))
    engine = full[lin.body_coordinates[ENGINE]]
    return [Mode(float(np.sqrt(max(omega_squared, 0.0)) / (2 * np.pi)), float(decay[index]),
                 float(shares[ENGINE][index]), _real_shape(engine[:, index]),
                 {body: float(share[index]) for body, share in shares.items() if body != ENGINE}, float(omega_squared))
            for index, omega_squared in enumerate(squared_frequencies)]


def _real_shape(part: np.ndarray) -> np.ndarray:
    """A (possibly complex) mode-shape part turned real, largest component 1:
    each component's magnitude relative to the largest, negative when it is
    more than 90 degrees out of phase with it (a whirl mode's pitch and yaw,
    90 degrees apart, both count)."""
    peak = part[np.argmax(np.abs(part))]
    if abs(peak) == 0:
        return np.zeros(len(part))
    ratio = part / peak
    return np.where(ratio.real < -1e-9 * np.abs(ratio), -1.0, 1.0) * np.abs(ratio)


def describe_engine_motion(shape: np.ndarray, length_scale: float = 1.0) -> str:
    """Name the dominant engine motions of a 6-component shape.

    Rotations are weighed by *length_scale* (m) against translations.
    """
    weights = np.abs(np.asarray(shape, dtype=float)) * np.r_[1, 1, 1, [length_scale] * 3]
    if weights.max() == 0:
        return "no engine motion"
    order = np.argsort(-weights)
    parts = [f"{ENGINE_MOTIONS[i]}" + ("" if k == 0 else f" ({weights[i] / weights[order[0]]:.2f})")
             for k, i in enumerate(order) if weights[i] >= 0.3 * weights[order[0]]]
    return "engine " + " with ".join(parts)


def _free_omega_squared() -> float:
    return (2 * np.pi * FREE_FREQUENCY_HZ) ** 2


def free_motions(modes: list[Mode]) -> list[Mode]:
    """The modes with ``|w| < 2 pi`` :data:`FREE_FREQUENCY_HZ`: free motions of a mechanism."""
    return [mode for mode in modes if abs(mode.omega_squared) < _free_omega_squared()]


def unstable_modes(modes: list[Mode]) -> list[Mode]:
    """The modes with negative stiffness beyond the free-motion limit
    (``w^2 <= -(2 pi`` :data:`FREE_FREQUENCY_HZ` ``)^2``): the static state is unstable."""
    return [mode for mode in modes if mode.omega_squared <= -_free_omega_squared()]


def mounted_modes(modes: list[Mode]) -> list[Mode]:
    """The engine's modes on its mount (most kinetic energy in the engine).

    Every one with ``w^2 > 0``, however slow: free motions and negative
    stiffness have stopped the run before (:mod:`workbook.solve.preload`,
    judged without the gyroscopic coupling), so a slow mode here is real,
    e.g. the backward whirl of a heavy fast rotor (0.016 Hz for
    1e5 kg m^2 at 248.5 Hz on the reference mount)."""
    return [mode for mode in modes if mode.mounted and mode.omega_squared > 0]
