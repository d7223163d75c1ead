"""Checks of single fields that several parts of a case share: a value found, or a CaseError naming it."""
from __future__ import annotations

import math

from workbook.errors import CaseError

__all__ = ["positive_number", "finite_point"]


def positive_number(item: str, name: str, value) -> float:
    """*value* as a finite float > 0, or a CaseError naming *item* and *name*."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if isinstance(value, bool) or not (math.isfinite(number) and number > 0):
        raise CaseError(item, name, value, "a finite number > 0")
    return number


def finite_point(item: str, name: str, value) -> tuple:
    """*value* as three finite floats (x, y, z), or a CaseError naming *item* and *name*."""
    try:
        point = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        point = ()
    if len(point) != 3 or not all(math.isfinite(v) for v in point):
        raise CaseError(item, name, value, "three finite numbers (x, y, z), m")
    return point
