"""Steady-state harmonic response of the linearised scene (the frequency domain).

About the preloaded equilibrium the scene obeys, in the independent
coordinates z of :func:`workbook.solve.modes.linearize` (Euler-parameter
constraints projected out),

    M z'' + D z' + K z = B f(t),        F_hinge = C_k z + C_d z',

with f the excitation force (3 components, N) at a point of the engine.
For ``f(t) = Re(f_hat exp(i w t))`` the steady state is
``z_hat = (K - w^2 M + i w D + i H)^-1 B f_hat`` and
``F_hat = (C_k + i C_h + i w C_d) z_hat``: exact for a linear scene (no
clearance), at any frequency, with no transient to wait for. The viscous
damping D is the case's, exactly as in the time domain.

H is the structural (hysteretic) damping of the loss factors, exact at every
frequency (:mod:`workbook.scene.structural_damping`). A hinge j with loss
factor eta_j acts with ``(1 + i eta_j)`` times its tangent stiffness: with
``J_j = d(p1 - p0)/dz`` (Exudyn's ``Displacement`` output of the connector,
by central differences) and ``C_k,j = K_j J_j`` its force rows, its
hysteretic force is ``i eta_j C_k,j z`` (the rows of C_h) and its
generalised force adds ``J_j^T eta_j C_k,j`` to H. A flexible link with loss
factor eta adds ``eta K_red`` on its modal coordinates (complex modulus of
its elastic stiffness).

B and C_k, C_d come from Exudyn itself: central differences of the
engine's point position (``GetObjectOutputBody``) and of the ``Force``
output of each force channel (hinges and, when built, the test-rig
transducers whose sum is then the pylon force) with respect to the full coordinates and
velocities, projected with the same basis as M, K and D. A rotating force
``C cos wt + S sin wt`` is the phasor ``f_hat = C - i S``: its two harmonic
parts 90 degrees apart are superposed in one complex solve.
"""
from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from workbook.answers.isolation import pylon_sum
from workbook.answers.results import ExcitationResult
from workbook.errors import RoundOffError
from workbook.model.case import ENGINE, SingleFrequencyExcitation
from workbook.scene.build import Scene, loss_factors
from workbook.solve.guards import checked_solve
from workbook.solve.modes import STIFFNESS_STEP, Linearization, linearize
from workbook.solve.preload import ROUNDOFF_MARGIN, spring_roundoff_force, stiffest_spring
from workbook.solve.truncation import residual_stiffness

__all__ = ["HarmonicModel", "harmonic_model", "excitation_phasor", "point_phasors", "FrequencyResponse",
           "RoundOff", "ROUNDOFF_SHARE", "ROUNDOFF_FLOOR"]

log = logging.getLogger(__name__)

#: Coordinate step of the central differences (m, rad, Euler parameters,
#: modal coordinates: all of order 1 or below), and velocity step (m/s, ...).
COORDINATE_STEP = 1e-7
VELOCITY_STEP = 1e-3
#: Largest share of the pylon force amplitude that the round-off of the
#: central differences may reach (:meth:`RoundOff.check`, a bound 10 to 100
#: times above the error measured on the reference mount).
ROUNDOFF_SHARE = 0.25
#: ... unless it stays below this share of the largest force-channel amplitude: a pylon force that cancels
#: (zero by symmetry, as a couple's on a mount that passes none) is then known to it.
ROUNDOFF_FLOOR = 1e-6


def point_phasors(excitation: SingleFrequencyExcitation) -> list[tuple[np.ndarray, np.ndarray]]:
    """The forces of *excitation* as ``(point, f_hat)`` with ``F(t) = Re(f_hat exp(i w t))``:
    one, or one per imbalance plane; point in m, ``f_hat`` in N, shape (3,) each.
    A force ``C cos wt + S sin wt`` is ``f_hat = C - i S``."""
    return [(np.asarray(point, dtype=float), np.asarray(c, dtype=complex) - 1j * np.asarray(s, dtype=float))
            for point, c, s in excitation.point_forces()]


def excitation_phasor(excitation: SingleFrequencyExcitation) -> np.ndarray:
    """Complex force amplitude ``f_hat`` with ``F(t) = Re(f_hat exp(i w t))``, N, shape (3,)
    (of an imbalance of several planes: their resultant)."""
    return sum((phasor for _, phasor in point_phasors(excitation)), np.zeros(3, dtype=complex))


@dataclass(frozen=True)
class RoundOff:
    """The round-off that the central differences of a linearisation carry.

    Attributes
    ----------
    case_name : str
        For the messages.
    stiffest_spring : float
        The stiffest spring of the scene (hinge, rig transducer or engine bearing), N/m.
    force : float
        Round-off of that spring's force at the scene's coordinates
        (:func:`~workbook.solve.preload.spring_roundoff_force` without its margin), N.
    """

    case_name: str
    stiffest_spring: float
    force: float

    @property
    def stiffness(self) -> float:
        """Bound of the round-off of an entry of K or of the force outputs, N/m: the force round-off
        over the outputs' coordinate step (twice it) and over K's."""
        return self.force * (1 / (2 * COORDINATE_STEP) + 1 / STIFFNESS_STEP)

    def check(self, frequency_hz: float, amplitude: float, pylon_force: np.ndarray, forces: np.ndarray) -> None:
        """Refuse an answer whose round-off bound, :attr:`stiffness` times the largest coordinate
        amplitude *amplitude* (m, rad, ...), reaches :data:`ROUNDOFF_SHARE` of the largest amplitude of
        *pylon_force* (N, complex, shape (3,)) and :data:`ROUNDOFF_FLOOR` of that of the force channels'
        *forces* (N, complex): a pylon force that cancels (a couple's) is known to that floor.

        Raises
        ------
        RoundOffError
        """
        noise, largest = self.stiffness * amplitude, float(np.abs(pylon_force).max())
        if not (noise < ROUNDOFF_SHARE * largest or noise < ROUNDOFF_FLOOR * float(np.abs(forces).max())):
            raise RoundOffError(
                f"case {self.case_name!r}: the frequency-domain answer at {frequency_hz:.6g} Hz cannot be "
                f"trusted: the stiffest spring has {self.stiffest_spring:.3g} N/m, so its force is known only to "
                f"{self.force:.2g} N at these coordinates, and the linearisation's central differences "
                f"(coordinate steps {COORDINATE_STEP:g} and {STIFFNESS_STEP:g}) turn that into up to {noise:.3g} N "
                f"of round-off on forces whose largest pylon amplitude is {largest:.3g} N. Lower the stiffest "
                f"stiffness: a hinge far stiffer than the link it holds acts as rigid anyway (on the reference "
                f"mount 1e12 N/m gives the same answer to 1e-3)")


@dataclass(frozen=True)
class FrequencyResponse:
    """Complex hinge-force amplitudes of one harmonic excitation.

    Attributes
    ----------
    frequency_hz : float
    hinge_forces : dict of str to ndarray, complex, shape (3,)
        ``F_hat`` of each force channel (hinge or transducer; force on its
        marker-0 body), N.
    pylon_force : ndarray, complex, shape (3,)
        Sum over the pylon channels, N.
    """

    frequency_hz: float
    hinge_forces: dict
    pylon_force: np.ndarray


@dataclass
class HarmonicModel:
    """The linearised scene with its excitation input and force-channel outputs.

    Attributes
    ----------
    linearization : Linearization
        M, K, D in independent coordinates (n of them) and the basis.
    hinge_names : list of str
        The force channels (:attr:`Scene.force_channels`): hinges, then
        test-rig transducers.
    pylon_hinges : list of str
        The channels summed into the pylon force (:attr:`Scene.pylon_channels`).
    stiffness_output, damping_output : ndarray, shape (3 h, n)
        Channel force per coordinate (N/m ...) and per velocity (N s/m ...),
        three rows per channel in the order of *hinge_names*.
    engine_point_jacobian : callable
        ``jacobian(point)``: d(position of a point of the engine)/dz,
        shape (3, n); *point* in global coordinates of the reference state, m.
    structural_output : ndarray, shape (3 h, n)
        C_h, the hysteretic channel force per coordinate, N/m ... (zero
        without loss factors or when the scene holds their viscous
        equivalent instead); H is ``linearization.structural``.
    residual_mass : ndarray, shape (n, n), or None
        R_z, the residual mass of the modes the flexible links omit, kg s^2
        (:mod:`workbook.solve.truncation`); None when not known.
    link_coordinates : dict of str to slice
        The elastic (modal) coordinates of each flexible link among the full
        coordinates: its modal coordinates are ``basis[rows] @ z``.
    roundoff : RoundOff or None
        The round-off its central differences carry (None: not known, not checked).
    """

    linearization: Linearization
    hinge_names: list
    pylon_hinges: list
    stiffness_output: np.ndarray
    damping_output: np.ndarray
    engine_point_jacobian: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    structural_output: np.ndarray = field(default=None, repr=False)  # type: ignore[arg-type]  # None: zeros
    residual_mass: np.ndarray | None = field(default=None, repr=False)
    link_coordinates: dict = field(default_factory=dict, repr=False)
    roundoff: RoundOff | None = None
    _inputs: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        if self.structural_output is None:
            self.structural_output = np.zeros_like(self.stiffness_output)

    @property
    def dof(self) -> int:
        """Independent coordinates of the linearisation."""
        return self.linearization.mass.shape[0]

    def input_matrix(self, point) -> np.ndarray:
        """Generalised force of a unit force in x, y, z at *point* of the engine, shape (n, 3)."""
        key = tuple(np.round(np.asarray(point, dtype=float), 12))
        if key not in self._inputs:
            self._inputs[key] = self.engine_point_jacobian(np.asarray(point, dtype=float)).T
        return self._inputs[key]

    def respond(self, frequency_hz: float, force: np.ndarray, point) -> FrequencyResponse:
        """Steady-state hinge forces for the force phasor *force* (N) at *point* (m) at *frequency_hz*."""
        return self.respond_generalised(frequency_hz, self.input_matrix(point) @ np.asarray(force, dtype=complex))

    def excitation_input(self, excitation: SingleFrequencyExcitation) -> np.ndarray:
        """Generalised force phasor of *excitation*: the sum over its point
        forces (one, or one per imbalance plane), shape (n,)."""
        return sum(self.input_matrix(point) @ phasor for point, phasor in point_phasors(excitation))

    def motion(self, frequency_hz: float, load: np.ndarray, added=None) -> np.ndarray:
        """Steady-state motion phasor ``z_hat`` (independent coordinates, shape (n,)) for the
        generalised force phasor *load* (shape (n,)) at *frequency_hz*; *added*: a dynamic
        stiffness (shape (n, n)) added to the scene's."""
        lin = self.linearization
        omega = 2 * np.pi * frequency_hz
        dynamic = lin.stiffness - omega ** 2 * lin.mass + 1j * omega * lin.damping
        if lin.structural is not None:
            dynamic = dynamic + 1j * lin.structural
        if added is not None:
            dynamic = dynamic + added
        return checked_solve(dynamic, load)

    def respond_generalised(self, frequency_hz: float, load: np.ndarray, added=None) -> FrequencyResponse:
        """Steady-state hinge forces for the generalised force phasor *load* (shape (n,)) at *frequency_hz*
        (*added*: see :meth:`motion`)."""
        return self._forces(frequency_hz, self.motion(frequency_hz, load, added))

    def link_phasors(self, motion: np.ndarray) -> dict:
        """Modal-coordinate phasors of each flexible link for the motion phasor *motion* (shape (n,))."""
        basis = self.linearization.basis
        return {name: basis[rows] @ motion for name, rows in self.link_coordinates.items()}

    def _forces(self, frequency_hz: float, motion: np.ndarray) -> FrequencyResponse:
        """The channel forces of *motion*.

        Raises
        ------
        RoundOffError
            :meth:`RoundOff.check`.
        """
        omega = 2 * np.pi * frequency_hz
        outputs = self.stiffness_output + 1j * (self.structural_output + omega * self.damping_output)
        forces = (outputs @ motion).reshape(-1, 3)
        hinges = dict(zip(self.hinge_names, forces, strict=True))
        pylon = pylon_sum(hinges, self.pylon_hinges)
        if self.roundoff is not None:
            self.roundoff.check(frequency_hz, float(np.abs(self.linearization.basis @ motion).max()), pylon, forces)
        return FrequencyResponse(frequency_hz, hinges, pylon)

    def result(self, excitation: SingleFrequencyExcitation, steady_tolerance: float) -> ExcitationResult:
        """The answers of *excitation* as an :class:`ExcitationResult` (no time histories)."""
        motion = self.motion(excitation.frequency, self.excitation_input(excitation))
        response = self._forces(excitation.frequency, motion)
        return ExcitationResult(
            name=excitation.name, frequency_hz=excitation.frequency,
            excitation_amplitude=excitation.force_amplitude, pylon_amplitude=np.abs(response.pylon_force),
            hinge_amplitudes={name: np.abs(f) for name, f in response.hinge_forces.items()},
            pylon_hinges=list(self.pylon_hinges), steady_change=0.0, steady_tolerance=steady_tolerance,
            warnings=[],
            hinge_phasors=dict(response.hinge_forces), link_phasors=self.link_phasors(motion))


def _central_difference(evaluate, set_value, base: np.ndarray, indices, step: float) -> np.ndarray:
    """Columns d(evaluate)/d(base[j]) for j in *indices* by central differences."""
    columns = []
    for j in indices:
        values = []
        for sign in (1.0, -1.0):
            shifted = base.copy()
            shifted[j] += sign * step
            set_value(shifted)
            values.append(evaluate())
        columns.append((values[0] - values[1]) / (2 * step))
    set_value(base)
    return np.array(columns).T


def harmonic_model(scene: Scene) -> HarmonicModel:
    """Linearise *scene* about its current (preloaded) state and differentiate
    its input and outputs.

    The scene must have been solved for its preload (``solve_preload``);
    the excitation is paused while linearising.

    Returns
    -------
    HarmonicModel
    """
    import exudyn as exu

    mbs = scene.mbs
    data = mbs.systemData
    current = exu.ConfigurationType.Current
    lin = linearize(scene)                # the excitation paused there
    q0 = np.array(data.GetODE2Coordinates(configuration=current))
    v0 = np.array(data.GetODE2Coordinates_t(configuration=current))
    channels = scene.force_channels
    names = list(channels)
    connectors = [channels[name].connector for name in names]

    def forces() -> np.ndarray:
        return np.concatenate([mbs.GetObjectOutput(c, exu.OutputVariableType.Force) for c in connectors])

    set_q = lambda q: data.SetODE2Coordinates(list(q), configuration=current)  # noqa: E731
    set_v = lambda v: data.SetODE2Coordinates_t(list(v), configuration=current)  # noqa: E731
    everything = range(len(q0))
    stiffness = _central_difference(forces, set_q, q0, everything, COORDINATE_STEP) @ lin.basis
    damping = _central_difference(forces, set_v, v0, everything, VELOCITY_STEP) @ lin.basis
    structural, structural_output = _structural_damping(scene, lin, stiffness, names, set_q, q0)
    if structural is not None:
        lin = dataclasses.replace(lin, structural=structural)

    engine_coordinates = lin.body_coordinates[ENGINE]
    engine_body = scene.engine.body
    centre = np.asarray(scene.case.engine.center_of_mass)

    def point_jacobian(point: np.ndarray) -> np.ndarray:
        local = list(point - centre)

        def position() -> np.ndarray:
            return np.array(mbs.GetObjectOutputBody(engine_body, exu.OutputVariableType.Position,
                                                    localPosition=local, configuration=current))

        partial = _central_difference(position, set_q, q0, engine_coordinates, COORDINATE_STEP)
        return partial @ lin.basis[engine_coordinates]

    links = {name: slice(mbs.GetNodeODE2Index(items.nodes[1]),
                         mbs.GetNodeODE2Index(items.nodes[1]) + scene.reduced[name].n_modes)
             for name, items in scene.links.items() if items.flexible}
    log.info("harmonic model of %r: %d independent coordinates, %d force channels", scene.case.name,
             lin.mass.shape[0], len(names))
    roundoff = RoundOff(scene.case.name, stiffest_spring(scene), spring_roundoff_force(scene) / ROUNDOFF_MARGIN)
    return HarmonicModel(lin, names, list(scene.pylon_channels), stiffness, damping, point_jacobian,
                         structural_output, residual_stiffness(scene, lin.basis), links, roundoff)


def _structural_damping(scene: Scene, lin: Linearization, stiffness_output: np.ndarray, names: list,
                        set_q, q0: np.ndarray) -> tuple[np.ndarray | None, np.ndarray]:
    """H and C_h of the loss factors the scene does not hold as viscous
    damping (module docstring); H is None when there are none."""
    import exudyn as exu

    output = np.zeros_like(stiffness_output)
    hinge_loss, link_loss = loss_factors(scene.case)
    if scene.loss_factor_hz is not None or not (hinge_loss or link_loss):
        return None, output
    structural = np.zeros_like(lin.stiffness)
    mbs = scene.mbs
    if hinge_loss:
        lossy = list(hinge_loss)
        by_name = {hinge.name: hinge for hinge in scene.case.hinges}
        connectors = [scene.hinges[name].connector for name in lossy]

        def displacements() -> np.ndarray:
            return np.concatenate([mbs.GetObjectOutput(c, exu.OutputVariableType.Displacement) for c in connectors])

        jacobian = _central_difference(displacements, set_q, q0, range(len(q0)), COORDINATE_STEP) @ lin.basis
        for k, name in enumerate(lossy):
            rows = slice(3 * names.index(name), 3 * names.index(name) + 3)
            output[rows] = scene.hinges[name].hinge_law.matrices(scene.case, by_name[name])[2] @ stiffness_output[rows]
            structural += jacobian[3 * k:3 * k + 3].T @ output[rows]
    for name, eta in link_loss.items():
        modal_node = scene.links[name].nodes[1]
        start = mbs.GetNodeODE2Index(modal_node)
        reduced_stiffness = np.asarray(scene.reduced[name].ffrf["stiffnessMatrixReduced"], dtype=float)
        projection = lin.basis[start:start + reduced_stiffness.shape[0]]
        structural += eta * projection.T @ reduced_stiffness @ projection
    return structural, output
