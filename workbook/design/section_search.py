"""The link section scale as a design variable: the grid of scales and the search over it.

A section scale changes the links' geometry, so every scale needs a new
Craig-Bampton reduction of each distinct link and a new linear mount: it
cannot be a variable of the gradient optimisation on the fast path. The
optimiser searches it outside: the scales are the points of a grid over the
variable's range (:func:`section_grid`, a step of at most *step*, so that a
scale tried once is found in the disk reduction cache the next time), and
the best of them is found by a golden-section search on the grid's indices
(:func:`grid_minimum`), each point asked once, the inner optimisation of the
fast variables run at every point asked.
"""
from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from workbook.errors import InputError

__all__ = ["SECTION", "SECTION_STEP", "section_grid", "grid_minimum"]

#: The study parameter of the links' section scale.
SECTION = "section_scale"
#: Default largest step between the section scales tried (the search's tolerance).
SECTION_STEP = 0.02
#: The golden section's smaller part, (3 - sqrt 5) / 2.
_GOLDEN = (3 - math.sqrt(5)) / 2


def section_grid(low: float, high: float, step: float = SECTION_STEP) -> np.ndarray:
    """The section scales a search tries from: evenly spaced over [low, high], at most *step* apart.

    Raises
    ------
    InputError
        A step that is not positive.
    """
    if not step > 0:
        raise InputError(f"section step: found {step:g}, expected a positive step of the section scale")
    count = int(math.ceil((high - low) / step - 1e-9)) + 1
    return np.round(np.linspace(low, high, max(count, 2)), 12)


def grid_minimum(count: int, key: Callable[[int], Any]) -> int:
    """The index in ``range(count)`` of the least ``key(index)``, by golden-section search.

    Exact for a *key* that falls, then rises over the indices (unimodal);
    each index is asked once. The last three to four indices are all asked,
    ties going to the lower index.

    Parameters
    ----------
    count : int
        At least 1.
    key : callable
        ``key(index)``, any ordered value.

    Returns
    -------
    int
    """
    known: dict[int, Any] = {}

    def at(index: int) -> Any:
        if index not in known:
            known[index] = key(index)
        return known[index]

    low, high = 0, count - 1
    inner = low + round(_GOLDEN * (high - low))
    while high - low > 3:
        left, right = sorted((inner, low + high - inner))
        if left == right:
            right += 1
        if at(left) <= at(right):
            high, inner = right, left
        else:
            low, inner = left, right
    return min(range(low, high + 1), key=lambda index: (at(index), index))
