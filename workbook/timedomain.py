"""Time-domain run of one excitation: plan, integrate, extract amplitudes.

The plan (all whole excitation periods):

- step: one period / ``steps_per_period`` (the highest excitation frequency of
  the run sets it; 40 steps per period or more);
- ramp: the excitation rises smoothly over ``ramp_periods`` periods;
- settle: ``settle_time_constants`` decay time constants ``1 / (zeta w)`` of
  the least damped mounted mode (or a fixed ``settle_time``);
- two measured windows of ``measured_periods`` periods each.

Integration: Exudyn's implicit generalized-alpha with modified Newton, from
the preloaded state, hinge forces stored in memory every step. Extraction:
the amplitude at the excitation frequency by single-bin DFT of the
mean-removed last window, per hinge and for the pylon sum; the run is steady
when the pylon amplitudes of the two windows agree within
``steady_tolerance``, else the result carries a warning.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Callable, Union

import numpy as np

from .amplitude import harmonic_amplitude, steady_amplitude
from .case import AnalysisSettings
from .excitation import ExcitationSignal
from .modes import Mode
from .results import ExcitationResult
from .scene import Scene

__all__ = ["TimePlan", "plan_run", "integrate", "extract", "TimeHistories"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class TimePlan:
    """Step size and durations of one run.

    Attributes
    ----------
    frequency_hz : float
        Excitation frequency, Hz.
    step : float
        Time step, s.
    steps_per_period : int
    ramp_periods, settle_periods, measured_periods : int
        Whole periods of the smooth start, of the settling after it, and of
        each of the two measured windows.
    settle_reason : str
        How the settle time was chosen.
    """

    frequency_hz: float
    step: float
    steps_per_period: int
    ramp_periods: int
    settle_periods: int
    measured_periods: int
    settle_reason: str

    @property
    def periods(self) -> int:
        """Total periods simulated."""
        return self.ramp_periods + self.settle_periods + 2 * self.measured_periods

    @property
    def steps(self) -> int:
        return self.periods * self.steps_per_period

    @property
    def end_time(self) -> float:
        """s."""
        return self.steps * self.step


def plan_run(analysis: AnalysisSettings, signal: ExcitationSignal, mounted: list[Mode]) -> TimePlan:
    """Choose the step and the durations of a run.

    Parameters
    ----------
    analysis : AnalysisSettings
    signal : ExcitationSignal
    mounted : list of Mode
        The mounted modes of the preloaded scene; the least damped one sets
        the settle time unless the settings fix it.
    """
    frequency = signal.frequency_hz
    period = 1.0 / frequency
    if analysis.settle_time is not None:
        settle, reason = analysis.settle_time, f"fixed settle time {analysis.settle_time:g} s"
    else:
        damped = [m for m in mounted if m.decay_rate > 0]
        if not damped:
            lowest = min((m.frequency_hz for m in mounted), default=frequency)
            settle = 20.0 / lowest
            reason = "undamped mounted modes: 20 periods of the lowest one (the transient will not decay)"
        else:
            slowest = min(damped, key=lambda m: m.decay_rate)
            settle = analysis.settle_time_constants / slowest.decay_rate
            reason = (f"{analysis.settle_time_constants:g} x 1/(zeta w) = {settle:.3g} s of the least damped "
                      f"mounted mode ({slowest.frequency_hz:.3g} Hz, zeta {slowest.damping_ratio:.3g})")
    return TimePlan(frequency, period / analysis.steps_per_period, analysis.steps_per_period,
                    math.ceil(analysis.ramp_periods - 1e-9), math.ceil(settle * frequency - 1e-9),
                    analysis.measured_periods, reason)


@dataclass
class TimeHistories:
    """Stored histories of one run.

    Attributes
    ----------
    time : ndarray, shape (n,)
        s.
    hinge_forces : dict of str to ndarray, shape (n, 3)
        Force of each hinge on the pylon (pylon-side hinges) or on its first body, N.
    """

    time: np.ndarray
    hinge_forces: dict


def integrate(scene: Scene, plan: TimePlan, progress: Union[Callable[[float], None], None] = None
              ) -> TimeHistories:
    """Run generalized-alpha over the plan from the scene's initial (preloaded) state.

    Parameters
    ----------
    scene : Scene
        With an excitation; solved for its preload.
    plan : TimePlan
    progress : callable, optional
        Called with the simulated time now and then (about 200 times).

    Raises
    ------
    RuntimeError
        If the solver fails.
    """
    import exudyn as exu

    analysis = scene.case.analysis
    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = plan.step
    integration = settings.timeIntegration
    integration.numberOfSteps = plan.steps
    integration.endTime = plan.end_time
    integration.verboseMode = 0
    integration.generalizedAlpha.spectralRadius = analysis.spectral_radius
    integration.newton.useModifiedNewton = True
    integration.newton.absoluteTolerance = analysis.newton_tolerance * scene.load_scale
    if progress is not None:
        interval = plan.end_time / 200
        reported = [-math.inf]

        def report(mbs, t):
            if t - reported[0] >= interval:
                reported[0] = t
                progress(t)
            return True

        scene.mbs.SetPreStepUserFunction(report)
    try:
        if not scene.mbs.SolveDynamic(settings, solverType=exu.DynamicSolverType.GeneralizedAlpha):
            raise RuntimeError(f"case {scene.case.name!r}: the time integration failed")
    finally:
        if progress is not None:
            scene.mbs.SetPreStepUserFunction(0)
            progress(plan.end_time)
    forces = {name: scene.mbs.GetSensorStoredData(items.sensor) for name, items in scene.hinges.items()}
    time = next(iter(forces.values()))[:, 0] if forces else np.zeros(0)
    return TimeHistories(time, {name: data[:, 1:4] for name, data in forces.items()})


def extract(scene: Scene, plan: TimePlan, histories: TimeHistories) -> ExcitationResult:
    """Amplitudes at the excitation frequency, the steady-state check and warnings."""
    analysis = scene.case.analysis
    signal = scene.excitation.signal
    time = histories.time
    pylon = sum((histories.hinge_forces[name] for name in scene.pylon_hinges), np.zeros((len(time), 3)))
    steady = steady_amplitude(time, pylon, plan.frequency_hz, plan.measured_periods, analysis.steady_tolerance)
    window = steady.window
    hinge_amplitudes = {name: np.abs(harmonic_amplitude(time[window], forces[window], plan.frequency_hz))
                        for name, forces in histories.hinge_forces.items()}
    warnings = []
    if not steady.steady:
        warnings.append(
            f"not steady: the pylon-force amplitudes of the last two {plan.measured_periods}-period windows "
            f"differ by {100 * steady.relative_change:.2f} % (> {100 * analysis.steady_tolerance:.2g} %); "
            f"lengthen the settle time or check the damping")
        log.warning("%s, %s: %s", scene.case.name, scene.excitation.name, warnings[-1])
    return ExcitationResult(
        name=scene.excitation.name, frequency_hz=plan.frequency_hz, excitation_amplitude=signal.amplitude,
        pylon_amplitude=steady.amplitude, hinge_amplitudes=hinge_amplitudes, pylon_hinges=list(scene.pylon_hinges),
        steady_change=steady.relative_change, steady_tolerance=analysis.steady_tolerance, warnings=warnings,
        time=time, hinge_histories=histories.hinge_forces, pylon_history=pylon,
        excitation_history=signal.force(time), window=window)
