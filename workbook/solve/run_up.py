"""Run-ups: a rotor imbalance over a speed range, its force growing as U w^2.

A :class:`~workbook.model.case.RunUp` is a sweep whose excitation is an
unbalance: at speed w the force of each plane is ``U w^2``. Like every
sweep it runs in the frequency domain (one scene, one linearisation, one
complex solve per speed). The answer tabulates, per speed, the excitation
force, the pylon-force amplitude and the transmissibility T per direction,
and plots both against the speed with the mounted modes marked at the speed
whose once-per-revolution force hits them (the mode's frequency in the run-up's
speed unit).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np

from workbook._renamed import renamed
from workbook.answers.results import PYLON_SUM
from workbook.model.case import DIRECTIONS, SPEED_UNITS, Case, RunUp, SpeedUnit
from workbook.solve.sweep import SweepAnswer, run_sweep

__all__ = ["RunUpAnswer", "run_up"]


@dataclass
class RunUpAnswer(SweepAnswer):
    """A run-up of one case: a :class:`~workbook.solve.sweep.SweepAnswer`
    whose points are speeds (``sweep`` is the :class:`RunUp`)."""

    @property
    def speed_unit(self) -> SpeedUnit:
        return cast(RunUp, self.sweep).speed_unit

    @property
    def speeds(self) -> np.ndarray:
        """The speeds in :attr:`speed_unit`."""
        return self.frequencies / SPEED_UNITS[self.speed_unit]

    def pylon_amplitudes(self, location: str = PYLON_SUM) -> np.ndarray:
        """Force amplitude per direction of the pylon sum or of a hinge, N, shape (speeds, 3)."""
        return np.array([run.amplitudes()[location] for run in self.result.runs])

    def to_pandas(self, location: str = PYLON_SUM):
        """One row per speed: frequency (Hz), excitation force (N), the force
        amplitude (N) and T per direction of the pylon sum or a hinge.

        Returns
        -------
        pandas.DataFrame
            Index: speed in :attr:`speed_unit`.
        """
        import pandas as pd

        columns = {"frequency Hz": self.frequencies,
                   "excitation N": [run.excitation_amplitude for run in self.result.runs]}
        forces, transmissibility = self.pylon_amplitudes(location), self.transmissibility(location)
        columns.update({f"F {axis} N": forces[:, i] for i, axis in enumerate(DIRECTIONS)})
        columns.update({f"T {axis}": transmissibility[:, i] for i, axis in enumerate(DIRECTIONS)})
        return pd.DataFrame(columns, index=pd.Index(self.speeds, name=f"speed {self.speed_unit}"))

    frame = renamed("frame", "to_pandas(location)", lambda self, *a, **k: self.to_pandas(*a, **k))

    def mode_speeds(self) -> list[tuple[int, str, float]]:
        """``(number, kind, speed)`` of each mode of :attr:`modes` whose
        frequency lies in the speed range (speed in :attr:`speed_unit`)."""
        low, high = self.frequencies[0], self.frequencies[-1]
        return [(number, kind, mode.frequency_hz / SPEED_UNITS[self.speed_unit])
                for number, (kind, mode) in enumerate(self.modes, start=1) if low <= mode.frequency_hz <= high]

    def plot(self, location: str = PYLON_SUM):
        """Force amplitude and T per direction against speed, modes marked.

        Mounted modes are dashed lines, link modes dotted, numbered as in
        ``modes.to_pandas()``.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        speeds = self.speeds
        fig, (force_axes, t_axes) = plt.subplots(2, 1, sharex=True, figsize=(9, 7), constrained_layout=True)
        excitation = [run.excitation_amplitude for run in self.result.runs]
        force_axes.semilogy(speeds, excitation, color="0.3", lw=1.0, ls="-.", label="excitation U w^2")
        for i, axis in enumerate(DIRECTIONS):
            force_axes.semilogy(speeds, np.maximum(self.pylon_amplitudes(location)[:, i], 1e-12), lw=1.0,
                                label=f"{location} {axis}")
            t_axes.semilogy(speeds, np.maximum(self.transmissibility(location)[:, i], 1e-12), lw=1.0,
                            label=f"T {axis}")
        for number, kind, speed in self.mode_speeds():
            for axes in (force_axes, t_axes):
                axes.axvline(speed, color="0.5", lw=0.7, ls="--" if kind == "mounted" else ":")
            force_axes.annotate(str(number), (speed, 1.0), xycoords=("data", "axes fraction"), ha="center",
                                va="bottom", fontsize="small")
        force_axes.set_ylabel("force amplitude N")
        t_axes.set_ylabel("T")
        t_axes.set_xlabel(f"speed {self.speed_unit}")
        force_axes.legend(loc="upper left", fontsize="small")
        t_axes.legend(loc="lower left", fontsize="small")
        fig.suptitle(f"{self.result.case_name}: run-up {self.sweep.name} (mounted modes dashed, link modes dotted)")
        return fig


def run_up(case: Case, item: RunUp, *, reduced=None) -> RunUpAnswer:
    """Run the run-up *item* on *case* in the frequency domain.

    Parameters
    ----------
    case : Case
    item : RunUp
    reduced : dict, optional
        Reduced links (default: reduced for the highest speed).

    Returns
    -------
    RunUpAnswer
    """
    answer = run_sweep(case, item, reduced=reduced)
    return RunUpAnswer(answer.sweep, answer.result, answer.modes)
