"""The isolation formulas: pylon-force sum, transmissibility, isolation
efficiency, level in dB and relative error.

Definitions (docs/physics.md, section 5), per direction d in x, y, z:

- pylon force: the vector sum of the pylon-side hinge forces, or of the test
  rig's transducer forces when the case has them;
- transmissibility ``T_d = |F_d(f)| / |F_exc(f)|`` with ``|F_exc|`` the
  amplitude of the excitation force;
- isolation efficiency ``eta_d = (1 - T_d) * 100 %``;
- level ``20 log10(T_d)`` dB;
- relative error of a value against a reference ``(value - reference) /
  reference * 100 %`` (simulation against test, a rung against the
  reference rung).
"""
from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

__all__ = ["pylon_sum", "transmissibility", "efficiency", "level_db", "relative_error"]


def pylon_sum(forces: Mapping[str, np.ndarray], channels: Iterable[str]) -> np.ndarray:
    """The pylon force: the vector sum of the forces of *channels*.

    Parameters
    ----------
    forces : mapping of str to array, shape (..., 3)
        Force per hinge or transducer, N: a static force (3,), a history
        (n, 3) or a phasor (3,) (complex).
    channels : iterable of str
        The pylon-side hinges or the rig's transducers.

    Returns
    -------
    ndarray, shape (..., 3)
        N.

    Raises
    ------
    ValueError
        No channel given: a mount without pylon-side hinges has no pylon force.
    """
    parts = [np.asarray(forces[name]) for name in channels]
    if not parts:
        raise ValueError("no pylon-side hinge or transducer: the pylon force is undefined")
    return np.sum(parts, axis=0)


def transmissibility(amplitude: np.ndarray, excitation_amplitude: float) -> np.ndarray:
    """``T = |F| / |F_exc|`` per direction (amplitudes in N)."""
    return np.asarray(amplitude) / excitation_amplitude


def efficiency(transmissibility: np.ndarray) -> np.ndarray:
    """Isolation efficiency (1 - T) * 100, %."""
    return (1.0 - np.asarray(transmissibility)) * 100.0


def level_db(transmissibility: np.ndarray) -> np.ndarray:
    """20 log10(T), dB (-inf for T = 0)."""
    with np.errstate(divide="ignore"):
        return 20.0 * np.log10(np.asarray(transmissibility, dtype=float))


def relative_error(value: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """(value - reference) / reference * 100, %."""
    reference = np.asarray(reference)
    return (np.asarray(value) - reference) / reference * 100.0
