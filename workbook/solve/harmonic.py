"""Steady-state harmonic response of the linearised scene (the frequency domain).

About the preloaded equilibrium the scene obeys, in the independent
coordinates z of :func:`workbook.solve.modes.linearize` (Euler-parameter
constraints projected out),

    M z'' + D z' + K z = B f(t),        F_hinge = C_k z + C_d z',

with f the excitation force (3 components, N) at a point of the engine.
For ``f(t) = Re(f_hat exp(i w t))`` the steady state is
``z_hat = (K - w^2 M + i w D)^-1 B f_hat`` and
``F_hat = (C_k + i w C_d) z_hat``: exact for a linear scene (no clearance),
at any frequency, with no transient to wait for. The hinge damping is the
case's viscous damping, exactly as in the time domain.

B and C_k, C_d come from Exudyn itself: central differences of the
engine's point position (``GetObjectOutputBody``) and of the ``Force``
output of each force channel (hinges and, when built, the test-rig
transducers whose sum is then the pylon force) with respect to the full coordinates and
velocities, projected with the same basis as M, K and D. A rotating force
``C cos wt + S sin wt`` is the phasor ``f_hat = C - i S``: its two harmonic
parts 90 degrees apart are superposed in one complex solve.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.linalg as sla

from workbook.answers.isolation import pylon_sum
from workbook.answers.results import ExcitationResult
from workbook.model.case import ENGINE, SingleFrequencyExcitation
from workbook.scene.build import Scene
from workbook.solve.modes import Linearization, linearize

__all__ = ["HarmonicModel", "harmonic_model", "excitation_phasor", "FrequencyResponse"]

log = logging.getLogger(__name__)

#: Coordinate step of the central differences (m, rad, Euler parameters,
#: modal coordinates: all of order 1 or below), and velocity step (m/s, ...).
COORDINATE_STEP = 1e-7
VELOCITY_STEP = 1e-3


def excitation_phasor(excitation: SingleFrequencyExcitation) -> np.ndarray:
    """Complex force amplitude ``f_hat`` with ``F(t) = Re(f_hat exp(i w t))``, N, shape (3,)
    (of an imbalance of several planes: their resultant)."""
    return sum(np.asarray(c, dtype=complex) - 1j * np.asarray(s, dtype=float) for _, c, s in excitation.point_forces())


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
    """

    linearization: Linearization
    hinge_names: list
    pylon_hinges: list
    stiffness_output: np.ndarray
    damping_output: np.ndarray
    engine_point_jacobian: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    _inputs: dict = field(default_factory=dict, repr=False)

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
        return sum(self.input_matrix(point) @ (np.asarray(c, dtype=complex) - 1j * np.asarray(s, dtype=float))
                   for point, c, s in excitation.point_forces())

    def respond_generalised(self, frequency_hz: float, load: np.ndarray) -> FrequencyResponse:
        """Steady-state hinge forces for the generalised force phasor *load* (shape (n,)) at *frequency_hz*."""
        lin = self.linearization
        omega = 2 * np.pi * frequency_hz
        dynamic = lin.stiffness - omega ** 2 * lin.mass + 1j * omega * lin.damping
        motion = sla.solve(dynamic, load, check_finite=False)
        forces = ((self.stiffness_output + 1j * omega * self.damping_output) @ motion).reshape(-1, 3)
        hinges = dict(zip(self.hinge_names, forces))
        pylon = pylon_sum(hinges, self.pylon_hinges)
        return FrequencyResponse(frequency_hz, hinges, pylon)

    def result(self, excitation: SingleFrequencyExcitation, steady_tolerance: float) -> ExcitationResult:
        """The answers of *excitation* as an :class:`ExcitationResult` (no time histories)."""
        response = self.respond_generalised(excitation.frequency, self.excitation_input(excitation))
        empty = np.zeros((0, 3))
        return ExcitationResult(
            name=excitation.name, frequency_hz=excitation.frequency,
            excitation_amplitude=excitation.force_amplitude, pylon_amplitude=np.abs(response.pylon_force),
            hinge_amplitudes={name: np.abs(f) for name, f in response.hinge_forces.items()},
            pylon_hinges=list(self.pylon_hinges), steady_change=0.0, steady_tolerance=steady_tolerance,
            warnings=[], time=np.zeros(0), hinge_histories={name: empty for name in self.hinge_names},
            pylon_history=empty, excitation_history=empty, window=slice(0, 0))


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
    with scene.excitation_paused():
        lin = linearize(scene)
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

    log.info("harmonic model of %r: %d independent coordinates, %d force channels", scene.case.name,
             lin.mass.shape[0], len(names))
    return HarmonicModel(lin, names, list(scene.pylon_channels), stiffness, damping, point_jacobian)
