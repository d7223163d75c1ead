"""A sweep's grid against the modes it crosses.

A sweep (or a run-up) answers at its grid points only. A lightly damped
mode between two points peaks where no point looks: the table's largest
value can lie far below the true peak. :func:`grid_warnings` compares the
grid with the half-power bandwidth of every mode in its range and warns
with the spacing that resolves the mode.
"""
from __future__ import annotations

import numpy as np

from workbook.model.case import SPEED_UNITS, RunUp, Sweep
from workbook.solve.modes import ENGINE_SHARE, FREE_FREQUENCY_HZ, Mode

__all__ = ["ModesInBand", "modes_in_band", "grid_warnings", "add_grid_warnings", "PEAK_SHORTFALL", "ADVISED_SPACING"]


#: A grid whose nearest point to a mode in its range sees less than this
#: share of the mode's peak (single-DOF estimate) is warned.
PEAK_SHORTFALL = 0.9
#: Spacing advised around a mode, in half-power bandwidths: the nearest
#: point then lies within an eighth of it (at least 97 % of the peak).
ADVISED_SPACING = 0.25


class ModesInBand(list):
    """The modes of a sweep's band: a list of ``(kind, Mode)``, numbered from 1
    in tables and plots; kind is ``"mounted"`` or ``"link"``."""

    def to_pandas(self):
        """Frequency (Hz), damping ratio (%), kind, engine share of the
        kinetic energy (%) and the motion of each mode.

        Returns
        -------
        pandas.DataFrame
            Index: mode number (from 1).
        """
        import pandas as pd

        rows = [(kind, mode.frequency_hz, 100 * mode.damping_ratio, 100 * mode.engine_share, mode.description)
                for kind, mode in self]
        frame = pd.DataFrame(rows, columns=["kind", "frequency Hz", "damping ratio %", "engine share %",
                                           "motion"])
        frame.index = pd.RangeIndex(1, len(frame) + 1, name="mode")
        return frame


def modes_in_band(modes: list[Mode], stop_hz: float) -> ModesInBand:
    """The mounted modes and the link modes up to *stop_hz*, labelled.

    Returns
    -------
    ModesInBand
        ``("mounted", mode)`` for every mounted mode (whatever its frequency)
        and ``("link", mode)`` for link modes from 0 to *stop_hz*, ascending.
    """
    chosen = ModesInBand()
    for mode in modes:
        if mode.frequency_hz < FREE_FREQUENCY_HZ:
            continue
        if mode.engine_share >= ENGINE_SHARE:
            chosen.append(("mounted", mode))
        elif mode.frequency_hz <= stop_hz:
            chosen.append(("link", mode))
    return chosen


def grid_warnings(frequencies_hz, modes: list[tuple[str, Mode]], unit: str = "Hz") -> dict[int, list[str]]:
    """Where a sweep's grid steps over the peak of a mode in its range.

    A mode at ``f_n`` with damping ratio ``zeta`` peaks within its
    half-power bandwidth ``df = 2 zeta f_n`` (``eta f_n`` for a loss factor
    eta). A point ``delta`` from it sees about ``1 / sqrt(1 + (2 delta /
    df)^2)`` of the peak (a single DOF); when the nearest point sees less
    than :data:`PEAK_SHORTFALL` of it, the table's largest value may lie far
    below the true peak (a single DOF with eta 0.002 on 12 speeds: 11
    against 500).

    Parameters
    ----------
    frequencies_hz : array_like
        The grid, Hz, ascending.
    modes : list of (str, Mode)
        :func:`modes_in_band`, numbered from 1 as in :meth:`ModesInBand.to_pandas`.
    unit : {"Hz", "rpm"}
        Unit the grid is given in (a run-up's speed unit), for the advice.

    Returns
    -------
    dict of int to list of str
        Warnings per grid point: the point nearest to each missed mode.
    """
    grid = np.asarray(frequencies_hz, dtype=float)
    per_hz = 1.0 / SPEED_UNITS[unit]
    warned: dict[int, list[str]] = {}
    for number, (kind, mode) in enumerate(modes, start=1):
        f_n, zeta = mode.frequency_hz, mode.damping_ratio
        if not grid[0] <= f_n <= grid[-1] or not 0 < zeta < 1:
            continue
        band = 2 * zeta * f_n
        nearest = int(np.argmin(np.abs(grid - f_n)))
        delta = abs(grid[nearest] - f_n)
        seen = 1 / np.sqrt(1 + (2 * delta / band) ** 2)
        if seen >= PEAK_SHORTFALL:
            continue
        step = ADVISED_SPACING * band
        warned.setdefault(nearest, []).append(
            f"the grid steps over the peak of {kind} mode {number} at {f_n * per_hz:.6g} {unit} "
            f"({mode.description}): its half-power bandwidth is {band * per_hz:.2g} {unit} (damping ratio "
            f"{zeta:.2g}) and the nearest point, {grid[nearest] * per_hz:.6g} {unit}, sees about {seen:.0%} of "
            f"the peak (single-DOF estimate); the table's largest value may be far below the true peak. Add "
            f"points no more than {step * per_hz:.2g} {unit} apart from {(f_n - band) * per_hz:.6g} to "
            f"{(f_n + band) * per_hz:.6g} {unit}")
    return warned


def add_grid_warnings(sweep: Sweep, runs: list, modes: list[Mode]) -> None:
    """Put the warnings of :func:`grid_warnings` on the runs of *sweep*.

    Parameters
    ----------
    sweep : Sweep or RunUp
    runs : list of ExcitationResult
        One per sweep frequency, in order.
    modes : list of Mode
        Every linearised mode of the sweep's scene.
    """
    unit = sweep.speed_unit if isinstance(sweep, RunUp) else "Hz"
    in_band = modes_in_band(modes, sweep.frequencies_hz[-1])
    for index, warnings in grid_warnings(sweep.frequencies_hz, in_band, unit).items():
        runs[index].warnings.extend(warnings)
