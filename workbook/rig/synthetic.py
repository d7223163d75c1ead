"""A synthetic rig record made from a simulated run, for tests and examples.

The steady-state window of a simulated run is written as a Fourier series
of the rotor frequency f0 (mean plus ``harmonics`` harmonics per channel,
by :func:`workbook.answers.amplitude.harmonic_amplitude`; of a frequency-domain
run, its phasors: the 1x response about a zeroed transducer), and re-evaluated at the
rig's sample times with a rotor phase that drifts: the speed changes
linearly by ``drift`` (relative) over the record, its mean staying f0,
``phi(t) = 2 pi f0 (t + drift (t^2 / (2 D) - t / 2))`` for a record of
duration D. Each transducer sums its hinges' forces (on a case with test-rig
transducers, the forces of the case's transducers under those hinges); white noise of
standard deviation ``noise`` x (the largest force amplitude of that
transducer, or of the excitation) is added to each channel. The known
answer is the simulated transmissibility: the drift is slow, so the rig
signal is the steady response at the instantaneous speed.
"""
from __future__ import annotations

import math

import numpy as np

from workbook.answers.amplitude import harmonic_amplitude
from workbook.answers.isolation import pylon_sum
from workbook.answers.results import ExcitationResult
from workbook.model.case import TRANSDUCER_PREFIX
from workbook.rig.correlation import MIN_SAMPLES_PER_PERIOD
from workbook.rig.records import RigRecord

__all__ = ["synthetic_record", "synthetic_records", "broadband_record", "run_up_record", "default_sample_rate", "REFERENCE_TRANSDUCERS",
           "RATE_MARGIN"]

#: A default record samples the highest frequency this many times more
#: often than :data:`~workbook.rig.correlation.MIN_SAMPLES_PER_PERIOD` (at least).
RATE_MARGIN = 1.25

#: The seed study's rig: two front and two rear three-way transducers, named
#: by the pylon-side hinges of the reference mount they carry.
REFERENCE_TRANSDUCERS = {
    "front-left": ("front-up-left",),
    "front-right": ("front-up-right",),
    "rear-left": ("rear-up-left", "rear-up-middle"),
    "rear-right": ("rear-up-right", "rear-up-lateral"),
}


def default_sample_rate(frequencies_hz) -> float:
    """The sample rate at which a record of any of *frequencies_hz* can be measured, Hz.

    The next power of two at or above ``MIN_SAMPLES_PER_PERIOD x RATE_MARGIN
    x max(frequencies_hz)``: 4096 Hz for the reference mount (HP rotor
    248.5 Hz: 16.5 samples per period; LP rotor 59 Hz: 69).

    Parameters
    ----------
    frequencies_hz : iterable of float
        Rotor frequencies of the case's runs, Hz.

    Returns
    -------
    float
        Hz.
    """
    return float(2 ** math.ceil(math.log2(MIN_SAMPLES_PER_PERIOD * RATE_MARGIN * max(frequencies_hz))))


def synthetic_record(result: ExcitationResult, transducers: dict, *, excitation=None, sample_rate_hz: float = 2048.0,
                     duration: float = 4.0, noise: float = 0.005, drift: float = 0.002, harmonics: int = 3,
                     seed: int = 0) -> RigRecord:
    """A rig record of a simulated run with noise and a linear speed drift.

    Parameters
    ----------
    result : ExcitationResult
        A steady simulated run: a time-domain one (its measured window is
        used) or a frequency-domain one (its phasors; give *excitation*).
    transducers : dict of str to sequence of str
        Pylon-side hinges carried by each transducer.
    excitation : SingleFrequencyExcitation, optional
        The run's excitation, whose phasor a frequency-domain run needs.
    sample_rate_hz : float
        Hz.
    duration : float
        Record length, s.
    noise : float
        Noise standard deviation relative to each transducer's largest amplitude.
    drift : float
        Relative change of the rotor speed from start to end of the record.
    harmonics : int
        Harmonics of the rotor frequency kept from a time-domain simulation.
    seed : int
        Seed of the noise generator.

    Returns
    -------
    RigRecord
    """
    f0 = result.frequency_hz
    time = np.arange(int(round(duration * sample_rate_hz))) / sample_rate_hz
    phase = 2 * np.pi * f0 * (time + drift * (time ** 2 / (2 * duration) - time / 2))
    rng = np.random.default_rng(seed)
    if result.has_histories:
        forces, excitation_force = result.hinge_histories, result.excitation_history
    else:
        from workbook.solve.harmonic import excitation_phasor

        forces, excitation_force = result.hinge_phasors, excitation_phasor(excitation)

    def resampled(force: np.ndarray) -> np.ndarray:
        if result.has_histories:
            values, sim_time = force[result.window], result.time[result.window]
            mean = values.mean(axis=0)
            phasors = [harmonic_amplitude(sim_time, values, k * f0) for k in range(1, harmonics + 1)]
        else:
            mean, phasors = np.zeros(3), [force]
        signal = np.broadcast_to(mean, (len(time), len(mean))).copy()
        for k, phasor in enumerate(phasors, start=1):
            signal += np.real(np.exp(1j * k * phase)[:, None] * phasor[None, :])
        return signal + rng.normal(0.0, noise * np.abs(phasors[0]).max(), signal.shape)

    channels = {name: _carrying(result.pylon_hinges, hinges) for name, hinges in transducers.items()}
    return RigRecord(
        time, {name: resampled(pylon_sum(forces, carried)) for name, carried in channels.items()},
        resampled(excitation_force), {name: tuple(hinges) for name, hinges in transducers.items()}, sample_rate_hz,
        f0, result.name,
        notes={"made by": f"workbook.rig.synthetic.synthetic_record from a simulation: noise {noise:g} x amplitude, "
                          f"speed drift {drift:g}, seed {seed}",
               "simulated T x y z": " ".join(f"{t:.6g}" for t in result.transmissibility)})


def synthetic_records(case, result, seeds, *, transducers: dict | None = None, duration: float = 2.0,
                      noise: float = 0.005) -> list[RigRecord]:
    """Noisy records of every run of *result* (the answers of *case*), one per seed and run.

    Sampled at :func:`default_sample_rate` of the case's excitations (every
    rotor can be compared at it); the other parameters as :func:`synthetic_record`.

    Parameters
    ----------
    case : workbook.model.case.Case
    result : workbook.answers.results.MountResult
        Frequency-domain answers of *case*, one run per excitation.
    seeds : iterable of int
    transducers : dict, optional
        Default :data:`REFERENCE_TRANSDUCERS`.
    duration : float
        s.
    noise : float
        Relative to each transducer's largest amplitude.

    Returns
    -------
    list of RigRecord
        Seed by seed, the runs in order.
    """
    rate = default_sample_rate(e.frequency_hz for e in case.excitations)
    return [synthetic_record(run, REFERENCE_TRANSDUCERS if transducers is None else transducers, excitation=excitation,
                             sample_rate_hz=rate, duration=duration, noise=noise, seed=seed)
            for seed in seeds for run, excitation in zip(result.runs, case.excitations, strict=True)]


def _carrying(pylon_channels, hinges) -> list:
    """The force channels that make a transducer carrying *hinges*: the case's test-rig transducers under
    them (named :func:`~workbook.model.case.transducer_name`), else the hinges themselves."""
    rig = [name for name in pylon_channels if name.startswith(TRANSDUCER_PREFIX)]
    if not rig:
        return list(hinges)
    return [name for name in rig if set(name[len(TRANSDUCER_PREFIX):].split(" + ")) <= set(hinges)]


def broadband_record(frf, *, sample_rate_hz: float = 1024.0, duration: float = 64.0, noise: float = 0.0,
                     seed: int = 0, run: str = "broadband") -> RigRecord:
    """A shaker record: independent white-noise excitation per direction through a known FRF.

    The excitation in each direction is Gaussian white noise of unit
    standard deviation (N); the pylon force in direction d is the excitation
    in d filtered by ``frf(f)[:, d]`` (periodic: the FFT of the whole record
    times the FRF at its bins), one transducer ``"pylon"`` carrying the
    hinge ``"pylon"``. White noise of standard deviation *noise* x (the
    pylon force's) is added to each pylon channel.

    Parameters
    ----------
    frf : callable
        ``frf(frequencies_hz)`` -> complex ndarray, shape (n, 3): pylon force
        per unit excitation force per direction.
    sample_rate_hz : float
        Hz.
    duration : float
        s.
    noise : float
        Response noise relative to the response's standard deviation.
    seed : int
    run : str

    Returns
    -------
    RigRecord
    """
    samples = int(round(duration * sample_rate_hz))
    rng = np.random.default_rng(seed)
    excitation = rng.normal(0.0, 1.0, (samples, 3))
    frequencies = np.fft.rfftfreq(samples, 1.0 / sample_rate_hz)
    pylon = np.fft.irfft(np.fft.rfft(excitation, axis=0) * frf(frequencies), n=samples, axis=0)
    pylon += rng.normal(0.0, 1.0, pylon.shape) * noise * pylon.std(axis=0)
    time = np.arange(samples) / sample_rate_hz
    return RigRecord(time, {"pylon": pylon}, excitation, {"pylon": ("pylon",)}, sample_rate_hz,
                     float(sample_rate_hz / MIN_SAMPLES_PER_PERIOD), run,
                     notes={"made by": f"workbook.rig.synthetic.broadband_record: white noise through a known FRF, "
                                       f"response noise {noise:g}, seed {seed}"})


def run_up_record(answer, transducers: dict, *, sample_rate_hz: float = 2048.0, duration: float = 30.0,
                  noise: float = 0.0, seed: int = 0) -> RigRecord:
    """A run-up record from a simulated run-up: the speed rising linearly over the run-up's range.

    The rotor frequency rises linearly from the run-up's first to its last
    speed, ``phi(t) = 2 pi int f dt``; each channel is
    ``Re(X(f(t)) exp(i phi(t)))`` with ``X(f)`` the simulated complex
    amplitude (excitation resultant, each transducer's sum of hinge
    phasors), interpolated linearly in f between the run-up's speeds: the
    quasi-steady response of a slow run-up. White noise of standard
    deviation *noise* x (the channel's largest amplitude) is added.

    Parameters
    ----------
    answer : RunUpAnswer or SweepAnswer
        A frequency-domain answer (its runs keep their hinge phasors).
    transducers : dict of str to sequence of str
        Pylon-side hinges carried by each transducer.
    sample_rate_hz : float
        Hz.
    duration : float
        s.
    noise : float
    seed : int

    Returns
    -------
    RigRecord
    """
    from workbook.solve.harmonic import excitation_phasor

    speeds = answer.frequencies
    time = np.arange(int(round(duration * sample_rate_hz))) / sample_rate_hz
    rotor = speeds[0] + (speeds[-1] - speeds[0]) * time / duration
    phase = 2 * np.pi * (speeds[0] * time + (speeds[-1] - speeds[0]) * time ** 2 / (2 * duration))
    rng = np.random.default_rng(seed)
    rotation = np.exp(1j * phase)[:, None]

    def channel(phasors: np.ndarray) -> np.ndarray:
        values = np.column_stack([np.interp(rotor, speeds, phasors[:, a].real)
                                  + 1j * np.interp(rotor, speeds, phasors[:, a].imag) for a in range(3)])
        signal = np.real(values * rotation)
        return signal + rng.normal(0.0, noise * np.abs(phasors).max(), signal.shape)

    runs = answer.result.runs
    excitation = np.array([excitation_phasor(point) for point in answer.sweep.expand()])
    forces = {name: channel(np.array([sum(run.hinge_phasors[h] for h in hinges) for run in runs]))
              for name, hinges in transducers.items()}
    return RigRecord(time, forces, channel(excitation), {name: tuple(h) for name, h in transducers.items()},
                     sample_rate_hz, float(speeds[-1]), answer.sweep.name,
                     notes={"made by": f"workbook.rig.synthetic.run_up_record from a simulated run-up from "
                                       f"{speeds[0]:g} to {speeds[-1]:g} Hz in {duration:g} s, noise {noise:g}, "
                                       f"seed {seed}"})
