"""What an input field is, said once: its unit, bound, description and sheet column.

A field of a case dataclass carries a :class:`FieldSpec` in its metadata
(``field(metadata=spec(...))``). From it :func:`check_fields` validates and
normalises the field (through the checks of :mod:`workbook.model.fields`, so
the messages are theirs), :func:`documented` writes the class docstring's
Parameters section, and :mod:`workbook.excel.layout` takes the sheet
column's SI unit and help line.
"""
from __future__ import annotations

import dataclasses
import inspect
import math
import textwrap
from dataclasses import dataclass
from typing import Any, Literal, TypeVar

from workbook.errors import CaseError
from workbook.model import fields
from workbook.model.units import DIMENSIONLESS

__all__ = ["FieldSpec", "spec", "field_spec", "check_fields", "documented"]

#: How a field is checked: a number, three numbers, a non-zero direction, one number or three (one per
#: direction of a hinge frame), two numbers (radial, axial; *minimum* 0), True or False, one of the spec's
#: choices; ``"own"``: by the class's own code (the spec only describes it).
Check = Literal["number", "vector3", "direction", "per_direction", "pair", "flag", "choice", "own"]

_METADATA_KEY = "spec"
#: Keeps a bound (``> 0``) on one line of the docstring.
_GLUE = "\u00a0"
_T = TypeVar("_T")


@dataclass(frozen=True)
class FieldSpec:
    """The description of one input field.

    Attributes
    ----------
    doc : str
        What the field is, for the docstring (its unit and bound are added).
    type : str
        The numpydoc type, e.g. ``"float"`` or ``"3 floats"``.
    check : str
        How :func:`check_fields` checks it (:data:`Check`).
    unit : str or None
        SI unit as a sheet writes it (``"N*s/m"``; :data:`DIMENSIONLESS` for a
        number without dimension); None for a field that is not a quantity.
    minimum : float
        Smallest value (of each component); ``-inf``: any finite value.
    strictly : bool
        The value must be above *minimum*, not equal to it.
    optional : bool
        None is a value (the field's default says what it means).
    choices : tuple of str
        The values of a ``"choice"`` field.
    column : str or None
        Key of the field's sheet column (of its three ``_x``, ``_y``, ``_z``
        columns for a vector); None: the field's name.
    help : str
        The sheet column's line on the Instructions sheet.
    """

    doc: str
    type: str = "float"
    check: Check = "number"
    unit: str | None = None
    minimum: float = -math.inf
    strictly: bool = False
    optional: bool = False
    choices: tuple[str, ...] = ()
    column: str | None = None
    help: str = ""

    @property
    def bound(self) -> str:
        """The bound in words, e.g. ``"> 0"`` (empty: none)."""
        if self.minimum == -math.inf:
            return ""
        return f"{'>' if self.strictly else '>='} {self.minimum:g}"

    @property
    def type_words(self) -> str:
        """The numpydoc type: *type*, the set of *choices*, ``or None`` if *optional*."""
        kind = "{" + ", ".join(f'"{choice}"' for choice in self.choices) + "}" if self.choices else self.type
        return f"{kind} or None" if self.optional else kind

    @property
    def unit_words(self) -> str:
        """The unit as prose writes it: ``"N s/m"``, ``"dimensionless"`` (empty: no unit)."""
        if self.unit is None:
            return ""
        return "dimensionless" if self.unit == DIMENSIONLESS else self.unit.replace("*", " ")


def spec(doc: str, **kwargs: Any) -> dict[str, FieldSpec]:
    """Metadata of a dataclass field: ``field(default=0.0, metadata=spec("...", unit="N/m"))``.

    The keywords are those of :class:`FieldSpec`.
    """
    return {_METADATA_KEY: FieldSpec(doc, **kwargs)}


def field_spec(cls: type, name: str) -> FieldSpec:
    """The spec of field *name* of dataclass *cls*, or a KeyError if it has none."""
    for item in dataclasses.fields(cls):
        if item.name == name and _METADATA_KEY in item.metadata:
            return item.metadata[_METADATA_KEY]
    raise KeyError(f"{cls.__name__}.{name} has no field spec")


_SPECS: dict[type, tuple[tuple[str, FieldSpec], ...]] = {}


def _specs(cls: type) -> tuple[tuple[str, FieldSpec], ...]:
    """Name and spec of each field of dataclass *cls* that has one, in field order (found once per class)."""
    found = _SPECS.get(cls)
    if found is None:
        found = _SPECS[cls] = tuple((item.name, item.metadata[_METADATA_KEY])
                                    for item in dataclasses.fields(cls)
                                    if _METADATA_KEY in item.metadata)
    return found


def check_fields(obj: Any, item: str) -> None:
    """Check and normalise every field of the frozen dataclass *obj* that has a spec.

    *item* names *obj* in a CaseError (``"hinge 'front-up-left'"``). Fields
    checked ``"own"`` are left to the class.
    """
    for name, field in _specs(type(obj)):
        value = getattr(obj, name)
        if field.check == "own" or (field.optional and value is None):
            continue
        object.__setattr__(obj, name, _checked(field, item, name, value))


def _checked(field: FieldSpec, item: str, name: str, value: Any) -> Any:
    """*value* of field *name* in its normal form, or a CaseError."""
    if field.check == "number":
        return fields.number(item, name, value, minimum=field.minimum, strictly=field.strictly)
    if field.check == "flag":
        if not isinstance(value, bool):
            raise CaseError(item, name, value, "True or False")
        return value
    if field.check == "choice":
        if value not in field.choices:
            raise CaseError(item, name, value, " or ".join(repr(choice) for choice in field.choices))
        return value
    if field.check == "pair":
        return fields.pair(item, name, value, strictly=field.strictly)
    if field.check == "direction":
        return fields.direction(item, name, value)
    if field.check == "per_direction":
        return fields.per_direction(item, name, value, minimum=field.minimum, strictly=field.strictly)
    # "vector3"
    vector = fields.vector3(item, name, value)
    if field.bound and not all(v > field.minimum if field.strictly else v >= field.minimum for v in vector):
        raise CaseError(item, name, value, f"three numbers {field.bound} ({field.unit_words} in x, y, z)")
    return vector


def documented(cls: type[_T]) -> type[_T]:
    """Class decorator: append the Parameters section, written from the field specs, to the docstring.

    Every field of the dataclass must have a spec (a field without one would
    be missing from the documentation).
    """
    specs = dict(_specs(cls))
    missing = [item.name for item in dataclasses.fields(cls) if item.name not in specs]  # type: ignore[arg-type]
    if missing:
        raise TypeError(f"{cls.__name__}: fields without a spec: {', '.join(missing)}")
    lines = [inspect.cleandoc(cls.__doc__ or ""), "", "Parameters", "----------"]
    for name, field in specs.items():
        lines.append(f"{name} : {field.type_words}")
        lines += [line.replace(_GLUE, " ") for line in textwrap.wrap(
            _description(field), width=76, initial_indent="    ", subsequent_indent="    ")]
    cls.__doc__ = "\n".join(lines) + "\n"
    return cls


def _description(field: FieldSpec) -> str:
    """The docstring text of a field: its description, unit and bound."""
    said = ", ".join(part for part in (field.unit_words, field.bound.replace(" ", _GLUE)) if part)
    doc = field.doc.rstrip(".")
    return f"{doc}; {said}." if said else f"{doc}."
