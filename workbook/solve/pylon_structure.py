"""A pylon structure's compliance at the pins, from its (reduced) stiffness and mass.

``D(w) = K (1 + i eta) - w^2 M`` with the structural loss factor eta, and
the compliance (receptance) at the pins ``G(w) = T D^-1 T^T``: pin motion
per force on the pylon at the pins, coupled through the structure, shape
(3 p, 3 p). The box beam (:mod:`workbook.solve.pylon_beam`) and the
reduced mesh (:mod:`workbook.solve.pylon_mesh`) both close the four-pole
set this way.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

__all__ = ["PylonStructure"]


@dataclass(frozen=True)
class PylonStructure:
    """A clamped pylon's matrices and its pin map.

    Attributes
    ----------
    stiffness, mass : ndarray, shape (n, n)
        Free DOF (the clamped ones removed): N/m (N m/rad for rotations) and
        kg (kg m^2).
    pin_map : ndarray, shape (3 p, n)
        Pin translations per DOF.
    loss_factor : float
    """

    stiffness: np.ndarray
    mass: np.ndarray
    pin_map: np.ndarray
    loss_factor: float

    def compliance(self, frequencies_hz) -> np.ndarray:
        """``G`` at each frequency, complex, shape (f, 3 p, 3 p), m/N."""
        result = []
        for frequency in np.atleast_1d(np.asarray(frequencies_hz, dtype=float)):
            omega = 2 * np.pi * frequency
            dynamic = self.stiffness * (1 + 1j * self.loss_factor) - omega ** 2 * self.mass
            result.append(self.pin_map @ sla.solve(dynamic, self.pin_map.T.astype(complex), check_finite=False))
        return np.array(result)
