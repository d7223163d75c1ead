"""Checks of single fields that several parts of a case share: a value found, or a CaseError naming it."""
from __future__ import annotations

import math

from workbook.errors import CaseError

__all__ = ["positive_number", "finite_point", "bounded_count", "MAX_SWEEP_POINTS", "MAX_MODE_COUNT"]

#: Most frequencies of one sweep, or speeds of one run-up: each is a solve of its own (a time-domain point
#: takes seconds), and a longer list is a slip (1e6 typed for 100) whose building alone costs minutes and
#: gigabytes.
MAX_SWEEP_POINTS = 10_000
#: Most fixed-interface modes a link or the casing keeps by count (the low-frequency rule keeps tens; a
#: reduction with thousands of modes is no longer a reduction).
MAX_MODE_COUNT = 1_000


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


def bounded_count(item: str, name: str, value, minimum: int, maximum: int, what: str) -> int:
    """*value* as a whole number from *minimum* to *maximum*, or a CaseError naming *item*, *name*, the
    value and the bounds (*what*: what the bound is, in words, e.g. 'the most points a sweep takes')."""
    try:
        whole = not isinstance(value, bool) and float(value).is_integer()
    except (TypeError, ValueError, OverflowError):
        whole = False
    if not (whole and minimum <= value <= maximum):
        raise CaseError(item, name, value, f"a whole number from {minimum} to {maximum:,} ({what})")
    return int(value)
