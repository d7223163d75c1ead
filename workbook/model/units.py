"""Units of the sheets: unit cells parsed and converted to SI with pint.

Every quantity column of a sheet has a unit cell (the row under the header).
:func:`si_factor` turns that unit text into the factor to the column's SI
unit, or raises :class:`UnitProblem` when the unit is unknown or of the wrong
dimension ("kg" in a stiffness column).

Two conventions differ from a plain pint conversion:

- ``g`` means *standard gravity* (9.80665 m/s^2) in an acceleration column
  and *gram* everywhere else (a mass, or an unbalance in g mm);
- frequencies count cycles: 1 rpm = 1/60 Hz (pint alone, which counts a
  revolution as 2 pi radians, would give 2 pi/60 Hz).

A dimensionless column takes ``-``, ``1``, an empty cell or ``%``.

A column's own SI unit and the common units of a table of known factors
(mm, kN/mm, t, GPa, rpm, ...) are converted without pint: its registry
takes about half a second to build, and is built only for another unit.
"""
from __future__ import annotations

import functools
import math
import re

from workbook.errors import UnitProblem

__all__ = ["si_factor", "DIMENSIONLESS"]

#: The SI unit text of a dimensionless column.
DIMENSIONLESS = "-"

_G_TOKEN = re.compile(r"(?<![A-Za-z_])g(?![A-Za-z_0-9])")


@functools.lru_cache(maxsize=1)
def registry():
    """The shared pint registry (``pint.UnitRegistry``), made on first use: pint takes a
    noticeable part of a short run's start-up, and a run without unit cells never needs it."""
    import pint

    return pint.UnitRegistry()


def _parse(text: str):
    import tokenize

    import pint

    try:
        return registry().Quantity(1.0, text)
    except (pint.PintError, AssertionError, AttributeError, SyntaxError, TypeError, ValueError,
            tokenize.TokenError, ArithmeticError):    # '(' and 'mm/0' are the text's, not ours
        raise UnitProblem("a known unit") from None


#: The SI unit texts of the sheets' columns: a unit cell holding its column's own SI unit needs no conversion.
_SI_UNITS = frozenset(("1/s", "Hz", "N", "h", "N*m", "N*s/m", "N/m", "Pa", "deg", "kg", "kg*m", "kg*m^2", "kg/m^3", "m",
                       "m/s^2", "s"))

#: (unit text, SI unit) -> the factor pint gives, for the units engineers type most (the template's among
#: them): a sheet written in these needs no pint registry. ``tests/test_warm_paths.py`` checks every entry
#: against pint, to the last bit.
_KNOWN = {
    ("mm", "m"): 0.001, ("cm", "m"): 0.01, ("km", "m"): 1000.0,
    ("GPa", "Pa"): 1e9, ("MPa", "Pa"): 1e6, ("kPa", "Pa"): 1000.0, ("N/mm^2", "Pa"): 1e6,
    ("kN", "N"): 1000.0, ("MN", "N"): 1e6,
    ("kN/mm", "N/m"): 1e6, ("N/mm", "N/m"): 1000.0, ("MN/m", "N/m"): 1e6, ("kN/m", "N/m"): 1000.0,
    ("N*s/mm", "N*s/m"): 1000.0, ("kN*s/m", "N*s/m"): 1000.0,
    ("t", "kg"): 1000.0, ("g", "kg"): 0.001,
    ("kg*mm^2", "kg*m^2"): 1e-06, ("t*m^2", "kg*m^2"): 1000.0,
    ("g*mm", "kg*m"): 1e-06, ("kg*mm", "kg*m"): 0.001,
    ("g/cm^3", "kg/m^3"): 999.9999999999999, ("t/m^3", "kg/m^3"): 1000.0,
    ("kN*m", "N*m"): 1000.0, ("N*mm", "N*m"): 0.001,
    ("ms", "s"): 0.001, ("rpm", "Hz"): 0.016666666666666666, ("kHz", "Hz"): 1000.0,
    ("1/min", "1/s"): 0.016666666666666666,
    ("g", "m/s^2"): 9.80665, ("rad", "deg"): 57.29577951308232, ("%", DIMENSIONLESS): 0.01,
}


@functools.lru_cache(maxsize=None)
def si_factor(text: str, si_unit: str) -> float:
    """Factor from the unit *text* to the column's *si_unit*.

    Parameters
    ----------
    text : str
        The unit cell's text, e.g. ``"mm"``, ``"kN/mm"``, ``"rpm"``, ``"t"``.
    si_unit : str
        The column's SI unit, e.g. ``"m"``, ``"N/m"``, ``"Hz"``, or
        :data:`DIMENSIONLESS`.

    Returns
    -------
    float
        Multiply a cell value by this to get it in *si_unit*.

    Raises
    ------
    UnitProblem
        Unknown unit, or a unit of another dimension.
    """
    text = text.strip()
    if text == si_unit and si_unit in _SI_UNITS:
        return 1.0
    known = _KNOWN.get((text, si_unit))
    if known is not None:
        return known
    return _pint_factor(text, si_unit)


def _pint_factor(text: str, si_unit: str) -> float:
    """:func:`si_factor` by pint, for a stripped *text*."""
    if si_unit == DIMENSIONLESS:
        if text in ("", "-", "1"):
            return 1.0
        target = "dimensionless"
    else:
        target = si_unit
        if not text:
            raise UnitProblem(f"a unit of {_dimension_words(si_unit)} (e.g. {si_unit})")
    expected = f"a unit of {_dimension_words(si_unit)} (e.g. {si_unit})"
    if registry().Quantity(1.0, target).check("[acceleration]"):
        text = _G_TOKEN.sub("g0", text)
    quantity = _parse(text)
    if registry().Quantity(1.0, target).check("[frequency]"):
        # a revolution is one cycle: count turns, not radians
        root = quantity.to_root_units()
        if root.units == registry().Unit("radian / second"):
            quantity = quantity.to("turn / second").magnitude * registry().Unit("1 / second")
    import pint

    try:
        factor = float(quantity.to(target).magnitude)
    except pint.DimensionalityError:
        raise UnitProblem(expected) from None
    if not math.isfinite(factor) or factor == 0:
        raise UnitProblem(expected)
    return factor


_WORDS = {"m": "length", "kg": "mass", "N": "force", "N/m": "stiffness", "N*s/m": "damping",
          "Hz": "frequency", "s": "time", "1/s": "rate", "kg*m^2": "moment of inertia",
          "Pa": "modulus", "kg/m^3": "density", "m/s^2": "acceleration", "N*m": "moment",
          "kg*m": "unbalance", "deg": "angle"}


def _dimension_words(si_unit: str) -> str:
    if si_unit == DIMENSIONLESS:
        return "no dimension ('-')"
    return _WORDS.get(si_unit) or str(registry().Quantity(1.0, si_unit).dimensionality)
