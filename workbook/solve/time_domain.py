"""Time-domain run of one excitation: plan, integrate, extract amplitudes.

The plan (all whole excitation periods) of a run from rest:

- step: one period / ``steps_per_period`` (the highest excitation frequency of
  the run sets it; 40 steps per period or more). Its accuracy is known, not
  hoped for: :mod:`workbook.solve.step_accuracy` gives the integrator's
  steady amplitude error on every mode of the preloaded scene; the largest
  is on the model card, and above :data:`~workbook.solve.step_accuracy.ACCURACY_LIMIT` the result warns
  with the steps per period that would meet it;
- ramp: the excitation rises smoothly over ``ramp_periods`` periods;
- settle: ``settle_time_constants`` decay time constants ``1 / (zeta w)`` of
  the least damped mounted mode (or a fixed ``settle_time``); undamped modes
  (zeta below :data:`workbook.solve.guards.UNDAMPED_RATIO`) cannot settle and are
  reported instead;
- two measured windows of ``measured_periods`` periods each.

A run that starts in the steady state of its linearised scene
(:mod:`workbook.solve.steady_start`) has no ramp and no settle time: it
integrates the two measured windows only. When they do not agree it goes on
window by window, comparing the last two, until they do or until it has
integrated as long as the ramp and settle time of a start from rest
(``extension_periods``); then it reports "not steady" like any run.

Integration: Exudyn's implicit generalized-alpha with modified Newton, from
the preloaded state, in segments: the ramp and settle time in at most
:data:`TRANSIENT_SEGMENTS` segments with the hinge-force sensors not
storing, then the two measured windows as one segment with the sensors
storing every step. Memory therefore grows with the measured windows only,
not with the length of the run. Between segments the run is checked
(:mod:`workbook.solve.guards`): a segment whose Newton iteration fails is run
again with the step halved (at most ``step_halvings`` times); a run-away
engine or a NaN stops the run; so does an exhausted ``time_budget``.
Restarting generalized-alpha at a segment boundary recomputes the
accelerations from the equations of motion; on the reference mount (rigid
links, LP rotor) this moved T_x and T_z by less than 1e-6 and the nearly
cancelled T_y (0.0012) by 2.4e-4 relative against one unbroken run.

Extraction: the amplitude at the excitation frequency by single-bin DFT of
the mean-removed last window, per hinge and for the pylon sum; the run is
steady when the pylon amplitudes of the two windows agree within
``steady_tolerance``, else the result carries a warning. A run from a steady
start is held to the stricter check of the complex amplitudes (magnitude and
phase against absolute time): a slowly decaying vibration at a mounted
mode's frequency can leak into the magnitudes of two windows alike (measured:
T 1.8 % off with magnitudes 0.3 % apart) but not with the same phase.
"""
from __future__ import annotations

import logging
import math
import time as wall_clock
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from workbook.answers.amplitude import harmonic_amplitude, steady_amplitude
from workbook.answers.isolation import pylon_sum
from workbook.answers.results import ExcitationResult
from workbook.errors import DivergenceError, NewtonFailure, RunTooLong, TimeBudgetExceeded
from workbook.model.case import AnalysisSettings
from workbook.scene.build import Scene
from workbook.scene.excitation import ExcitationSignal
from workbook.solve.guards import MAX_STEPS, UNDAMPED_RATIO, check_undamped_resonance, newton_cause, run_label, solver_output
from workbook.solve.modes import Mode, mounted_modes
from workbook.solve.steady_start import STEADY, Start
from workbook.solve.step_accuracy import ACCURACY_LIMIT, ACCURACY_TARGET, amplitude_error, steps_for_accuracy

__all__ = ["TimePlan", "plan_run", "integrate", "extract", "run_warnings", "TimeHistories", "TRANSIENT_SEGMENTS"]

log = logging.getLogger(__name__)

#: The ramp and settle time are integrated in at most this many segments
#: (checks, progress and the time budget act between segments).
TRANSIENT_SEGMENTS = 50


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
    undamped_hz : tuple of float
        Mounted modes without damping, Hz: their free vibration started by
        the ramp never decays.
    amplitude_error : float
        The integrator's estimated steady amplitude error, relative
        (:func:`workbook.solve.step_accuracy.amplitude_error`).
    error_source : str
        The mode it is largest on.
    steps_needed : int
        Steps per period that keep it within
        :data:`~workbook.solve.step_accuracy.ACCURACY_TARGET`.
    start : {"rest", "steady"}
        Where the run starts (:mod:`workbook.solve.steady_start`).
    extension_periods : int
        Periods the run may integrate beyond its plan, window by window,
        while its last two windows disagree (a steady start only: the ramp
        and settle periods a start from rest would have taken).
    """

    frequency_hz: float
    step: float
    steps_per_period: int
    ramp_periods: int
    settle_periods: int
    measured_periods: int
    settle_reason: str
    undamped_hz: tuple = ()
    amplitude_error: float = 0.0
    error_source: str = ""
    steps_needed: int = 0
    start: Start = "rest"
    extension_periods: int = 0

    @property
    def accuracy_target(self) -> float:
        """The relative amplitude error :attr:`steps_needed` keeps to."""
        return ACCURACY_TARGET

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

    def segments(self) -> list[tuple[int, int, bool]]:
        """The integration segments as ``(first step, last step, store)``.

        The ramp and settle time in at most :data:`TRANSIENT_SEGMENTS`
        segments of whole periods, not stored; then the two measured windows
        as one stored segment.
        """
        transient = self.ramp_periods + self.settle_periods
        per_segment = max(1, math.ceil(transient / TRANSIENT_SEGMENTS))
        bounds = list(range(0, transient, per_segment)) + [transient]
        segments = [(a * self.steps_per_period, b * self.steps_per_period, False)
                    for a, b in zip(bounds, bounds[1:], strict=False)]
        return segments + [(transient * self.steps_per_period, self.steps, True)]


def plan_run(analysis: AnalysisSettings, signal: ExcitationSignal, modes: list[Mode], where: str = "run",
             start: Start = "rest") -> TimePlan:
    """Choose the step and the durations of a run.

    Parameters
    ----------
    analysis : AnalysisSettings
    signal : ExcitationSignal
    modes : list of Mode
        The modes of the preloaded scene: the least damped mounted one sets
        the settle time unless the settings fix it; every one counts for the
        resonance check and the integrator's accuracy.
    where : str
        Case and run, for error messages.
    start : {"rest", "steady"}
        From rest: ramp, settle time and the two measured windows. In the
        steady state: the two measured windows only, with the ramp and
        settle periods of a start from rest as the most it may go on while
        not steady.

    Raises
    ------
    ResonanceError
        The excitation lies on an undamped mode, closer than the
        measured window can tell apart (1 / ``measured_periods``).
    RunTooLong
        The plan has more than :data:`workbook.solve.guards.MAX_STEPS` steps.
    """
    frequency = signal.frequency_hz
    period = 1.0 / frequency
    mounted = mounted_modes(modes)
    check_undamped_resonance(
        where, frequency, modes, 1.0 / analysis.measured_periods,
        f"the free vibration started by the ramp never decays, and a {analysis.measured_periods}-period window "
        f"cannot tell it from the response (on the mode itself the response grows without bound)")
    damped = [m for m in mounted if m.damping_ratio >= UNDAMPED_RATIO]
    undamped = tuple(m.frequency_hz for m in mounted if m.damping_ratio < UNDAMPED_RATIO)
    if analysis.settle_time is not None:
        settle, reason = analysis.settle_time, f"fixed settle time {analysis.settle_time:g} s"
    elif not damped:
        lowest = min((m.frequency_hz for m in mounted), default=frequency)
        settle = 20.0 / lowest
        reason = "undamped mounted modes: 20 periods of the lowest one (the transient will not decay)"
    else:
        slowest = min(damped, key=lambda m: m.decay_rate)
        settle = analysis.settle_time_constants / slowest.decay_rate
        reason = (f"{analysis.settle_time_constants:g} x 1/(zeta w) = {settle:.3g} s of the least damped "
                  f"mounted mode ({slowest.frequency_hz:.3g} Hz, zeta {slowest.damping_ratio:.3g})")
    error, worst = amplitude_error(modes, frequency, analysis.steps_per_period, analysis.spectral_radius)
    source = "" if worst is None else (f"the mode at {worst.frequency_hz:.4g} Hz, zeta {worst.damping_ratio:.3g} "
                                       f"({worst.description})")
    needed = steps_for_accuracy(modes, frequency, analysis.steps_per_period, analysis.spectral_radius,
                                ACCURACY_TARGET)
    ramp_periods, settle_periods = math.ceil(analysis.ramp_periods - 1e-9), math.ceil(settle * frequency - 1e-9)
    extension = 0
    if start == STEADY:
        longest = MAX_STEPS // analysis.steps_per_period - 2 * analysis.measured_periods
        extension = max(0, min(ramp_periods + settle_periods, longest))
        reason = (f"none: the run starts in the steady state; while its last two windows disagree it goes on "
                  f"window by window for at most {extension} periods (the ramp and settle time of a start from "
                  f"rest: {reason})")
        ramp_periods = settle_periods = 0
    plan = TimePlan(frequency, period / analysis.steps_per_period, analysis.steps_per_period,
                    ramp_periods, settle_periods, analysis.measured_periods, reason, undamped, error, source,
                    needed, start, extension)
    if plan.steps > MAX_STEPS:
        raise RunTooLong(f"{where}: the plan needs {plan.steps:.3g} time steps ({plan.end_time:.3g} s simulated; "
                         f"settle time: {reason}), more than {MAX_STEPS:.0e}. Add damping, set a fixed settle time "
                         f"or answer the case in the frequency domain.")
    return plan


@dataclass
class TimeHistories:
    """Stored histories of one run.

    Attributes
    ----------
    time : ndarray, shape (n,)
        s; the measured windows only.
    hinge_forces : dict of str to ndarray, shape (n, 3)
        Force of each force channel (``Scene.force_channels``): each hinge on the
        pylon (pylon-side hinges) or on its first body, each rig transducer on the ground, N.
    retries : list of str
        Segments run again with a smaller step after a Newton failure: when,
        which step, why.
    extended_periods : int
        Periods integrated beyond the plan because the windows disagreed.
    """

    time: np.ndarray
    hinge_forces: dict
    retries: list = field(default_factory=list)
    extended_periods: int = 0


def _simulation_settings(scene: Scene, plan: TimePlan):
    import exudyn as exu

    analysis = scene.case.analysis
    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    # one sample per step: a write period of exactly one step skips a sample
    # when the accumulated time falls a round-off short of the next write
    # (measured: once in 320000 steps at 248.5 Hz); half a step never does
    settings.solution.sensors.writePeriod = 0.5 * plan.step
    integration = settings.timeIntegration
    integration.verboseMode = 0
    # a failed segment is re-run by integrate() with a halved step; Exudyn's own
    # step adaptation would sample the measured window unevenly
    integration.adaptiveStep = False
    integration.generalizedAlpha.spectralRadius = analysis.spectral_radius
    integration.newton.useModifiedNewton = True
    integration.newton.absoluteTolerance = analysis.newton_tolerance * scene.load_scale
    return settings


def _advance_initial_state(mbs) -> None:
    """Make the state reached the initial state of the next segment."""
    import exudyn as exu

    data = mbs.systemData
    data.SetSystemState(systemStateList=data.GetSystemState(), configuration=exu.ConfigurationType.Initial)
    data.SetODE2Coordinates_tt(coordinates=data.GetODE2Coordinates_tt(), configuration=exu.ConfigurationType.Initial)


def _solve_segment(scene: Scene, settings, plan: TimePlan, first: int, last: int, where: str,
                   retries: list) -> None:
    """Integrate steps *first* to *last*, halving the step after a Newton failure."""
    import exudyn as exu

    integration = settings.timeIntegration
    start, end = first * plan.step, last * plan.step
    halvings = scene.case.analysis.step_halvings
    cause = ""
    for halving in range(halvings + 1):
        integration.startTime, integration.endTime = start, end
        integration.numberOfSteps = (last - first) * 2 ** halving
        solver = exu.MainSolverImplicitSecondOrder()
        with solver_output():
            solved = solver.SolveSystem(scene.mbs, settings)  # type: ignore[call-arg,misc]
        if solved:
            _advance_initial_state(scene.mbs)
            if halving:
                retries.append(f"{start:.6g} to {end:.6g} s: step halved {halving} time(s) to "
                               f"{plan.step / 2 ** halving:.3g} s after: {cause}")
                log.info("%s: %s", where, retries[-1])
            return
        cause = newton_cause(solver.conv)
    raise NewtonFailure(where, start, end, plan.step / 2 ** halvings, halvings, cause)


def _check_motion(scene: Scene, preloaded: np.ndarray, simulated: float, where: str) -> None:
    """Stop on NaN or infinite coordinates, or on a run-away engine."""
    import exudyn as exu

    coordinates = np.asarray(scene.mbs.systemData.GetODE2Coordinates())
    if not np.all(np.isfinite(coordinates)):
        raise DivergenceError(f"{where}: at t = {simulated:.6g} s the solution contains NaN or infinite values: "
                              f"the integration diverged")
    position = np.asarray(scene.mbs.GetNodeOutput(scene.engine.node, exu.OutputVariableType.Position))
    moved = float(np.linalg.norm(position - preloaded))
    limit = scene.case.analysis.divergence_displacement
    if moved > limit:
        raise DivergenceError(
            f"{where}: at t = {simulated:.6g} s the engine's centre of gravity is {1e3 * moved:.4g} mm from its "
            f"preloaded position (limit {1e3 * limit:g} mm, divergence_displacement): the motion diverges. "
            f"Check the hinge stiffnesses and damping, or raise the limit if such motion is meant.")


def integrate(scene: Scene, plan: TimePlan, progress: Callable[[float], None] | None = None,
              steady: Callable[[TimeHistories], bool] | None = None) -> TimeHistories:
    """Run generalized-alpha over the plan from the scene's initial state.

    The scene's initial state (the preloaded one, or for a steady start the
    steady state set by :meth:`workbook.solve.steady_start.SteadyStart.apply`)
    is advanced segment by segment and ends as the state at the end of the
    run.

    Parameters
    ----------
    scene : Scene
        With an excitation; solved for its preload.
    plan : TimePlan
    progress : callable, optional
        Called with the simulated time after each segment, s.
    steady : callable, optional
        ``steady(histories)``: whether the last two windows agree. While
        they do not, the run goes on window by window for at most
        ``plan.extension_periods`` periods, the histories holding the last
        two windows.

    Raises
    ------
    NewtonFailure
        Newton's method failed in a segment even at the smallest step.
    DivergenceError
        The engine ran away, or a value became NaN or infinite.
    TimeBudgetExceeded
        The run used up the case's ``time_budget``.
    """
    import exudyn as exu

    analysis = scene.case.analysis
    assert scene.excitation is not None
    where = run_label(scene.case.name, scene.excitation.name)
    settings = _simulation_settings(scene, plan)
    preloaded = np.asarray(scene.mbs.GetNodeOutput(scene.engine.node, exu.OutputVariableType.Position,
                                                   configuration=exu.ConfigurationType.Initial))
    # a steady start sets its own initial accelerations: at t = 0 the excitation, starting in
    # full from the first step, is still zero, so the equations of motion there would not give them
    settings.timeIntegration.generalizedAlpha.computeInitialAccelerations = plan.start != STEADY
    began = wall_clock.perf_counter()
    retries: list = []
    window = plan.measured_periods * plan.steps_per_period
    limit = plan.steps + plan.extension_periods * plan.steps_per_period
    segments = plan.segments()
    histories = None
    while segments:
        first, last, store = segments.pop(0)
        elapsed = wall_clock.perf_counter() - began
        if analysis.time_budget is not None and elapsed > analysis.time_budget:
            raise TimeBudgetExceeded(where, analysis.time_budget, elapsed, first * plan.step,
                                     max(plan.end_time, last * plan.step))
        for items in scene.force_channels.values():
            scene.mbs.SetSensorParameter(items.sensor, "storeInternal", store)
        _solve_segment(scene, settings, plan, first, last, where, retries)
        settings.timeIntegration.generalizedAlpha.computeInitialAccelerations = True
        _check_motion(scene, preloaded, last * plan.step, where)
        if progress is not None:
            progress(last * plan.step)
        if store:
            histories = _stored_histories(scene, histories, 2 * window, retries, where)
            histories.extended_periods = (last - plan.steps) // plan.steps_per_period
            if steady is not None and last + window <= limit and not steady(histories):
                segments.append((last, last + window, True))
    assert histories is not None
    return histories


def _stored_histories(scene: Scene, before: TimeHistories | None, samples: int, retries: list, where: str
                      ) -> TimeHistories:
    """The stored sensor data of the segment just integrated, after the last
    samples of *before* (whose last sample is the segment's first), at most
    *samples* + 1 samples."""
    forces = {name: scene.mbs.GetSensorStoredData(items.sensor) for name, items in scene.force_channels.items()}
    time = next(iter(forces.values()))[:, 0] if forces else np.zeros(0)
    hinge_forces = {name: data[:, 1:4] for name, data in forces.items()}
    if not all(np.all(np.isfinite(f)) for f in hinge_forces.values()):
        raise DivergenceError(f"{where}: the stored hinge forces contain NaN or infinite values")
    if before is not None:
        time = np.concatenate([before.time, time[1:]])[-samples - 1:]
        hinge_forces = {name: np.concatenate([before.hinge_forces[name], f[1:]])[-samples - 1:]
                        for name, f in hinge_forces.items()}
    return TimeHistories(time, hinge_forces, retries)


def extract(scene: Scene, plan: TimePlan, histories: TimeHistories) -> ExcitationResult:
    """Amplitudes at the excitation frequency, the steady-state check and warnings."""
    analysis = scene.case.analysis
    assert scene.excitation is not None and scene.excitation.signal is not None
    signal = scene.excitation.signal
    time = histories.time
    pylon = pylon_sum(histories.hinge_forces, scene.pylon_channels)
    steady = steady_amplitude(time, pylon, plan.frequency_hz, plan.measured_periods, analysis.steady_tolerance,
                              phase=plan.start == STEADY)
    window = steady.window
    hinge_amplitudes = {name: np.abs(harmonic_amplitude(time[window], forces[window], plan.frequency_hz))
                        for name, forces in histories.hinge_forces.items()}
    warnings = run_warnings(scene, plan, steady.relative_change, histories.extended_periods)
    return ExcitationResult(
        name=scene.excitation.name, frequency_hz=plan.frequency_hz, excitation_amplitude=signal.amplitude,
        pylon_amplitude=steady.amplitude, hinge_amplitudes=hinge_amplitudes, pylon_hinges=list(scene.pylon_channels),
        steady_change=steady.relative_change, steady_tolerance=analysis.steady_tolerance, warnings=warnings,
        time=time, hinge_histories=histories.hinge_forces, pylon_history=pylon,
        excitation_history=signal.force(time), window=window)


def run_warnings(scene: Scene, plan: TimePlan, relative_change: float, extended_periods: int = 0) -> list[str]:
    """The warnings of a time run: not steady (the pylon amplitudes of the two
    windows differ by *relative_change*, after *extended_periods* periods
    beyond the plan), a coarse step, undamped modes."""
    assert scene.excitation is not None
    analysis = scene.case.analysis
    warnings = []
    if relative_change > analysis.steady_tolerance:
        remedy = ("lengthen the settle time or check the damping" if plan.start != STEADY else
                  f"the run started in the steady state of its linearised scene and went on {extended_periods} "
                  f"periods beyond its plan without settling: the scene does not behave as its linearisation "
                  f"(check the damping, or start at rest with a fixed settle time)")
        compared = "pylon-force amplitudes" if plan.start != STEADY else "complex pylon-force amplitudes"
        warnings.append(
            f"not steady: the {compared} of the last two {plan.measured_periods}-period windows "
            f"differ by {100 * relative_change:.2f} % (> {100 * analysis.steady_tolerance:.2g} %); {remedy}")
        log.info("%s, %s: %s", scene.case.name, scene.excitation.name, warnings[-1])
    if plan.amplitude_error > ACCURACY_LIMIT:
        warnings.append(
            f"time step too coarse: at {plan.steps_per_period} steps per period the integrator's period error "
            f"puts the answer about {100 * plan.amplitude_error:.3g} % off on {plan.error_source}; "
            f"{plan.steps_needed} steps per period keep it below {100 * ACCURACY_TARGET:g} % (or answer "
            f"a linear scene in the frequency domain)")
        log.info("%s, %s: %s", scene.case.name, scene.excitation.name, warnings[-1])
    if plan.undamped_hz:
        started = ("the free vibration started by the ramp never decays and is part of the measured forces"
                   if plan.start != STEADY else "the run started in the steady state, but any free vibration "
                   "in them (from the integrator's error or a nonlinearity) never decays")
        warnings.append(
            f"undamped mounted modes at {', '.join(f'{f:.4g}' for f in plan.undamped_hz)} Hz: {started}; the "
            f"frequency domain gives the steady answer")
        log.info("%s, %s: %s", scene.case.name, scene.excitation.name, warnings[-1])
    return warnings
