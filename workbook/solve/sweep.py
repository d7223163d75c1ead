"""Frequency sweeps: transmissibility curves and the mounted modes in band.

A sweep runs in the frequency domain (one scene, one linearisation, one
complex solve per frequency). The answer holds the usual
:class:`~workbook.answers.results.MountResult` (one run per frequency) and the
linearised modes in band: the engine's six rigid-body modes on its mount
(most kinetic energy in the engine) and any link mode inside the band. It
tabulates those modes (frequency, damping ratio, motion) and plots the
transmissibility per direction, for the pylon sum and any hinge, with the
modes marked.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbook._renamed import renamed
from workbook.answers.isolation import transmissibility
from workbook.answers.results import PYLON_SUM, MountResult
from workbook.model.case import DIRECTIONS, Case, Sweep
from workbook.solve.method import FREQUENCY, MethodChoice
from workbook.solve.pipeline import prepare, solve_frequencies
from workbook.solve.sweep_grid import ModesInBand, add_grid_warnings, modes_in_band

__all__ = ["SweepAnswer", "run_sweep", "modes_in_band"]


@dataclass
class SweepAnswer:
    """A frequency sweep of one case.

    Attributes
    ----------
    sweep : Sweep
    result : MountResult
        One run per sweep frequency.
    modes : ModesInBand
        The mounted modes and the link modes in band (:func:`modes_in_band`);
        ``modes.to_pandas()`` tabulates them.
    """

    sweep: Sweep
    result: MountResult
    modes: ModesInBand

    @property
    def frequencies(self) -> np.ndarray:
        """Hz."""
        return np.array([run.frequency_hz for run in self.result.runs])

    def transmissibility(self, location: str = PYLON_SUM) -> np.ndarray:
        """T per direction of the pylon sum or of a hinge, shape (frequencies, 3)."""
        return np.array([transmissibility(run.amplitudes()[location], run.excitation_amplitude) for run in self.result.runs])

    def to_pandas(self, locations=(PYLON_SUM,)):
        """T per frequency, location and direction, one column per (location, direction).

        Returns
        -------
        pandas.DataFrame
            Index: frequency (Hz).
        """
        import pandas as pd

        columns = {f"T {location} {axis}": self.transmissibility(location)[:, i]
                   for location in locations for i, axis in enumerate(DIRECTIONS)}
        return pd.DataFrame(columns, index=pd.Index(self.frequencies, name="frequency Hz"))

    curves_frame = renamed("curves_frame", "to_pandas(locations)", lambda self, *a, **k: self.to_pandas(*a, **k))
    modes_frame = renamed("modes_frame", "modes.to_pandas()", lambda self: self.modes.to_pandas())

    def plot(self, locations=(PYLON_SUM,)):
        """Transmissibility per direction against frequency (log-log), modes marked.

        Mounted modes are dashed lines, link modes dotted, numbered as in
        :meth:`ModesInBand.to_pandas <workbook.solve.sweep_grid.ModesInBand.to_pandas>` of :attr:`modes`.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        frequencies = self.frequencies
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(9, 8), constrained_layout=True)
        for i, axis in enumerate(DIRECTIONS):
            for location in locations:
                axes[i].loglog(frequencies, np.maximum(self.transmissibility(location)[:, i], 1e-12), lw=1.0,
                               label=location)
            axes[i].set_ylabel(f"T {axis}")
            for number, (kind, mode) in enumerate(self.modes, start=1):
                if frequencies[0] <= mode.frequency_hz <= frequencies[-1]:
                    axes[i].axvline(mode.frequency_hz, color="0.5", lw=0.7, ls="--" if kind == "mounted" else ":")
                    if i == 0:
                        axes[i].annotate(str(number), (mode.frequency_hz, 1.0), xycoords=("data", "axes fraction"),
                                         ha="center", va="bottom", fontsize="small")
        axes[-1].set_xlabel("frequency Hz")
        axes[0].legend(loc="lower left", fontsize="small")
        fig.suptitle(f"{self.result.case_name}: {self.sweep.name}, transmissibility "
                     f"(mounted modes dashed, link modes dotted)")
        return fig


def run_sweep(case: Case, sweep: Sweep, *, reduced=None) -> SweepAnswer:
    """Run *sweep* on *case* in the frequency domain.

    A mode whose peak the grid steps over is warned on the point nearest
    to it (:func:`~workbook.solve.sweep_grid.grid_warnings`).

    Parameters
    ----------
    case : Case
    sweep : Sweep
    reduced : dict, optional
        Reduced links (default: reduced for the sweep's highest frequency).

    Returns
    -------
    SweepAnswer
    """
    points = sweep.expand()
    prepared = prepare(case, points[0], reduce_for=points[-1], reduced=reduced)
    method = MethodChoice(FREQUENCY, "a sweep runs in the frequency domain: one linearisation serves "
                                       "every frequency")
    with prepared.scene:
        runs = solve_frequencies(case, prepared, points, method)
    add_grid_warnings(sweep, runs, prepared.modes)
    return SweepAnswer(sweep, MountResult(case.name, runs),
                       modes_in_band(prepared.modes, sweep.frequencies_hz[-1]))
