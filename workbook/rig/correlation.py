"""Test correlation: transmissibility measured on the rig, compared with simulation.

The measured answers go through the same amplitude extraction as the
simulated ones (:mod:`workbook.answers.amplitude`): the rotor frequency is the
spectral peak of the excitation force next to the nominal one (the rotor
speed drifts on a rig; the peak is searched over the whole record, then
refined over the two windows measured), and at that frequency the last window of
``periods`` whole periods gives, by a least-squares fit of a mean and a
sinusoid at that frequency (:func:`~workbook.answers.amplitude.harmonic_amplitudes`),
the pylon-force amplitude per direction (vector sum of the transducers) and
the excitation amplitude; the window before it checks (by single-bin DFT)
that the record is steady. The fit, not a single-bin DFT, measures the
amplitudes: a window of whole samples spans whole periods only to within a
sample, and a DFT over it takes in the negative-frequency image by an amount
that depends on each channel's phase, which does not cancel in T (0.1 to
0.2 % in records of the reference mount at 16 to 70 samples per period). Then (docs/physics.md, section 5)::

    T_d = |F_pylon,d(f)| / |F_exc(f)|,   eta_d = (1 - T_d) 100 %,
    error = (sim - test) / test x 100 %.

``|F_exc|`` is the largest amplitude of the excitation force vector over a
period (the semi-major axis of its ellipse): the rotating force's magnitude,
or a harmonic force's amplitude, as in the simulation.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from workbook.answers.amplitude import harmonic_amplitude, harmonic_amplitudes, period_window, steady_amplitude
from workbook.answers.isolation import efficiency, relative_error
from workbook.answers.results import ExcitationResult, PylonAnswers
from workbook.errors import RecordError
from workbook.model.case import DIRECTIONS
from workbook.rig.records import RigRecord

__all__ = ["Measurement", "measure", "peak_frequency", "force_amplitude", "comparison_frame",
           "MIN_SAMPLES_PER_PERIOD", "PEAK_SEARCH", "MIN_EXCITATION_SHARE", "MIN_EXCITATION_RESOLUTION"]

log = logging.getLogger(__name__)

#: A record must sample each rotor period at least this often.
MIN_SAMPLES_PER_PERIOD = 10
#: The peak is searched within this fraction of the nominal frequency.
PEAK_SEARCH = 0.02
#: Least share of the excitation channels' fluctuation (sqrt(2) times their RMS about the mean: the
#: amplitude of a pure sinusoid) that ``|F_exc|`` at the rotor frequency must carry.
MIN_EXCITATION_SHARE = 0.1
#: ... and of their largest absolute value (a constant channel fluctuates by its round-off alone).
MIN_EXCITATION_RESOLUTION = 1e-6


@dataclass(frozen=True)
class Measurement(PylonAnswers):
    """Answers of one rig record.

    Attributes
    ----------
    run : str
    nominal_hz : float
        Nominal rotor frequency, Hz.
    frequency_hz : float
        Rotor frequency found (spectral peak next to the nominal one), Hz.
    periods : int
        Whole periods per window.
    excitation_amplitude : float
        ``|F_exc|``, N.
    pylon_amplitude : ndarray, shape (3,)
        Pylon force amplitude per direction, N.
    transducer_amplitudes : dict of str to ndarray, shape (3,)
        Amplitude of each transducer, N.
    steady_change : float
        Largest relative change of the amplitudes between the last two windows.
    """

    run: str
    nominal_hz: float
    frequency_hz: float
    periods: int
    excitation_amplitude: float
    pylon_amplitude: np.ndarray
    transducer_amplitudes: dict
    steady_change: float


def force_amplitude(phasors: np.ndarray) -> float:
    """Largest magnitude over a period of the force ``Re(X exp(i w t))``, N.

    Parameters
    ----------
    phasors : ndarray, complex, shape (3,)
        Complex amplitude X of each force component.
    """
    return float(np.linalg.svd(np.column_stack([phasors.real, phasors.imag]), compute_uv=False)[0])


def peak_frequency(time: np.ndarray, signals: np.ndarray, nominal_hz: float, search: float = PEAK_SEARCH) -> float:
    """Frequency of the spectral peak of *signals* next to *nominal_hz*.

    The summed power of the single-bin DFTs over the whole history is scanned
    on a grid of a tenth of the DFT resolution within ``nominal (1 +- search)``,
    then the best grid point is refined.

    Parameters
    ----------
    time : ndarray, shape (n,)
        s.
    signals : ndarray, shape (n, k)
    nominal_hz : float
        Hz.
    search : float
        Half-width of the search band relative to *nominal_hz*.

    Returns
    -------
    float
        Hz.
    """
    duration = time[-1] - time[0]

    def power(f):
        return -float(np.sum(np.abs(harmonic_amplitude(time, signals, f)) ** 2))

    grid = np.arange(nominal_hz * (1 - search), nominal_hz * (1 + search), 0.1 / duration)
    best = grid[np.argmin([power(f) for f in grid])]
    step = 0.1 / duration
    return float(minimize_scalar(power, bounds=(best - step, best + step), method="bounded",
                                 options={"xatol": 1e-6 * nominal_hz}).x)


def measure(record: RigRecord, periods: int, *, nominal_hz: float | None = None,
            search: float = PEAK_SEARCH) -> Measurement:
    """Measured amplitudes and transmissibility of a rig record.

    Parameters
    ----------
    record : RigRecord
    periods : int
        Whole rotor periods per window; the record must hold two windows.
    nominal_hz : float, optional
        Nominal rotor frequency (default: the record's), Hz.
    search : float
        Half-width of the band searched for the peak, relative to the
        nominal frequency; 0 takes the DFT at the nominal frequency.

    Returns
    -------
    Measurement

    Raises
    ------
    RecordError
        Sampled too coarsely for the rotor frequency, too short for two
        windows of *periods* periods, or without an excitation at the rotor
        frequency to divide by (:data:`MIN_EXCITATION_SHARE`, :data:`MIN_EXCITATION_RESOLUTION`).
    """
    nominal = record.nominal_hz if nominal_hz is None else nominal_hz
    per_period = record.sample_rate_hz / nominal
    if per_period < MIN_SAMPLES_PER_PERIOD:
        raise RecordError(record.path, f"sample rate {record.sample_rate_hz:g} Hz gives {per_period:.1f} samples "
                          f"per period at {nominal:g} Hz; at least {MIN_SAMPLES_PER_PERIOD} needed "
                          f"({MIN_SAMPLES_PER_PERIOD * nominal:g} Hz)", column="time [s]")
    duration = len(record.time) / record.sample_rate_hz
    needed = 2 * periods / (nominal * (1 - search))
    if duration < needed:
        raise RecordError(record.path, f"too short: {duration:.4g} s recorded, two windows of {periods} periods "
                          f"at {nominal:g} Hz need {needed:.4g} s", column="time [s]")
    frequency = nominal
    if search > 0:  # the peak over the whole record, then over the two windows measured at it (speed drift)
        frequency = peak_frequency(record.time, record.excitation, nominal, search)
        span = slice(period_window(record.time, frequency, 2 * periods).start, None)
        frequency = peak_frequency(record.time[span], record.excitation[span], frequency, search)
    names = list(record.transducers)
    signals = np.column_stack([record.pylon, record.excitation, *record.transducers.values()])
    steady = steady_amplitude(record.time, signals, frequency, periods)
    window = steady.window
    # least squares at the frequency: a window of whole samples is not one of whole periods, and a single-bin
    # DFT would take in the negative-frequency image by an amount that depends on each channel's phase
    phasors = harmonic_amplitudes(record.time[window], signals[window], [frequency])[0]
    excitation = force_amplitude(phasors[3:6])
    fluctuation = float(np.sqrt(2 * np.sum(np.var(record.excitation[window], axis=0))))
    largest = float(np.abs(record.excitation[window]).max())
    if not excitation > max(MIN_EXCITATION_SHARE * fluctuation, MIN_EXCITATION_RESOLUTION * largest):
        raise RecordError(record.path, f"no excitation at the rotor frequency to divide by: |F_exc| at "
                          f"{frequency:.6g} Hz is {excitation:.3g} N, against {fluctuation:.3g} N of fluctuation "
                          f"(at least {MIN_EXCITATION_SHARE:g} of it needed) and values up to {largest:.3g} N in the "
                          "excitation channels; check that they are connected, scaled and recorded")
    amplitudes = np.abs(phasors)
    log.info("%s: rotor at %.4f Hz (nominal %g Hz), windows differ by %.2f %%", record.run, frequency, nominal,
             100 * steady.relative_change)
    return Measurement(record.run, nominal, frequency, periods, excitation, amplitudes[:3],
                       {name: amplitudes[6 + 3 * i:9 + 3 * i] for i, name in enumerate(names)},
                       steady.relative_change)


def comparison_frame(measurement: Measurement, simulated: ExcitationResult):
    """The validation table: simulated and measured T and eta per direction, with the error.

    Parameters
    ----------
    measurement : Measurement
    simulated : ExcitationResult
        The simulated run of the same excitation.

    Returns
    -------
    pandas.DataFrame
        Index: direction; columns ``T sim``, ``T test``, ``error %`` (of T,
        (sim - test) / test x 100), ``eta sim %``, ``eta test %``.
    """
    import pandas as pd

    sim, test = simulated.transmissibility, measurement.transmissibility
    return pd.DataFrame({"T sim": sim, "T test": test, "error %": relative_error(sim, test),
                         "eta sim %": efficiency(sim), "eta test %": efficiency(test)},
                        index=pd.Index(DIRECTIONS, name="direction"))
