"""Checks of single fields, the one vocabulary of every part of a case: a value found, or a CaseError naming it.

Every check takes ``(item, name, value, ...)``: the item at fault (``"hinge 'front-up-left'"``), the
field's name and the value found, and returns the value in its normal form.
"""
from __future__ import annotations

import math
from typing import Any

from workbook.errors import CaseError

__all__ = ["number", "positive_number", "vector3", "pair", "direction", "per_direction", "nonempty_name",
           "bounded_count", "MAX_SWEEP_POINTS", "MAX_MODE_COUNT", "HINGE_DIRECTIONS"]

#: Most frequencies of one sweep, or speeds of one run-up: each is a solve of its own (a time-domain point
#: takes seconds), and a longer list is a slip (1e6 typed for 100) whose building alone costs minutes and
#: gigabytes.
MAX_SWEEP_POINTS = 10_000
#: Most fixed-interface modes a link or the casing keeps by count (the low-frequency rule keeps tens; a
#: reduction with thousands of modes is no longer a reduction).
MAX_MODE_COUNT = 1_000
#: Names of a hinge's three directions (:attr:`workbook.model.case.Hinge.frame`).
HINGE_DIRECTIONS = ("radial 1", "radial 2", "axial")


def number(item: str, name: str, value: Any, *, minimum: float = -math.inf, strictly: bool = False) -> float:
    """*value* as a finite float at or above *minimum* (above it if *strictly*), or a CaseError."""
    if isinstance(value, bool):
        raise CaseError(item, name, value, "a number")
    try:
        found = float(value)
    except (TypeError, ValueError):
        raise CaseError(item, name, value, "a number") from None
    too_small = found <= minimum if strictly else found < minimum
    if not math.isfinite(found) or too_small:
        bound = f"{'>' if strictly else '>='} {minimum:g}" if minimum > -math.inf else "finite"
        raise CaseError(item, name, value, f"a number {bound}")
    return found


def positive_number(item: str, name: str, value: Any) -> float:
    """*value* as a finite float > 0, or a CaseError."""
    return number(item, name, value, minimum=0.0, strictly=True)


def vector3(item: str, name: str, value: Any) -> tuple[float, float, float]:
    """*value* as three finite floats, or a CaseError."""
    try:
        vector = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        raise CaseError(item, name, value, "three numbers") from None
    if len(vector) != 3 or not all(math.isfinite(v) for v in vector):
        raise CaseError(item, name, value, "three finite numbers")
    return vector[0], vector[1], vector[2]


def pair(item: str, name: str, value: Any, *, strictly: bool) -> tuple[float, float]:
    """*value* as two finite floats (radial, axial), each >= 0 (> 0 if *strictly*), or a CaseError."""
    try:
        found = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        found = ()
    if len(found) != 2 or not all(math.isfinite(v) and (v > 0 if strictly else v >= 0) for v in found):
        raise CaseError(item, name, value, f"two numbers (radial, axial) {'> 0' if strictly else '>= 0'}")
    return found[0], found[1]


def direction(item: str, name: str, value: Any) -> tuple[float, float, float]:
    """*value* as three finite floats, not all zero, or a CaseError."""
    vector = vector3(item, name, value)
    if not any(vector):
        raise CaseError(item, name, value, "a non-zero direction")
    return vector


def per_direction(item: str, name: str, value: Any, *, minimum: float,
                  strictly: bool) -> float | tuple[float, ...]:
    """*value* as one number or three (one per :data:`HINGE_DIRECTIONS`), each at or above *minimum*
    (above it if *strictly*), or a CaseError.

    A bad one of three is named ``"<name>[<direction>]"``, e.g. ``"stiffness[axial]"``.
    """
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        return number(item, name, value, minimum=minimum, strictly=strictly)
    values = tuple(value)
    if len(values) != 3:
        raise CaseError(item, name, value, f"one number or three ({', '.join(HINGE_DIRECTIONS)}); "
                                           f"{len(values)} given")
    return tuple(number(item, f"{name}[{direction}]", v, minimum=minimum, strictly=strictly)
                 for v, direction in zip(values, HINGE_DIRECTIONS, strict=True))


def nonempty_name(item: str, value: Any) -> str:
    """*value* as the name of *item*: a text that is not blank, or a CaseError."""
    if not isinstance(value, str) or not value.strip():
        raise CaseError(item, "name", value, "a non-empty text")
    return value


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
