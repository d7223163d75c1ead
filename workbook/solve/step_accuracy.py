"""How far the time integrator's steady answer is from the exact one, and
the step that keeps it close enough.

Exudyn's generalized-alpha (Arnold and Bruls: an algorithmic acceleration
``a`` beside the true one, ``(1 - am) a+ + am a = (1 - af) u''+ + af u''``,
Newmark updates of u and u' with ``a``, the equations of motion met at
each new step) integrates a harmonically forced linear mode
``m u'' + c u' + k u = F exp(i W t)`` into a discrete steady state
``u_n = U_h exp(i W n h)``. Every relation is linear in the phasors with
``z = exp(i W h)``, so ``U_h`` is a closed form; its ratio to the exact
``U = F / (k - m W^2 + i c W)`` is the integrator's error on that mode's
contribution to the answer. Near a lightly damped mode the integrator's
period error detunes the peak: the error grows with the period error over
the damping ratio (a mode at 4.7 Hz with zeta 0.29 %, excited on it at 40
steps per period: 17 % low), which is why the step must follow from the
modes near the excitation, not from the excitation alone.
"""
from __future__ import annotations

import numpy as np

__all__ = ["response_ratio", "amplitude_error", "steps_for_accuracy", "MAX_STEPS_PER_PERIOD", "ACCURACY_LIMIT",
           "ACCURACY_TARGET"]

#: Estimated relative amplitude error of the integrator above which a
#: time-domain result warns (a linear scene's time-domain answer must not be
#: silently further than this from the frequency domain's).
ACCURACY_LIMIT = 0.01
#: The error the recommended steps per period keep to.
ACCURACY_TARGET = ACCURACY_LIMIT / 2

#: Steps per excitation period beyond which a time-domain run is not raised
#: further (the frequency domain answers a linear scene exactly).
MAX_STEPS_PER_PERIOD = 5120


def _parameters(spectral_radius: float) -> tuple[float, float, float, float]:
    rho = spectral_radius
    alpha_m, alpha_f = (2 * rho - 1) / (rho + 1), rho / (rho + 1)
    gamma = 0.5 + alpha_f - alpha_m
    return alpha_m, alpha_f, gamma, 0.25 * (gamma + 0.5) ** 2


def response_ratio(natural_hz, damping_ratio, frequency_hz: float, step: float, spectral_radius: float):
    """Steady discrete response of generalized-alpha over the exact one.

    Parameters
    ----------
    natural_hz : float or ndarray
        Undamped natural frequency of the mode, Hz (> 0).
    damping_ratio : float or ndarray
        Its damping ratio.
    frequency_hz : float
        Excitation frequency, Hz.
    step : float
        Time step, s.
    spectral_radius : float
        rho_infinity of the integrator, 0 to 1.

    Returns
    -------
    complex or ndarray of complex
        ``U_h / U``: 1 for a perfect integrator.
    """
    alpha_m, alpha_f, gamma, beta = _parameters(spectral_radius)
    omega_n = 2 * np.pi * np.asarray(natural_hz, dtype=float)
    omega = 2 * np.pi * frequency_hz
    z = np.exp(1j * omega * step)
    # a = r u''; u' = q u''; u = g u'' (per unit of the true acceleration phasor)
    r = ((1 - alpha_f) * z + alpha_f) / ((1 - alpha_m) * z + alpha_m)
    q = step * ((1 - gamma) + gamma * z) * r / (z - 1)
    g = (step * q + step ** 2 * ((0.5 - beta) + beta * z) * r) / (z - 1)
    # unit mass: u'' + 2 zeta w_n u' + w_n^2 u = 1
    discrete = g / (1 + 2 * np.asarray(damping_ratio) * omega_n * q + omega_n ** 2 * g)
    exact = 1 / (omega_n ** 2 - omega ** 2 + 2j * np.asarray(damping_ratio) * omega_n * omega)
    return discrete / exact


def amplitude_error(modes, frequency_hz: float, steps_per_period: int, spectral_radius: float):
    """Largest relative amplitude error of the integrator over *modes*.

    Returns
    -------
    error : float
        ``max |U_h / U - 1|`` over the modes (0 without modes).
    mode : workbook.solve.modes.Mode or None
        The mode where it occurs.
    """
    if not modes:
        return 0.0, None
    step = 1.0 / (frequency_hz * steps_per_period)
    errors = np.abs(response_ratio([m.frequency_hz for m in modes], [m.damping_ratio for m in modes],
                                   frequency_hz, step, spectral_radius) - 1)
    worst = int(np.argmax(errors))
    return float(errors[worst]), modes[worst]


def steps_for_accuracy(modes, frequency_hz: float, steps_per_period: int, spectral_radius: float,
                       target: float) -> int:
    """The fewest steps per period, from *steps_per_period* up by doubling,
    whose :func:`amplitude_error` is at most *target*; at most
    :data:`MAX_STEPS_PER_PERIOD` (the caller then reports the error left)."""
    steps = steps_per_period
    while steps < MAX_STEPS_PER_PERIOD and amplitude_error(modes, frequency_hz, steps, spectral_radius)[0] > target:
        steps = min(2 * steps, MAX_STEPS_PER_PERIOD)
    return steps
