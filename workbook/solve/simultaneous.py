"""Several frequencies in one time-domain run: both rotors together.

A :class:`~workbook.model.case.Simultaneous` excitation (the LP and the HP
rotor at once, say) runs as one time integration with every part acting,
each at its own frequency:

- plan: the step from the highest frequency (``steps_per_period`` steps of
  its period); the smooth start of every part over ``ramp_periods`` periods
  of the lowest frequency; the settle time as for one excitation; each
  measured window at least ``measured_periods`` periods of the lowest
  frequency (whole periods of the highest);
- extraction: per force channel the mean and the complex amplitude at every
  part's frequency together, by least squares over the window
  (:func:`workbook.answers.amplitude.harmonic_amplitudes`), exact for a
  steady response whatever the ratio of the frequencies; the steady check
  compares the pylon amplitudes of two consecutive windows at every
  frequency.

The answer is one :class:`~workbook.answers.results.ExcitationResult` per
part, T referring to that part's force. In the frequency domain the same
excitation is answered part by part (superposition, :mod:`workbook.solve.pipeline`).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from workbook.answers.amplitude import harmonic_amplitudes, period_window, relative_change
from workbook.answers.isolation import pylon_sum
from workbook.answers.results import ExcitationResult
from workbook.model.case import AnalysisSettings, Simultaneous
from workbook.scene.build import Scene
from workbook.scene.excitation import ExcitationSignal
from workbook.solve.guards import check_undamped_resonance
from workbook.solve.modes import Mode
from workbook.solve.steady_start import STEADY, Start
from workbook.solve.time_domain import TimeHistories, TimePlan, plan_run, run_warnings

__all__ = ["plan_simultaneous", "extract_simultaneous"]


def _lowest_and_highest(item: Simultaneous):
    parts = sorted(item.parts, key=lambda part: part.frequency)
    return parts[0], parts[-1]


def plan_simultaneous(analysis: AnalysisSettings, item: Simultaneous, modes: list[Mode], where: str,
                      start: Start = "rest") -> TimePlan:
    """The plan of one run of every part of *item* (see the module text).

    Raises
    ------
    ResonanceError
        A part's frequency lies on an undamped mode.
    RunTooLong
        The plan has too many steps.
    """
    lowest, highest = _lowest_and_highest(item)
    ratio = highest.frequency / lowest.frequency
    for part in item.parts:
        check_undamped_resonance(where, part.frequency, modes, 1.0 / analysis.measured_periods,
                                 f"{part.name!r} excites an undamped mode: its free vibration never decays")
    scaled = dataclasses.replace(analysis, ramp_periods=analysis.ramp_periods * ratio,
                                 measured_periods=math.ceil(analysis.measured_periods * ratio - 1e-9))
    return plan_run(scaled, ExcitationSignal.of(highest, scaled.ramp_periods), modes, where, start)


def extract_simultaneous(scene: Scene, plan: TimePlan, histories: TimeHistories, item: Simultaneous
                         ) -> list[ExcitationResult]:
    """The amplitudes at every part's frequency from one run's histories, one result per part."""
    analysis = scene.case.analysis
    time = histories.time
    frequencies = [part.frequency for part in item.parts]
    pylon = pylon_sum(histories.hinge_forces, scene.pylon_channels)
    last = period_window(time, plan.frequency_hz, plan.measured_periods)
    before = period_window(time, plan.frequency_hz, plan.measured_periods, end=last.start)
    complex_last = harmonic_amplitudes(time[last], pylon[last], frequencies)
    complex_before = harmonic_amplitudes(time[before], pylon[before], frequencies)
    amplitude = np.abs(complex_last)
    hinges = {name: np.abs(harmonic_amplitudes(time[last], forces[last], frequencies))
              for name, forces in histories.hinge_forces.items()}
    results = []
    for j, part in enumerate(item.expand()):
        change = relative_change(complex_last[j], complex_before[j], phase=plan.start == STEADY)
        # the start of every part lasts ramp_periods periods of the lowest frequency
        signal = ExcitationSignal.of(part, analysis.ramp_periods * part.frequency / min(frequencies))
        results.append(ExcitationResult(
            name=part.name, frequency_hz=part.frequency, excitation_amplitude=part.force_amplitude,
            pylon_amplitude=amplitude[j], hinge_amplitudes={name: a[j] for name, a in hinges.items()},
            pylon_hinges=list(scene.pylon_channels), steady_change=change,
            steady_tolerance=analysis.steady_tolerance,
            warnings=run_warnings(scene, plan, change, histories.extended_periods), time=time,
            hinge_histories=histories.hinge_forces, pylon_history=pylon, excitation_history=signal.force(time),
            window=last))
    return results
