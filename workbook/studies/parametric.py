"""Parameter studies: which case parameters vary, the study rows, and each row's case.

A study is a tuple of rows; a row maps parameter names to values. Each row's
case is the base case with those values put in (``dataclasses.replace`` on
the frozen case), so that a row is plain picklable data for a worker.

Parameters (SI units):

=================  =====  ====================================================
name               unit   what it sets
=================  =====  ====================================================
hinge_stiffness    N/m    translational stiffness of every hinge
hinge_damping      N s/m  translational damping of every hinge
hinge_loss_factor  -      structural loss factor of every hinge
clearance          m      radial clearance of every hinge
section_scale      -      factor on the cross-section of every link (shank width
                          and thickness, eye thickness)
material           text   preset material of every link (steel, titanium)
frequency          Hz     frequency of every single-frequency excitation
removed_link       text   a link removed with its hinges (``none``: all kept)
transducer_stiffness N/m  stiffness of every test-rig force transducer, x y z
engine_mass        kg     the engine's mass (its inertia kept)
casing_modulus     Pa     Young's modulus of the flexible engine casing's
                          material (a case with ``Engine.casing``)
=================  =====  ====================================================

A hinge parameter may name a group of hinges and a direction of the hinge
frame: ``hinge_stiffness/front`` sets the hinges whose names start with
``front``, ``hinge_loss_factor/thrust/axial`` their axial loss factor
(directions ``radial1``, ``radial2``, ``radial``: both, ``axial``; the
group ``all``: every hinge). :func:`parameter` reads such a name.

Rows come from lists or ranges (:func:`grid`, all combinations) or from a
Latin hypercube over ranges (:func:`latin_hypercube`).
"""
from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from workbook.errors import CaseError, InputError
from workbook.model.case import Case, HarmonicForce, RotatingForce

__all__ = ["Parameter", "PARAMETERS", "parameter", "parameter_value", "check_parameters",
           "HINGE_DIRECTIONS", "grid", "linear_range", "latin_hypercube", "row_case", "study_cases",
           "MAX_STUDY_ROWS"]


@dataclass(frozen=True)
class Parameter:
    """A parameter a study may vary.

    Attributes
    ----------
    name : str
    unit : str
        SI unit (``-`` for none, ``text`` for a choice).
    help : str
    apply : callable
        ``apply(case, value) -> Case``.
    hinge_field : str or None
        The :class:`~workbook.model.case.Hinge` field it sets on every hinge (None: another change), so that
        a row's changes of every hinge make one new hinge each (:func:`row_case`).
    """

    name: str
    unit: str
    help: str
    apply: Callable[[Case, Any], Case]
    hinge_field: str | None = None

    @property
    def numeric(self) -> bool:
        return self.unit != "text"


def _hinges(case: Case, **changes) -> Case:
    return dataclasses.replace(case, hinges=tuple(dataclasses.replace(h, **changes) for h in case.hinges))


def _every_hinge(name: str, unit: str, help_text: str, field_name: str) -> Parameter:
    """The parameter *name* setting the field *field_name* of every hinge to its value (a float)."""
    return Parameter(name, unit, help_text, lambda case, v: _hinges(case, **{field_name: float(v)}), field_name)


#: Directions of a hinge's frame a hinge parameter may name, as indices of its three values.
HINGE_DIRECTIONS = {"radial1": (0,), "radial2": (1,), "radial": (0, 1), "axial": (2,)}
#: The group of every hinge in a qualified hinge parameter.
ALL_HINGES = "all"


def _group(case: Case, group: str, name: str) -> set:
    """Names of the hinges of *group* (all: every hinge), for the parameter *name*."""
    names = [h.name for h in case.hinges]
    chosen = {n for n in names if group == ALL_HINGES or n.startswith(group)}
    if not chosen:
        raise CaseError("study", name, group, f"the start of hinge names or {ALL_HINGES!r}; hinges: {', '.join(names)}")
    return chosen


def _hinge_values(case: Case, field_name: str, value: float, group: str, direction: str, name: str) -> Case:
    """*case* with *field_name* of the hinges of *group* (all: every hinge) set to *value* in *direction*."""
    chosen = _group(case, group, name)
    hinges = []
    for hinge in case.hinges:
        if hinge.name in chosen:
            values = hinge.values(field_name).copy()
            values[list(HINGE_DIRECTIONS.get(direction, (0, 1, 2)))] = value
            changed: Any = tuple(float(v) for v in values)
            hinge = dataclasses.replace(hinge, **{field_name: changed})
        hinges.append(hinge)
    return dataclasses.replace(case, hinges=tuple(hinges))


#: What a case needs for transducer_stiffness and casing_modulus to change.
_NEEDS_RIG = "a case with test-rig force transducers"
_NEEDS_CASING = "a case with a flexible engine casing (Engine.casing)"


def check_parameters(case: Case, names) -> None:
    """Refuse a parameter that no row of a study of *case* can take, whatever its value: a hinge group
    without hinges, transducer_stiffness without a test rig, casing_modulus without a flexible casing.

    Raises
    ------
    InputError
        An unknown name (:func:`parameter`).
    CaseError
        Naming the parameter and what the case lacks.
    """
    for name in names:
        parameter(name)
        if name == "transducer_stiffness" and case.test_rig is None:
            raise CaseError("study", name, case.name, _NEEDS_RIG)
        if name == "casing_modulus" and case.engine.casing is None:
            raise CaseError("study", name, case.name, _NEEDS_CASING)
        if name not in PARAMETERS:
            _group(case, _hinge_target(name)[1], name)


def _casing_modulus(case: Case, modulus: float) -> Case:
    casing = case.engine.casing
    if casing is None:
        raise CaseError("study", "casing_modulus", modulus, _NEEDS_CASING)
    if not modulus > 0:
        raise CaseError("study", "casing_modulus", modulus, "a positive Young's modulus, Pa")
    material = dataclasses.replace(casing.material, youngs_modulus=float(modulus))
    return dataclasses.replace(case, engine=dataclasses.replace(case.engine, casing=dataclasses.replace(
        casing, material=material)))


def _transducers(case: Case, stiffness: float) -> Case:
    if case.test_rig is None:
        raise CaseError("study", "transducer_stiffness", stiffness, _NEEDS_RIG)
    return dataclasses.replace(case, test_rig=dataclasses.replace(case.test_rig, stiffness=(float(stiffness),) * 3))


#: Case field set by each hinge parameter.
_HINGE_FIELDS = {"hinge_stiffness": "stiffness", "hinge_damping": "damping", "hinge_loss_factor": "loss_factor"}


def _hinge_target(name: str) -> tuple[str, str, str]:
    """``(base, group, direction)`` of a hinge parameter (group ``all`` when unqualified).

    Raises
    ------
    InputError
        Not a hinge parameter, or a bad group syntax or direction, naming what is known.
    """
    base, qualified, qualifier = name.partition("/")
    group, _, direction = qualifier.partition("/")
    if base not in _HINGE_FIELDS or (qualified and not group) or (direction and direction not in HINGE_DIRECTIONS):
        raise InputError(f"unknown study parameter {name!r}; known: {', '.join(PARAMETERS)}, and hinge_stiffness, "
                         f"hinge_damping or hinge_loss_factor as NAME/GROUP or NAME/GROUP/DIRECTION (GROUP: the "
                         f"start of hinge names or {ALL_HINGES!r}; DIRECTION: {', '.join(HINGE_DIRECTIONS)})")
    return base, group or ALL_HINGES, direction


def parameter(name: str) -> Parameter:
    """The study parameter *name*: one of :data:`PARAMETERS`, or a hinge parameter qualified by a group
    and a direction (module text).

    Raises
    ------
    InputError
        An unknown name, group syntax or direction, naming it and what is known.
    """
    if name in PARAMETERS:
        return PARAMETERS[name]
    base, group, direction = _hinge_target(name)
    where = "every hinge" if group == ALL_HINGES else f"the hinges whose names start with {group!r}"
    general = PARAMETERS[base]
    return Parameter(name, general.unit, f"{general.help.split(' of every hinge')[0]} of {where}"
                     + (f", {direction}" if direction else ""),
                     lambda case, v: _hinge_values(case, _HINGE_FIELDS[base], float(v), group, direction, name))


def parameter_value(case: Case, name: str) -> float:
    """The value *case* holds of the numeric parameter *name* (SI units; a hinge parameter, the
    transducer stiffness, the engine mass or the casing's modulus).

    Raises
    ------
    InputError
        An unknown name, or a parameter without a value in *case*: another kind, no test rig, or hinges
        (directions) of the group holding different values.
    """
    if name == "engine_mass":
        return float(case.engine.mass)
    if name == "casing_modulus":
        if case.engine.casing is None:
            raise CaseError("case", name, None, "a case with a flexible engine casing (Engine.casing)")
        return float(case.engine.casing.material.youngs_modulus)
    if name == "transducer_stiffness":
        if case.test_rig is None:
            raise CaseError("case", name, None, "a case with test-rig force transducers")
        values = np.asarray(case.test_rig.stiffness, dtype=float)
    elif name in PARAMETERS and name not in _HINGE_FIELDS:
        raise InputError(f"{name!r} has no single value in a case to start from; a hinge parameter, "
                         "transducer_stiffness, engine_mass or casing_modulus has")
    else:
        base, group, direction = _hinge_target(name)
        axes = list(HINGE_DIRECTIONS.get(direction, (0, 1, 2)))
        chosen = _group(case, group, name)
        values = np.concatenate([h.values(_HINGE_FIELDS[base])[axes] for h in case.hinges if h.name in chosen])
    if np.ptp(values) > 1e-9 * np.abs(values).max():
        raise CaseError("case", name, f"{values.min():g} to {values.max():g}",
                        "one value over its hinges and directions (name a smaller group or a direction)")
    return float(values[0])


def _link_models(case: Case, change: Callable, parameter: str, value: Any) -> Case:
    links = []
    for link in case.links:
        if link.model.geometry is None:
            raise CaseError(f"link {link.name!r}", "model", "a mesh file", "a parametric link geometry")
        try:
            links.append(dataclasses.replace(link, model=change(link.model)))
        except ValueError as error:  # flexbodies rejects the changed geometry or material
            raise CaseError(f"link {link.name!r}", parameter, value, f"a value giving a valid link ({error})") from None
    return dataclasses.replace(case, links=tuple(links))


def _section(case: Case, scale: float) -> Case:
    if not scale > 0:
        raise CaseError("study", "section_scale", scale, "a positive factor")

    def change(model):
        geometry = model.geometry
        return dataclasses.replace(model, geometry=dataclasses.replace(
            geometry, shank_width=geometry.shank_width * scale, shank_thickness=geometry.shank_thickness * scale,
            thickness=geometry.thickness * scale))

    return _link_models(case, change, "section_scale", scale)


def _material(case: Case, name: str) -> Case:
    from flexbodies import material

    try:
        preset = material(name)
    except ValueError as error:
        raise CaseError("study", "material", name, str(error)) from None
    return _link_models(case, lambda model: dataclasses.replace(model, material=preset), "material", name)


def _frequency(case: Case, frequency_hz: float) -> Case:
    excitations = []
    for excitation in case.excitations:
        if not isinstance(excitation, (RotatingForce, HarmonicForce)):
            raise CaseError(f"excitation {excitation.name!r}", "frequency", frequency_hz,
                            "a single-frequency excitation (a sweep sets its own frequencies)")
        excitations.append(dataclasses.replace(excitation, frequency_hz=float(frequency_hz), rpm=None))
    return dataclasses.replace(case, excitations=tuple(excitations))


PARAMETERS = {p.name: p for p in (
    _every_hinge("hinge_stiffness", "N/m", "translational stiffness of every hinge", "stiffness"),
    _every_hinge("hinge_damping", "N*s/m", "translational damping of every hinge", "damping"),
    _every_hinge("hinge_loss_factor", "-", "structural loss factor of every hinge", "loss_factor"),
    _every_hinge("clearance", "m", "radial clearance of every hinge", "radial_clearance"),
    Parameter("section_scale", "-", "factor on the cross-section of every link (shank width and thickness, "
              "eye thickness)",
              lambda case, v: _section(case, float(v))),
    Parameter("material", "text", "preset material of every link (steel, titanium)", _material),
    Parameter("frequency", "Hz", "frequency of every single-frequency excitation", _frequency),
    Parameter("removed_link", "text", "a link removed with its hinges (none: all kept)",
              lambda case, name: case if name == "none" else case.without_link(name)),
    Parameter("transducer_stiffness", "N/m", "stiffness of every test-rig force transducer in x, y and z",
              _transducers),
    Parameter("engine_mass", "kg", "the engine's mass (its inertia kept)",
              lambda case, v: dataclasses.replace(case, engine=dataclasses.replace(case.engine, mass=float(v)))),
    Parameter("casing_modulus", "Pa", "Young's modulus of the flexible engine casing's material", _casing_modulus),
)}


#: Most rows of one study: a row is a run of its own (seconds each at best), and more is a slip (a range of
#: 1e6 points typed for 100, or too many lists combined) whose rows alone would fill the memory.
MAX_STUDY_ROWS = 100_000


def _check_rows(count: int, what: str) -> None:
    """Refuse a study of more than :data:`MAX_STUDY_ROWS` rows (*what*: where the count comes from)."""
    if count > MAX_STUDY_ROWS:
        raise InputError(f"{what} gives {count:,} rows; a study has at most {MAX_STUDY_ROWS:,}")


def _check_names(names) -> None:
    for name in names:
        parameter(name)


def grid(values: dict[str, list]) -> tuple[dict, ...]:
    """Every combination of the listed values, the last parameter varying fastest.

    Parameters
    ----------
    values : dict of str to list
        Values per parameter (SI units).

    Returns
    -------
    tuple of dict
    """
    _check_names(values)
    _check_rows(math.prod(len(v) for v in values.values()),
                " x ".join(f"{len(v):,} {name}" for name, v in values.items()) or "no parameter")
    names = list(values)
    return tuple(dict(zip(names, combination, strict=True)) for combination in itertools.product(*values.values()))


def linear_range(start: float, stop: float, points: int) -> list[float]:
    """*points* evenly spaced values from *start* to *stop*."""
    if points < 1:
        raise InputError(f"a range needs at least one point, got {points}")
    _check_rows(points, f"a range of {points:,} points")
    return [float(v) for v in np.linspace(start, stop, points)]


def latin_hypercube(bounds: dict[str, tuple[float, float]], samples: int, seed: int = 0) -> tuple[dict, ...]:
    """*samples* rows of a Latin hypercube over the numeric ranges *bounds*.

    Parameters
    ----------
    bounds : dict of str to (low, high)
        Range per numeric parameter (SI units).
    samples : int
    seed : int
        Seed of :class:`scipy.stats.qmc.LatinHypercube`.

    Returns
    -------
    tuple of dict
    """
    from scipy.stats import qmc

    _check_names(bounds)
    text = [n for n in bounds if not parameter(n).numeric]
    if text:
        raise InputError(f"a Latin hypercube needs numeric ranges; {', '.join(text)} takes a list")
    if samples < 1:
        raise InputError(f"a Latin hypercube needs at least one sample, got {samples}")
    _check_rows(samples, f"a Latin hypercube of {samples:,} samples")
    unit = qmc.LatinHypercube(d=len(bounds), seed=seed).random(samples)
    low, high = np.array(list(bounds.values()), dtype=float).T
    points = qmc.scale(unit, low, high) if len(bounds) else unit
    return tuple({name: float(value) for name, value in zip(bounds, row, strict=True)} for row in points)


def row_case(case: Case, row: dict, index: int) -> Case:
    """The case of study row *index*: *case* with the row's parameter values.

    Raises
    ------
    CaseError
        A value the case rejects (e.g. a stiffness of 0).
    """
    _check_names(row)
    pending: dict = {}                 # consecutive changes of every hinge, made together
    for name, value in row.items():
        chosen = parameter(name)
        if chosen.hinge_field is not None:
            pending[chosen.hinge_field] = float(value)
            continue
        if pending:
            case, pending = _hinges(case, **pending), {}
        case = chosen.apply(case, value)
    if pending:
        case = _hinges(case, **pending)
    return dataclasses.replace(case, name=f"{case.name} / row {index}")


def study_cases(case: Case, rows: tuple) -> list:
    """The case of every row, or the CaseError that row's values raise.

    Returns
    -------
    list of Case or CaseError
    """
    cases: list[Case | CaseError] = []
    for index, row in enumerate(rows):
        try:
            cases.append(row_case(case, row, index))
        except CaseError as error:
            cases.append(error)
    return cases
