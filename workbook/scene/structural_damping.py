"""Loss-factor (structural, hysteretic) damping and its viscous equivalent.

A loss factor eta makes a stiffness k act as ``k (1 + i eta)``: the damping
force is in phase with the velocity and its amplitude ``eta k |u|`` does not
grow with the frequency, as in bolted metal joints and most materials. The
frequency domain uses that complex stiffness exactly. A time integration
cannot (a complex stiffness has no time-domain counterpart for an arbitrary
motion); it gets the viscous damping that dissipates the same energy per
cycle at one frequency,

    d = eta k / omega,

which gives the same steady state at that frequency, and only there (below
it the viscous damper is stronger than the loss factor, above it weaker).
"""
from __future__ import annotations

import math

__all__ = ["equivalent_viscous_damping"]


def equivalent_viscous_damping(loss_factor: float, stiffness: float, frequency_hz: float) -> float:
    """Viscous damping equivalent to a loss factor at one frequency.

    Parameters
    ----------
    loss_factor : float
        eta, dimensionless.
    stiffness : float
        k, N/m (or any stiffness unit: the result is in that unit times s).
    frequency_hz : float
        The frequency at which the two agree, Hz (> 0).

    Returns
    -------
    float
        ``eta k / (2 pi f)``, N s/m.
    """
    if not frequency_hz > 0:
        raise ValueError(f"the loss factor's viscous equivalent needs a frequency > 0 Hz, got {frequency_hz}")
    return loss_factor * stiffness / (2 * math.pi * frequency_hz)
