"""Amplitude at a known frequency from sampled force histories.

Used on simulated hinge forces and on measured rig data alike, so it knows
nothing about Exudyn: a history is a time vector and one or more signal
columns. The amplitude at frequency f is the single-bin DFT of the
mean-removed signal over a window of an integer number of periods,
``A = 2/N |sum (x_k - mean) exp(-i 2 pi f t_k)|``, which is exact for a
uniformly sampled sinusoid plus a constant. A signal holding several known
frequencies at once (two rotors together) is fitted by least squares
(:func:`harmonic_amplitudes`), exact for a sum of those sinusoids plus a
constant over any window.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["period_window", "harmonic_amplitude", "harmonic_amplitudes", "steady_amplitude", "SteadyAmplitude",
           "relative_change",
           "amplitude_spectrum"]


def period_window(time: np.ndarray, frequency_hz: float, periods: int, *, end: int | None = None) -> slice:
    """Index range of the last *periods* whole periods ending at sample *end*.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Uniformly sampled times, s.
    frequency_hz : float
        Frequency whose periods count, Hz.
    periods : int
        Whole periods in the window.
    end : int, optional
        Index one past the window's last sample (default: the end).

    Returns
    -------
    slice
        ``time[window]`` spans ``periods / frequency_hz`` to within one sample.

    Raises
    ------
    ValueError
        If the history is shorter than the window or not uniformly sampled.
    """
    time = np.asarray(time, dtype=float)
    end = len(time) if end is None else end
    step = _uniform_step(time)
    samples = int(round(periods / (frequency_hz * step)))
    if samples < 2 or samples > end:
        raise ValueError(f"a window of {periods} periods at {frequency_hz:g} Hz needs {samples} samples; "
                         f"{end} available")
    return slice(end - samples, end)


def _uniform_step(time: np.ndarray) -> float:
    steps = np.diff(time)
    if len(steps) == 0 or steps.min() <= 0:
        raise ValueError("time must increase")
    step = float(np.median(steps))
    if np.abs(steps - step).max() > 1e-6 * step + 1e-12:
        raise ValueError("time must be uniformly sampled")
    return step


def harmonic_amplitude(time: np.ndarray, signals: np.ndarray, frequency_hz: float) -> np.ndarray:
    """Complex amplitude of each signal column at *frequency_hz*.

    The mean is removed first; the window should span whole periods.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Uniformly sampled times of the window, s.
    signals : ndarray, shape (n,) or (n, k)
        The sampled signals.
    frequency_hz : float
        Frequency of interest, Hz.

    Returns
    -------
    ndarray, complex, shape () or (k,)
        ``X`` with ``x(t) ~ mean + Re(X exp(i 2 pi f t))``; ``abs(X)`` is the
        amplitude in the signals' unit.
    """
    time = np.asarray(time, dtype=float)
    values = np.asarray(signals, dtype=float)
    centred = values - values.mean(axis=0)
    phasor = np.exp(-2j * np.pi * frequency_hz * time)
    return 2.0 / len(time) * np.tensordot(phasor, centred, axes=(0, 0))


def harmonic_amplitudes(time: np.ndarray, signals: np.ndarray, frequencies_hz) -> np.ndarray:
    """Complex amplitude of each signal column at each of several frequencies, by least squares.

    Fits ``x(t) = c + sum_j Re(X_j exp(i 2 pi f_j t))`` to each column; exact
    for such a signal over any window (of at least one period of the
    closest-spaced frequencies, for a well-conditioned fit).

    Parameters
    ----------
    time : ndarray, shape (n,)
        Times of the window, s.
    signals : ndarray, shape (n,) or (n, k)
    frequencies_hz : sequence of float
        Distinct frequencies, Hz.

    Returns
    -------
    ndarray, complex, shape (m,) or (m, k)
        ``X_j`` per frequency (rows) and signal column.
    """
    time = np.asarray(time, dtype=float)
    values = np.asarray(signals, dtype=float)
    phase = 2 * np.pi * np.outer(time - time[0], np.asarray(frequencies_hz, dtype=float))
    design = np.column_stack([np.ones_like(time), np.cos(phase), np.sin(phase)])
    coefficients, *_ = np.linalg.lstsq(design, values, rcond=None)
    count = phase.shape[1]
    cos_part, sin_part = coefficients[1:1 + count], coefficients[1 + count:]
    shift = np.exp(-2j * np.pi * np.asarray(frequencies_hz, dtype=float) * time[0])
    shift = shift.reshape((-1,) + (1,) * (values.ndim - 1))
    return (cos_part - 1j * sin_part) * shift


@dataclass(frozen=True)
class SteadyAmplitude:
    """Amplitudes from the last window, checked against the window before.

    Attributes
    ----------
    amplitude : ndarray, shape (k,)
        Amplitude of each signal in the last window.
    previous : ndarray, shape (k,)
        Amplitude of each signal in the window before.
    relative_change : float
        Largest amplitude change between the windows relative to the largest
        amplitude.
    tolerance : float
        The allowed relative change.
    window : slice
        Samples of the last window.
    """

    amplitude: np.ndarray
    previous: np.ndarray
    relative_change: float
    tolerance: float
    window: slice

    @property
    def steady(self) -> bool:
        """True if the two windows agree within the tolerance."""
        return self.relative_change <= self.tolerance


def steady_amplitude(time: np.ndarray, signals: np.ndarray, frequency_hz: float, periods: int,
                     tolerance: float = 0.005, *, phase: bool = False) -> SteadyAmplitude:
    """Amplitude at *frequency_hz* over the last *periods* periods, with a steady-state check.

    Parameters
    ----------
    time : ndarray, shape (n,)
        Uniformly sampled times, s.
    signals : ndarray, shape (n,) or (n, k)
        The sampled signals.
    frequency_hz : float
        Frequency of interest, Hz.
    periods : int
        Periods per window; the history must hold two windows.
    tolerance : float
        Allowed relative change between the two windows.
    phase : bool
        Compare the complex amplitudes (magnitude and phase against absolute
        time) instead of the magnitudes only: stricter, since a slowly
        decaying vibration at another frequency can leak into the
        magnitudes of two windows alike but not with the same phase.

    Returns
    -------
    SteadyAmplitude
    """
    values = np.asarray(signals, dtype=float)
    values = values[:, None] if values.ndim == 1 else values
    last = period_window(time, frequency_hz, periods)
    before = period_window(time, frequency_hz, periods, end=last.start)
    complex_last = harmonic_amplitude(time[last], values[last], frequency_hz)
    complex_before = harmonic_amplitude(time[before], values[before], frequency_hz)
    amplitude, previous = np.abs(complex_last), np.abs(complex_before)
    return SteadyAmplitude(amplitude, previous, relative_change(complex_last, complex_before, phase), tolerance, last)


def relative_change(last: np.ndarray, before: np.ndarray, phase: bool = False) -> float:
    """Largest change between the complex amplitudes *last* and *before* of two
    windows relative to the largest magnitude: of the magnitudes, or with
    *phase* of the complex amplitudes themselves."""
    scale = max(np.abs(last).max(), np.abs(before).max())
    difference = np.abs(last - before) if phase else np.abs(np.abs(last) - np.abs(before))
    return float(difference.max() / scale) if scale > 0 else 0.0


def amplitude_spectrum(time: np.ndarray, signal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum of a mean-removed, uniformly sampled signal.

    Returns
    -------
    frequencies : ndarray
        Hz.
    amplitudes : ndarray
        Amplitude of a sinusoid at each frequency, in the signal's unit.
    """
    step = _uniform_step(np.asarray(time, dtype=float))
    values = np.asarray(signal, dtype=float)
    values = values - values.mean(axis=0)
    spectrum = np.abs(np.fft.rfft(values, axis=0)) * 2.0 / len(values)
    return np.fft.rfftfreq(len(values), step), spectrum
