"""Rotor speed bands on the fast path: the worst T over each speed range, its peaks found between the points.

A rotor runs anywhere from idle to red line, so its isolation is judged by
the worst T over that band, not at one speed. :func:`band_case` turns each
named single-frequency rotor excitation into a :class:`~workbook.model.case.Sweep`
over its band (:data:`BAND_POINTS` evenly spaced speeds, the band's top the
highest, so that the links are reduced for it), and every sweep of a case
is a band. A mounted mode inside a band puts a narrow peak between two
points of any fixed grid (its half-power width is about eta f, 3 Hz at
60 Hz for eta = 0.05), so :func:`band_peaks` looks for the true peak of
each direction: a bounded scalar search of T(f) around the grid's highest
point and around every undamped mode of the design inside the band. Its
derivative with respect to the design is T's at the peak's frequency held
fixed (Danskin: the peak's own shift adds nothing to first order).
"""
from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from workbook.errors import InputError
from workbook.model.case import SINGLE_FREQUENCY_KINDS, Case, Imbalance, Sweep

if TYPE_CHECKING:     # the linear mount loads the scene's modules: imported where a band is answered
    from workbook.design.linear_mount import ItemSolution

__all__ = ["BAND_POINTS", "band_text", "band_case", "band_peaks", "with_frequencies"]

#: Speeds of a band given as LOW:HIGH (evenly spaced, both ends included).
BAND_POINTS = 25
#: Relative tolerance of a peak's frequency.
PEAK_TOLERANCE = 1e-5


def band_text(text: str) -> tuple[str, tuple[float, float]]:
    """Read a band ``NAME=LOW:HIGH`` (Hz), e.g. ``LP rotor=40:62``.

    Raises
    ------
    InputError
        Naming the text and what is expected.
    """
    name, sign, rest = text.partition("=")
    try:
        low, high = (float(v) for v in rest.split(":"))
        if sign and name.strip() and 0 < low < high:
            return name.strip(), (low, high)
    except ValueError:
        pass
    raise InputError(f"band {text!r}: expected EXCITATION=LOW:HIGH, the rotor excitation's name and its speed "
                     "range in Hz, 0 < LOW < HIGH")


def band_case(case: Case, bands: dict, points: int = BAND_POINTS) -> Case:
    """*case* with each excitation named in *bands* (name to (low, high), Hz) a sweep over its band.

    Raises
    ------
    InputError
        A name that is no single-frequency excitation of *case*, a band
        that is not 0 < low < high, or fewer than 2 points.
    """
    if points < 2:
        raise InputError(f"band points: found {points}, expected at least 2")
    single = {item.name: item for item in case.excitations if isinstance(item, SINGLE_FREQUENCY_KINDS)}
    for name, (low, high) in bands.items():
        if name not in single:
            raise InputError(f"band {name!r}: expected the name of a single-frequency excitation of case "
                             f"{case.name!r} ({', '.join(single) or 'none'})")
        if not 0 < low < high:
            raise InputError(f"band {name!r}: found {low:g}:{high:g} Hz, expected 0 < LOW < HIGH")
    excitations = tuple(Sweep.band(item.name, single[item.name], bands[item.name][0], bands[item.name][1], points,
                                   spacing="linear") if item.name in bands else item for item in case.excitations)
    return dataclasses.replace(case, excitations=excitations)


def with_frequencies(case: Case, added: dict) -> Case:
    """*case* with the frequencies *added* (sweep name to Hz) put into its sweeps (duplicates dropped)."""
    excitations = []
    for item in case.excitations:
        if isinstance(item, Sweep) and item.name in added:
            merged = np.sort(np.concatenate([item.frequencies_hz, added[item.name]]))
            keep = np.append(True, np.diff(merged) > PEAK_TOLERANCE * merged[1:])
            item = dataclasses.replace(item, frequencies_hz=tuple(float(f) for f in merged[keep]))
        excitations.append(item)
    return dataclasses.replace(case, excitations=tuple(excitations))


def _transmissibility(solution: ItemSolution, load: np.ndarray, frequency: float, pylon: list) -> np.ndarray:
    """T per direction at *frequency* (Hz) of the generalised force *load* per N of excitation, shape (3,)."""
    import scipy.linalg as sla

    model = solution.model
    omega = 2 * np.pi * frequency
    motion = sla.solve(model.dynamic(omega), load, check_finite=False)
    return np.abs((model.output(omega) @ motion).reshape(-1, 3)[pylon].sum(axis=0))


def band_peaks(item: Sweep, solution: ItemSolution, pylon: list, grid: np.ndarray) -> np.ndarray:
    """The frequency of the highest T of each direction over the band of *item* (Hz, shape (3,)).

    Parameters
    ----------
    item : Sweep
        Its frequencies are the grid; its lowest and highest the band.
    solution : ItemSolution
        The design's solved item.
    pylon : list of int
        The pylon channels' positions among the force channels.
    grid : ndarray, shape (points, 3)
        T at the grid's frequencies.
    """
    import scipy.linalg as sla
    from scipy.optimize import minimize_scalar

    frequencies = np.asarray(item.frequencies_hz)
    low, high = frequencies[0], frequencies[-1]
    spacing = np.diff(frequencies).max() if len(frequencies) > 1 else 0.0
    model = solution.model
    modes = np.sqrt(np.abs(sla.eigvals(model.stiffness, model.mass).real)) / (2 * np.pi)
    modes = modes[(modes > low) & (modes < high)]

    solved: dict = {}

    def load(f: float) -> np.ndarray:
        """The load per N of excitation at *f*: one direction at every speed for a single force."""
        excitation = dataclasses.replace(item.template, frequency_hz=f if varying else low, rpm=None)
        return model.load(excitation) / excitation.force_amplitude

    varying = isinstance(item.template, Imbalance)          # its planes' forces may grow unlike one another
    fixed = load(low)

    def at(f: float) -> np.ndarray:
        if f not in solved:
            solved[f] = _transmissibility(solution, load(f) if varying else fixed, f, pylon)
        return solved[f]

    peaks = np.zeros(3)
    for d in range(3):
        best = int(np.argmax(grid[:, d]))
        peak, value = frequencies[best], grid[best, d]
        brackets = [(frequencies[max(best - 1, 0)], frequencies[min(best + 1, len(frequencies) - 1)])]
        brackets += [(max(low, f - spacing), min(high, f + spacing)) for f in modes]
        for a, b in brackets:
            if b <= a:
                continue
            found = minimize_scalar(lambda f, d=d: -at(f)[d], bounds=(a, b), method="bounded",
                                    options={"xatol": PEAK_TOLERANCE * b})
            if -found.fun > value:
                peak, value = float(found.x), -float(found.fun)
        peaks[d] = peak
    return peaks
