"""Whether a link's first pinned-pinned frequency shifts by more than a fraction, for many tensions at once.

The stress-stiffening passes stiffen a link whose first pinned-pinned
frequency its tension shifts by more than
:data:`~workbook.solve.stress_stiffening.AUTO_SHIFT`. The lowest eigenvalue
``lambda(P)`` of ``K + P G`` (generalised with M) is the least of the
Rayleigh quotients, each affine in the tension P: it is concave. So
between two neighbouring tensions of a grid it lies above their chord, and
below the chords of the neighbouring intervals drawn on; a tension whose
bounds both fall on one side of the shift's limits is decided without an
eigenvalue problem, the others are solved as before
(:meth:`flexbodies.geometric_stiffness.LinkStiffening.pinned_hz`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from flexbodies.geometric_stiffness import LinkStiffening

__all__ = ["ShiftBracket", "GRID_POINTS", "MARGIN"]

#: Tensions of the grid, from 0.95 of the buckling load in compression to as much in tension.
GRID_POINTS = 129
#: Relative clearance of a bound from a limit for the bound to decide (round-off of the bounds).
MARGIN = 1e-9


@dataclass(frozen=True)
class ShiftBracket:
    """The lowest pinned-pinned eigenvalue of a link on a grid of tensions.

    Attributes
    ----------
    stiffening : flexbodies.geometric_stiffness.LinkStiffening
    tensions : ndarray, shape (m,)
        N, increasing.
    values : ndarray, shape (m,)
        ``lambda`` there, (rad/s)^2.
    unloaded : float
        ``lambda(0)``.
    """

    stiffening: LinkStiffening
    tensions: np.ndarray
    values: np.ndarray
    unloaded: float

    @classmethod
    def of(cls, stiffening: LinkStiffening) -> "ShiftBracket":
        """The bracket of a link's :class:`~flexbodies.geometric_stiffness.LinkStiffening`."""
        reach = 0.95 * float(stiffening.buckling_load)
        tensions = np.linspace(-reach, reach, GRID_POINTS)
        return cls(stiffening, tensions, _eigenvalue(stiffening, tensions), float(_eigenvalue(stiffening, 0.0)))

    def shifted(self, tensions: np.ndarray, fraction: float) -> np.ndarray:
        """Whether the first pinned-pinned frequency at each of *tensions* (N) differs from the unloaded one
        by more than *fraction*, as ``|pinned_hz(P) / pinned_hz(0) - 1| > fraction`` decides it."""
        tensions = np.asarray(tensions, dtype=float)
        grid, values = self.tensions, self.values
        interval = np.clip(np.searchsorted(grid, tensions) - 1, 0, len(grid) - 2)

        def chord(k: np.ndarray) -> np.ndarray:
            """The chord of the intervals *k*, drawn at the tensions."""
            slope = (values[k + 1] - values[k]) / (grid[k + 1] - grid[k])
            return values[k] + slope * (tensions - grid[k])

        lower = chord(interval)
        upper = np.minimum(chord(np.maximum(interval - 1, 0)), chord(np.minimum(interval + 1, len(grid) - 2)))
        inside = (tensions >= grid[0]) & (tensions <= grid[-1]) & (interval >= 1) & (interval <= len(grid) - 3)
        low, high = self.unloaded * (1 - fraction) ** 2, self.unloaded * (1 + fraction) ** 2
        clearance = MARGIN * self.unloaded
        out = inside & ((upper < low - clearance) | (lower > high + clearance))
        within = inside & (lower > low + clearance) & (upper < high - clearance)
        shifted = out.copy()
        rest = np.flatnonzero(~(out | within))
        if len(rest):
            exact = self.stiffening.pinned_hz(tensions[rest], 1)[:, 0] / self.stiffening.pinned_hz(0.0, 1)[0]
            shifted[rest] = np.abs(exact - 1.0) > fraction
        return shifted


def _eigenvalue(stiffening: LinkStiffening, tensions) -> np.ndarray:
    """The lowest pinned-pinned eigenvalue at *tensions* (N), (rad/s)^2, from its signed frequency."""
    frequency = 2 * np.pi * stiffening.pinned_hz(tensions, 1)[..., 0]
    return np.sign(frequency) * frequency ** 2
