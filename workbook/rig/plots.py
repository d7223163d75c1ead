"""Pictures of a rig record: time histories, amplitude spectra, and measured against simulated T.

The amplitude spectrum is the one-sided FFT amplitude of each channel, N:
``A_k = 2 |X_k| / n`` (``|X_0| / n`` at 0 Hz and at the Nyquist frequency),
with a rectangular window (no taper) over the largest whole number of rotor
periods the record holds, rounded to whole samples: the rotor frequency
then falls on a DFT bin (coherent sampling), and a sine of amplitude A at
it reads A (within the rounding of the window to a sample, at most one
sample in n). The rotor frequency is the spectral peak of the excitation
next to the nominal one (:func:`workbook.rig.correlation.peak_frequency`),
marked on every spectrum.
"""
from __future__ import annotations

import numpy as np

from workbook.model.case import DIRECTIONS
from workbook.rig.correlation import peak_frequency
from workbook.rig.records import EXCITATION_CHANNEL, RigRecord

__all__ = ["amplitude_spectrum", "coherent_samples", "plot_record", "SHOWN_PERIODS", "SHOWN_HARMONICS"]

#: Rotor periods shown in the time histories.
SHOWN_PERIODS = 5
#: The spectra are shown up to this multiple of the rotor frequency.
SHOWN_HARMONICS = 4


def coherent_samples(sample_rate_hz: float, frequency_hz: float, samples: int) -> int:
    """Samples of the largest whole number of periods of *frequency_hz* within *samples*, rounded to a sample.

    Parameters
    ----------
    sample_rate_hz : float
        Hz.
    frequency_hz : float
        Hz.
    samples : int
        Samples available.

    Returns
    -------
    int
    """
    periods = int(samples * frequency_hz / sample_rate_hz)
    return min(samples, max(2, int(round(periods * sample_rate_hz / frequency_hz))))


def amplitude_spectrum(signals: np.ndarray, sample_rate_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided FFT amplitude spectrum of *signals*, rectangular window over all samples given.

    Parameters
    ----------
    signals : ndarray, shape (n,) or (n, k)
        Uniformly sampled values (a force, N).
    sample_rate_hz : float
        Hz.

    Returns
    -------
    frequencies : ndarray, shape (n // 2 + 1,)
        Hz.
    amplitudes : ndarray, shape (n // 2 + 1,) or (n // 2 + 1, k)
        Amplitude of each frequency, in the unit of *signals*: a sine of
        amplitude A on a bin reads A.
    """
    n = signals.shape[0]
    amplitudes = np.abs(np.fft.rfft(signals, axis=0)) / n
    doubled = slice(1, None if n % 2 else -1)  # every bin but 0 Hz and (n even) the Nyquist frequency
    amplitudes[doubled] *= 2
    return np.fft.rfftfreq(n, 1.0 / sample_rate_hz), amplitudes


def plot_record(record: RigRecord, comparison=None):
    """The record's time histories (top row) and amplitude spectra (bottom row), a column per sensor.

    Each axes shows the sensor's x, y and z channels; the spectra mark the
    rotor frequency. With *comparison* a third row compares measured and
    simulated T per direction.

    Parameters
    ----------
    record : RigRecord
    comparison : pandas.DataFrame, optional
        The validation table (:func:`workbook.rig.correlation.comparison_frame`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    frequency = peak_frequency(record.time, record.excitation, record.nominal_hz)
    sensors = {**record.transducers, EXCITATION_CHANNEL: record.excitation}
    rows = 2 if comparison is None else 3
    figure = Figure(figsize=(3.6 * len(sensors), 3.2 * rows), layout="constrained")
    grid = figure.add_gridspec(rows, len(sensors))
    shown = min(len(record.time), int(np.ceil(SHOWN_PERIODS * record.sample_rate_hz / frequency)) + 1)
    window = coherent_samples(record.sample_rate_hz, frequency, len(record.time))
    for column, (name, forces) in enumerate(sensors.items()):
        history, spectrum = figure.add_subplot(grid[0, column]), figure.add_subplot(grid[1, column])
        frequencies, amplitudes = amplitude_spectrum(forces[-window:] - forces[-window:].mean(axis=0),
                                                     record.sample_rate_hz)
        for axis, direction in enumerate(DIRECTIONS):
            history.plot(1e3 * record.time[:shown], forces[:shown, axis], lw=1, label=direction)
            spectrum.plot(frequencies, amplitudes[:, axis], lw=1, label=direction)
        spectrum.axvline(frequency, color="0.4", ls="--", lw=0.8, label=f"rotor {frequency:.2f} Hz")
        spectrum.set_xlim(0, min(frequencies[-1], SHOWN_HARMONICS * frequency))
        history.set(title=name, xlabel="time [ms]", ylabel="force [N]")
        spectrum.set(xlabel="frequency [Hz]", ylabel="amplitude [N]")
        for axes in (history, spectrum):
            axes.grid(alpha=0.3)
        if column == 0:
            spectrum.legend(fontsize="small")
    if comparison is not None:
        bars = figure.add_subplot(grid[2, :])
        positions = np.arange(len(DIRECTIONS))
        bars.bar(positions - 0.2, comparison["T sim"], 0.4, label="simulated")
        bars.bar(positions + 0.2, comparison["T test"], 0.4, label="measured")
        for position, (test, error) in enumerate(zip(comparison["T test"], comparison["error %"], strict=True)):
            bars.annotate(f"{error:+.2f} %", (position + 0.2, test), ha="center", va="bottom", fontsize="small")
        bars.set(xticks=positions, xticklabels=list(DIRECTIONS), yscale="log", ylabel="transmissibility T",
                 title=f"{record.run}: measured against simulated T (error = (sim - test) / test)")
        bars.legend()
        bars.grid(alpha=0.3, axis="y")
    figure.suptitle(f"{record.path or 'rig record'}: run {record.run!r}, {record.sample_rate_hz:g} Hz")
    return figure
