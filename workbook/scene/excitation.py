"""The excitation force as a function of time, for Exudyn and for numpy.

A single-frequency excitation is ``F(t) = r(t) (C cos wt + S sin wt)`` with
constant vectors C and S (see ``force_coefficients`` of the case's
excitations) and a smooth start ``r(t)``: 0 up to t = 0, a raised cosine from
0 to 1 over the ramp time, then 1. (Exudyn's static solver evaluates loads at
its final load-step time: the preload solve ends at t = 0, where the
excitation is exactly zero.) Starting the force smoothly over several periods
leaves the low mounted modes almost unexcited, so the run needs far less
settle time than after a sudden start (measured on a single-DOF model: a
ratio of 25 between excitation and natural frequency needed about 2 decay
time constants after a 10-period ramp, against more than 4 without).

The same law is evaluated by Exudyn as a symbolic user function (C++ speed)
and by numpy for plots and checks. An excitation of several points (the
planes of an :class:`~workbook.model.case.Imbalance`) is one such law per
point (:meth:`ExcitationSignal.at_points`), all with the same start; its
resultant (:meth:`ExcitationSignal.of`) is their sum, the force the
excitation history shows. The parts of a
:class:`~workbook.model.case.Simultaneous` excitation each keep their own
frequency and share the start of the lowest.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from workbook.model.case import Simultaneous, SingleFrequencyExcitation

__all__ = ["ExcitationSignal"]


@dataclass(frozen=True)
class ExcitationSignal:
    """``F(t) = r(t) (C cos wt + S sin wt)`` with a raised-cosine start ``r``.

    Attributes
    ----------
    frequency_hz : float
        Hz.
    cos_part, sin_part : tuple of 3 floats
        C and S, N.
    amplitude : float
        Amplitude of the excitation force, N (the reference of the
        transmissibility).
    ramp_time : float
        Duration of the smooth start, s (0: sudden start).
    """

    frequency_hz: float
    cos_part: tuple
    sin_part: tuple
    amplitude: float
    ramp_time: float

    @classmethod
    def of(cls, excitation: SingleFrequencyExcitation, ramp_periods: float) -> "ExcitationSignal":
        """The resultant signal of a case excitation (the sum over its points),
        starting over *ramp_periods* periods; its amplitude is the excitation's
        ``force_amplitude``."""
        parts = excitation.point_forces()
        cos_part = np.sum([c for _, c, _ in parts], axis=0)
        sin_part = np.sum([s for _, _, s in parts], axis=0)
        frequency = excitation.frequency
        return cls(frequency, tuple(cos_part), tuple(sin_part), excitation.force_amplitude,
                   ramp_periods / frequency)

    @classmethod
    def at_points(cls, excitation: SingleFrequencyExcitation | Simultaneous, ramp_periods: float
                  ) -> tuple[tuple[tuple, "ExcitationSignal"], ...]:
        """``(point, signal)`` of each point force of a case excitation, all
        starting together over *ramp_periods* periods of the lowest
        frequency (the parts of a :class:`Simultaneous` each at its own
        frequency); each signal's amplitude is the largest magnitude its
        force reaches."""
        parts = excitation.parts if isinstance(excitation, Simultaneous) else (excitation,)
        ramp_time = ramp_periods / min(part.frequency for part in parts)
        return tuple((point, cls(part.frequency, tuple(c), tuple(s), float(np.linalg.norm(np.column_stack([c, s]), 2)),
                                 ramp_time))
                     for part in parts for point, c, s in part.point_forces())

    @property
    def omega(self) -> float:
        """Angular frequency, rad/s."""
        return 2 * math.pi * self.frequency_hz

    def ramp(self, time: np.ndarray) -> np.ndarray:
        """The start factor r(t), 0 to 1."""
        time = np.asarray(time, dtype=float)
        if self.ramp_time == 0:
            return np.where(time > 0, 1.0, 0.0)
        rising = 0.5 - 0.5 * np.cos(np.pi * np.clip(time, 0.0, None) / self.ramp_time)
        return np.where(time < self.ramp_time, rising, 1.0)

    def force(self, time: np.ndarray) -> np.ndarray:
        """Force at each time, N, shape (n, 3)."""
        time = np.asarray(time, dtype=float)
        phase = self.omega * time
        steady = (np.outer(np.cos(phase), self.cos_part) + np.outer(np.sin(phase), self.sin_part))
        return self.ramp(time)[:, None] * steady

    def exudyn_user_function(self):
        """A ``loadVectorUserFunction`` for ``LoadForceVector``, written so that
        ``exudyn.advancedUtilities.CreateSymbolicUserFunction`` can record it."""
        import exudyn as exu

        esym = exu.symbolic  # type: ignore[attr-defined]  # the stubs omit the submodule
        omega, ramp_time = self.omega, self.ramp_time
        cos_part, sin_part = self.cos_part, self.sin_part

        def load_vector(mbs, t, loadVector):
            if ramp_time > 0:
                started = esym.max(t, esym.Real(0.0))
                factor = esym.IfThenElse(t < ramp_time, 0.5 - 0.5 * esym.cos(math.pi / ramp_time * started),
                                         esym.Real(1.0))
            else:
                factor = esym.IfThenElse(t > 0, esym.Real(1.0), esym.Real(0.0))
            c, s = esym.cos(omega * t), esym.sin(omega * t)
            return [factor * (cos_part[i] * c + sin_part[i] * s) for i in range(3)]

        return load_vector
