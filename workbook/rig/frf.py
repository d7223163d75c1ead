"""Frequency response functions of broadband and run-up rig records.

**H1 with coherence** (a shaker test with broadband or swept excitation).
Per direction d the excitation force ``x = F_exc,d`` and the pylon force
``y = F_pylon,d`` (vector sum of the transducers) give, from Welch-averaged
auto and cross spectra (:func:`scipy.signal.welch`, :func:`scipy.signal.csd`:
Hann windows of ``segment`` seconds, half overlapping, mean removed)::

    H1_d(f) = G_xy(f) / G_xx(f),      gamma2_d(f) = |G_xy|^2 / (G_xx G_yy),
    T_d(f) = |H1_d(f)|,

the estimator that is unbiased by noise on the response. Its normalised
random error is ``eps = sqrt(1 - gamma2) / (sqrt(gamma2) sqrt(2 n_d))`` for
``n_d`` averages (Bendat & Piersol, Random Data, 4th ed., table 9.6); noise
on the excitation biases it low. Each direction is a single-input estimate:
it holds when the excitation in d is uncorrelated with that of the other
directions (one shaker direction per test, or independent sources);
otherwise the coherence falls below 1 and says so. A direction without
excitation (its RMS below :data:`SILENT` of the largest) has no FRF (NaN).

**Order tracking** (a run-up record). The rotor frequency ``f(t)`` is the
spectral peak of the excitation in frames of ``frame`` seconds (half
overlapping; the FFT peak, refined by
:func:`workbook.rig.correlation.peak_frequency`), interpolated linearly
between the frames' centres; its integral is the rotor phase
``phi(t) = 2 pi int f dt``. The 1x component of each channel in a frame is
the Hann-weighted single-bin DFT along that phase,
``X = 2 sum(w x e^{-i phi}) / sum(w)`` (exact for ``Re(X e^{i phi})`` whose
amplitude is constant over the frame, up to the leakage of the mean and of
the 2x-distant image through the Hann window, below 1e-4 for 8 periods).
The excitation amplitude is the largest magnitude of the force vector over
a period (:func:`workbook.rig.correlation.force_amplitude`), and
``T_d = |P_d| / |F_exc|``, as in a simulated run-up
(:mod:`workbook.solve.run_up`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbook.errors import RecordError
from workbook.model.case import DIRECTIONS
from workbook.rig.correlation import MIN_SAMPLES_PER_PERIOD, force_amplitude, peak_frequency
from workbook.rig.records import EXCITATION_CHANNEL, RigRecord

__all__ = ["RecordFRF", "OrderTrack", "h1_estimate", "record_frf", "order_track", "plot_frf", "plot_order_track",
           "SILENT", "MIN_AVERAGES", "MIN_FRAME_PERIODS"]

#: A direction whose excitation RMS is below this fraction of the largest one is not excited.
SILENT = 1e-6
#: Fewest Welch averages (segments) an H1 estimate takes.
MIN_AVERAGES = 4
#: A frame of the order track must hold this many periods of the rotor.
MIN_FRAME_PERIODS = 8


@dataclass
class RecordFRF:
    """H1 estimate of the pylon force per unit excitation force, per direction.

    Attributes
    ----------
    frequencies_hz : ndarray, shape (n,)
        Hz.
    h1 : ndarray, complex, shape (n, 3)
        ``F_pylon,d / F_exc,d`` per direction (NaN: not excited).
    coherence : ndarray, shape (n, 3)
        Ordinary coherence gamma^2, 0 to 1.
    averages : int
        Segments averaged, n_d.
    segment_s : float
        Segment length, s (resolution 1 / segment_s Hz).
    run : str
    path : str
    """

    frequencies_hz: np.ndarray
    h1: np.ndarray
    coherence: np.ndarray
    averages: int
    segment_s: float
    run: str = ""
    path: str = ""

    @property
    def transmissibility(self) -> np.ndarray:
        """``T_d(f) = |H1_d(f)|``, shape (n, 3)."""
        return np.abs(self.h1)

    @property
    def random_error(self) -> np.ndarray:
        """Normalised random error of ``|H1|``, ``sqrt(1 - gamma2) / sqrt(2 n_d gamma2)``, shape (n, 3)."""
        coherence = np.clip(self.coherence, 1e-12, 1.0)
        return np.sqrt((1 - coherence) / (2 * self.averages * coherence))

    def band(self, low_hz: float, high_hz: float) -> np.ndarray:
        """Mask of the frequencies within ``[low_hz, high_hz]``."""
        return (self.frequencies_hz >= low_hz) & (self.frequencies_hz <= high_hz)


@dataclass
class OrderTrack:
    """The 1x (once per revolution) component of a run-up record, frame by frame.

    Attributes
    ----------
    time_s : ndarray, shape (k,)
        Frame centres, s.
    frequency_hz : ndarray, shape (k,)
        Rotor frequency at each frame centre, Hz.
    excitation_amplitude : ndarray, shape (k,)
        ``|F_exc|``, N.
    pylon_amplitude : ndarray, shape (k, 3)
        Pylon-force amplitude per direction, N.
    frame_s : float
        Frame length, s.
    run : str
    path : str
    """

    time_s: np.ndarray
    frequency_hz: np.ndarray
    excitation_amplitude: np.ndarray
    pylon_amplitude: np.ndarray
    frame_s: float
    run: str = ""
    path: str = ""

    @property
    def transmissibility(self) -> np.ndarray:
        """``T_d = |P_d| / |F_exc|`` per frame, shape (k, 3)."""
        return self.pylon_amplitude / self.excitation_amplitude[:, None]


def h1_estimate(excitation: np.ndarray, response: np.ndarray, sample_rate_hz: float,
                segment: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """H1 estimate and coherence of *response* per unit *excitation* (module docstring).

    Parameters
    ----------
    excitation, response : ndarray, shape (n,)
        Uniformly sampled signals.
    sample_rate_hz : float
        Hz.
    segment : int
        Samples per Welch segment (Hann window, half overlap).

    Returns
    -------
    frequencies : ndarray, shape (segment // 2 + 1,)
        Hz.
    h1 : ndarray, complex
        ``G_xy / G_xx`` in the unit of response per unit of excitation.
    coherence : ndarray
        ``|G_xy|^2 / (G_xx G_yy)``.
    averages : int
        Segments averaged.
    """
    from scipy.signal import csd, welch

    options = dict(fs=sample_rate_hz, window="hann", nperseg=segment, noverlap=segment // 2, detrend="constant")
    frequencies, gxx = welch(excitation, **options)
    _, gyy = welch(response, **options)
    _, gxy = csd(excitation, response, **options)
    with np.errstate(divide="ignore", invalid="ignore"):
        h1 = gxy / gxx
        coherence = np.abs(gxy) ** 2 / (gxx * gyy)
    averages = 1 + (len(excitation) - segment) // (segment - segment // 2)
    return frequencies, h1, np.nan_to_num(coherence), averages


def record_frf(record: RigRecord, segment_s: float = 1.0) -> RecordFRF:
    """H1 and coherence of the pylon force per unit excitation, per direction, of a broadband record.

    Parameters
    ----------
    record : RigRecord
    segment_s : float
        Welch segment length, s: the frequency resolution is ``1 / segment_s``.

    Returns
    -------
    RecordFRF

    Raises
    ------
    RecordError
        A record too short for :data:`MIN_AVERAGES` segments, or an
        excitation without any signal, naming the channel.
    """
    segment = int(round(segment_s * record.sample_rate_hz))
    averages = 1 + (len(record.time) - segment) // max(1, segment - segment // 2)
    if segment < 16 or averages < MIN_AVERAGES:
        raise RecordError(record.path, f"segments of {segment_s:g} s ({segment} samples) give {max(averages, 0)} "
                          f"averages over the {len(record.time) / record.sample_rate_hz:.4g} s recorded; at least "
                          f"{MIN_AVERAGES} of at least 16 samples needed (a shorter segment)", column="time [s]")
    excitation = record.excitation - record.excitation.mean(axis=0)
    rms = np.sqrt(np.mean(excitation ** 2, axis=0))
    if rms.max() == 0:
        raise RecordError(record.path, "the excitation is constant in every direction: no FRF",
                          column=f"{EXCITATION_CHANNEL} {DIRECTIONS[0]}")
    pylon = record.pylon
    frequencies = np.fft.rfftfreq(segment, 1.0 / record.sample_rate_hz)
    h1 = np.full((len(frequencies), 3), np.nan, dtype=complex)
    coherence = np.zeros((len(frequencies), 3))
    count = averages
    for axis in range(3):
        if rms[axis] < SILENT * rms.max():
            continue
        _, h1[:, axis], coherence[:, axis], count = h1_estimate(excitation[:, axis], pylon[:, axis],
                                                               record.sample_rate_hz, segment)
    return RecordFRF(frequencies, h1, coherence, count, segment / record.sample_rate_hz, record.run, record.path)


def _frame_peak(time: np.ndarray, excitation: np.ndarray, sample_rate_hz: float, low_hz: float,
                high_hz: float) -> float:
    """The excitation's spectral peak in a frame between *low_hz* and *high_hz*, Hz."""
    n = len(time)
    padded = 4 * n
    spectrum = np.abs(np.fft.rfft(excitation * np.hanning(n)[:, None], n=padded, axis=0)) ** 2
    frequencies = np.fft.rfftfreq(padded, 1.0 / sample_rate_hz)
    inside = (frequencies >= low_hz) & (frequencies <= high_hz)
    power = spectrum.sum(axis=1)
    coarse = float(frequencies[inside][np.argmax(power[inside])])
    duration = n / sample_rate_hz
    return peak_frequency(time, excitation, coarse, search=min(0.5, 1.0 / (duration * coarse)))


def order_track(record: RigRecord, frame_s: float = 1.0, *, low_hz: float | None = None,
                high_hz: float | None = None) -> OrderTrack:
    """The 1x component of excitation and pylon force along the rotor speed of a run-up record.

    Parameters
    ----------
    record : RigRecord
    frame_s : float
        Frame length, s; frames overlap by half.
    low_hz, high_hz : float, optional
        Band in which the rotor frequency is searched (default: from
        ``MIN_FRAME_PERIODS / frame_s`` to the sample rate over
        :data:`~workbook.rig.correlation.MIN_SAMPLES_PER_PERIOD`), Hz.

    Returns
    -------
    OrderTrack
        Frames in which the rotor turns fewer than :data:`MIN_FRAME_PERIODS`
        times are left out.

    Raises
    ------
    RecordError
        A record shorter than two frames, or no frame with enough periods.
    """
    rate = record.sample_rate_hz
    frame = int(round(frame_s * rate))
    hop = frame // 2
    if frame < 16 or len(record.time) < frame + hop:
        raise RecordError(record.path, f"frames of {frame_s:g} s need at least {(frame + hop) / rate:.4g} s of "
                          f"record; {len(record.time) / rate:.4g} s recorded (a shorter frame)", column="time [s]")
    low = MIN_FRAME_PERIODS / frame_s if low_hz is None else low_hz
    high = rate / MIN_SAMPLES_PER_PERIOD if high_hz is None else high_hz
    starts = np.arange(0, len(record.time) - frame + 1, hop)
    centres = record.time[starts] + (frame - 1) / (2 * rate)
    peaks = np.array([_frame_peak(record.time[s:s + frame], record.excitation[s:s + frame], rate, low, high)
                      for s in starts])
    rotor = np.interp(record.time, centres, peaks)
    phase = 2 * np.pi * np.concatenate([[0.0], np.cumsum((rotor[1:] + rotor[:-1]) / 2) / rate])
    weights = np.hanning(frame)
    signals = np.column_stack([record.excitation, record.pylon])
    phasors = np.empty((len(starts), 6), dtype=complex)
    for index, start in enumerate(starts):
        window = slice(start, start + frame)
        values = signals[window] - signals[window].mean(axis=0)
        rotation = weights * np.exp(-1j * phase[window])
        phasors[index] = 2 * (rotation @ values) / weights.sum()
    kept = peaks * frame_s >= MIN_FRAME_PERIODS
    if not kept.any():
        raise RecordError(record.path, f"no frame of {frame_s:g} s holds {MIN_FRAME_PERIODS} rotor periods "
                          "(a longer frame)", column=f"{EXCITATION_CHANNEL} {DIRECTIONS[0]}")
    excitation = np.array([force_amplitude(p[:3]) for p in phasors])
    return OrderTrack(centres[kept], peaks[kept], excitation[kept], np.abs(phasors[kept, 3:]), frame / rate,
                      record.run, record.path)


def plot_frf(frf: RecordFRF, simulated=None):
    """T per direction (log) and coherence against frequency; with *simulated*, its T too.

    Parameters
    ----------
    frf : RecordFRF
    simulated : tuple of (ndarray, ndarray), optional
        Frequencies (Hz, shape (m,)) and simulated T (shape (m, 3)).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    figure = Figure(figsize=(9, 8), layout="constrained")
    axes = figure.subplots(4, 1, sharex=True, height_ratios=(2, 2, 2, 1.2))
    shown = frf.frequencies_hz > 0
    for axis, direction in enumerate(DIRECTIONS):
        axes[axis].semilogy(frf.frequencies_hz[shown], frf.transmissibility[shown, axis], lw=1, label="H1 (test)")
        if simulated is not None:
            axes[axis].semilogy(simulated[0], simulated[1][:, axis], "k--", lw=1, label="simulated")
        axes[axis].set_ylabel(f"T {direction}")
        axes[-1].plot(frf.frequencies_hz[shown], frf.coherence[shown, axis], lw=1, label=direction)
    for item in axes:
        item.grid(alpha=0.3)
    axes[0].legend(fontsize="small")
    axes[-1].legend(fontsize="small", ncols=3)
    axes[-1].set(xlabel="frequency [Hz]", ylabel="coherence", ylim=(0, 1.05))
    figure.suptitle(f"{frf.path or 'rig record'}: run {frf.run!r}, H1 of pylon force / excitation "
                    f"({frf.averages} averages of {frf.segment_s:g} s)")
    return figure


def plot_order_track(track: OrderTrack, simulated=None):
    """1x amplitudes and T per direction against the rotor frequency; with *simulated*, its T too.

    Parameters
    ----------
    track : OrderTrack
    simulated : tuple of (ndarray, ndarray), optional
        Frequencies (Hz, shape (m,)) and simulated T (shape (m, 3)).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    figure = Figure(figsize=(9, 7), layout="constrained")
    forces, ratios = figure.subplots(2, 1, sharex=True)
    order = np.argsort(track.frequency_hz)
    speed = track.frequency_hz[order]
    forces.semilogy(speed, track.excitation_amplitude[order], color="0.3", ls="-.", lw=1, label="excitation")
    for axis, direction in enumerate(DIRECTIONS):
        forces.semilogy(speed, track.pylon_amplitude[order, axis], lw=1, label=f"pylon {direction}")
        line, = ratios.semilogy(speed, track.transmissibility[order, axis], lw=1, label=f"T {direction} (test)")
        if simulated is not None:
            ratios.semilogy(simulated[0], simulated[1][:, axis], ls="--", lw=1, color=line.get_color(),
                            label=f"T {direction} (simulated)")
    forces.set_ylabel("1x amplitude [N]")
    ratios.set(xlabel="rotor frequency [Hz]", ylabel="T")
    for item in (forces, ratios):
        item.grid(alpha=0.3)
        item.legend(fontsize="small")
    figure.suptitle(f"{track.path or 'rig record'}: run {track.run!r}, 1x order track (frames of {track.frame_s:g} s)")
    return figure
