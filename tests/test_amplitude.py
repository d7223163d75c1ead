"""Amplitude extraction on synthetic histories with known answers."""
import numpy as np
import pytest

from workbook.answers.amplitude import amplitude_spectrum, harmonic_amplitude, period_window, steady_amplitude


def sampled(frequency, periods, samples_per_period, start=0.0):
    step = 1.0 / (frequency * samples_per_period)
    return start + step * np.arange(int(round(periods * samples_per_period)) + 1)


def test_amplitude_and_phase_of_offset_sinusoids():
    f = 59.0
    t = sampled(f, 12, 37)[:-1]            # 12 whole periods, 37 samples each
    signals = np.column_stack([5.0 + 3.0 * np.cos(2 * np.pi * f * t + 0.4),
                               -2.0 + 0.5 * np.sin(2 * np.pi * f * t),
                               7.0 + 0 * t])
    phasors = harmonic_amplitude(t, signals, f)
    np.testing.assert_allclose(np.abs(phasors), [3.0, 0.5, 0.0], atol=1e-12)
    assert np.angle(phasors[0]) == pytest.approx(0.4)
    assert np.angle(phasors[1]) == pytest.approx(-np.pi / 2)


def test_other_harmonics_do_not_leak_into_the_bin():
    f = 248.5
    t = sampled(f, 20, 40)[:-1]
    x = 1.0 * np.sin(2 * np.pi * f * t) + 10.0 * np.sin(2 * np.pi * 2 * f * t) + 4.0 * np.cos(2 * np.pi * 0.5 * f * t)
    assert abs(harmonic_amplitude(t, x, f)) == pytest.approx(1.0, abs=1e-10)


def test_period_window_takes_the_last_whole_periods():
    f = 10.0
    t = sampled(f, 7.3, 40)
    window = period_window(t, f, 3)
    assert window.stop == len(t)
    assert (window.stop - window.start) == 120
    before = period_window(t, f, 3, end=window.start)
    assert before.stop == window.start and before.stop - before.start == 120
    with pytest.raises(ValueError, match="needs"):
        period_window(t, f, 8)


def test_steady_check_accepts_steady_and_flags_a_decaying_transient():
    f, fn = 59.0, 4.7
    t = sampled(f, 60, 40)
    steady_signal = 3.0 * np.sin(2 * np.pi * f * t) + 100.0
    result = steady_amplitude(t, steady_signal, f, periods=20)
    assert result.amplitude[0] == pytest.approx(3.0, rel=1e-9)
    assert result.steady and result.relative_change < 1e-9
    # a slowly decaying transient at a mounted-mode frequency changes between windows
    transient = 2.0 * np.exp(-0.5 * t) * np.sin(2 * np.pi * fn * t)
    result = steady_amplitude(t, steady_signal + transient, f, periods=20, tolerance=0.005)
    assert not result.steady
    assert result.relative_change > 0.005


def test_spectrum_peaks_at_the_signal_frequency():
    f = 59.0
    t = sampled(f, 20, 40)[:-1]
    frequencies, amplitudes = amplitude_spectrum(t, 2.5 * np.sin(2 * np.pi * f * t) + 1.0)
    peak = np.argmax(amplitudes)
    assert frequencies[peak] == pytest.approx(f)
    assert amplitudes[peak] == pytest.approx(2.5, rel=1e-9)


def test_non_uniform_sampling_is_refused():
    t = np.array([0.0, 0.1, 0.2, 0.35, 0.4])
    with pytest.raises(ValueError, match="uniformly"):
        period_window(t, 5.0, 1)
