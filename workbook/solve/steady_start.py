"""Where a time run starts: at rest, or in the steady state of its own linearised scene.

*At rest* (``start="rest"``): the preloaded equilibrium, the excitation
rising smoothly over ``ramp_periods`` periods; the free vibration the start
leaves in the mounted modes must then decay before the answer is measured,
and the least damped mounted mode sets how long that takes
(:func:`workbook.solve.time_domain.plan_run`). Lightly damped modes make
that long: the viscous equivalent ``eta k / w`` of a hinge loss factor at
the rotor frequency damps the engine's rigid-body modes on its mount far
below their resonance only weakly.

*In the steady state* (``start="steady"``): the scene the time run
integrates (with its viscous equivalents of the loss factors at the run's
frequency, not the complex stiffness of the frequency domain) is linearised
about the preload, and its harmonic solution at each excitation frequency,
``z_j = (K - w_j^2 M + i w_j D)^-1 B f_j`` (:meth:`HarmonicModel.motion`),
mapped to the full coordinates ``q_j = basis z_j``, gives the initial state

    q(0) = q_preload + sum_j Re(q_j),   q'(0) = sum_j Re(i w_j q_j),
    q''(0) = sum_j Re(-w_j^2 q_j),

with the excitation acting in full from the first step (no ramp). For a
linear scene this is the periodic solution itself: what is left to decay is
only the difference between the integrator's discrete steady state and the
exact one (its amplitude error, :mod:`workbook.solve.step_accuracy`) and the
linearisation's round-off. The answer still comes from the integration,
measured in two windows checked against each other; a start that was wrong
shows as a change between them, and the run then integrates window after
window until two agree, at most as long as a start from rest would have
settled, before it reports "not steady" like any run.

``AnalysisSettings.start = "auto"`` (the default) starts in the steady state
when the scene is linear (no hinge clearance law is built) and at rest when
a clearance makes it nonlinear: there the linearised steady state is not the
scene's periodic solution. Asked for explicitly, ``"steady"`` starts a
nonlinear scene from its linearised steady state too (the integration then
settles from there, within the same limit).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Final, Literal

import numpy as np

from workbook.model.case import Case, Simultaneous, SingleFrequencyExcitation
from workbook.scene.build import Scene
from workbook.scene.hinge_laws import linear_note, nonlinear_reason
from workbook.solve.harmonic import HarmonicModel

__all__ = ["REST", "STEADY", "StartChoice", "choose_start", "SteadyStart", "steady_start"]

#: The starts a time-domain run takes.
Start = Literal["rest", "steady"]
REST: Final = "rest"
STEADY: Final = "steady"


@dataclass(frozen=True)
class StartChoice:
    """How a time run starts and why.

    Attributes
    ----------
    start : {"rest", "steady"}
    reason : str
    """

    start: Start
    reason: str


def choose_start(case: Case) -> StartChoice:
    """The start of a time run of *case* from ``case.analysis.start`` (module text)."""
    asked = case.analysis.start
    nonlinear = nonlinear_reason(case)
    if asked == REST:
        return StartChoice(REST, "the case asks for it (start 'rest')")
    if asked == STEADY:
        return StartChoice(STEADY, "the case asks for it (start 'steady')" + (
            f"; {nonlinear}, so the linearised steady state is only where the integration starts settling"
            if nonlinear else ""))
    if nonlinear:
        return StartChoice(REST, f"auto: {nonlinear}, its linearised steady state is not its periodic solution")
    return StartChoice(STEADY, f"auto: the scene is linear ({linear_note()}), so the harmonic solution of its "
                       "linearisation is its periodic steady state")


@dataclass(frozen=True)
class SteadyStart:
    """The steady state of a linearised scene at t = 0 as offsets from the preload.

    Attributes
    ----------
    omegas : ndarray, shape (m,)
        Circular frequency of each excitation part, rad/s.
    phasors : ndarray, complex, shape (m, N)
        ``q_j``: the motion phasor of each part in the full ODE2 coordinates
        (m, rad, Euler parameters, modal coordinates).
    """

    omegas: np.ndarray
    phasors: np.ndarray

    def offsets(self, derivative: int) -> np.ndarray:
        """``sum_j Re((i w_j)^derivative q_j)``: the coordinates' (0), velocities'
        (1) or accelerations' (2) offset from the preload at t = 0, shape (N,)."""
        return np.real(((1j * self.omegas) ** derivative) @ self.phasors)

    def apply(self, scene: Scene) -> None:
        """Make preload + the steady state the initial state of *scene*'s time integration.

        The scene's initial coordinates must be the preloaded ones (after
        ``solve_preload``) and its velocities zero.
        """
        import exudyn as exu

        data = scene.mbs.systemData
        initial = exu.ConfigurationType.Initial
        preloaded = np.asarray(data.GetODE2Coordinates(configuration=initial))
        data.SetODE2Coordinates(coordinates=list(preloaded + self.offsets(0)), configuration=initial)
        data.SetODE2Coordinates_t(coordinates=list(self.offsets(1)), configuration=initial)
        data.SetODE2Coordinates_tt(coordinates=list(self.offsets(2)), configuration=initial)


def steady_start(model: HarmonicModel, excitation: SingleFrequencyExcitation | Simultaneous) -> SteadyStart:
    """The steady state of *model* (the linearisation of the scene the time run
    integrates) under *excitation*, every part of a
    :class:`~workbook.model.case.Simultaneous` one at its own frequency.

    Parameters
    ----------
    model : HarmonicModel
        Of the time run's own scene (viscous equivalents of the loss factors
        built in, no structural damping H).
    excitation : RotatingForce, HarmonicForce, Imbalance or Simultaneous

    Returns
    -------
    SteadyStart
    """
    parts = excitation.parts if isinstance(excitation, Simultaneous) else (excitation,)
    basis = model.linearization.basis
    phasors = np.array([basis @ model.motion(part.frequency, model.excitation_input(part)) for part in parts])
    return SteadyStart(np.array([2 * np.pi * part.frequency for part in parts]), phasors)
