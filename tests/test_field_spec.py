"""Each input field described once: its spec gives the check, the docstring and the sheet column.

The classes whose fields carry a :class:`~workbook.model.field_spec.FieldSpec`
are checked here against the three uses: a value outside the spec's bound is
refused naming the field and the bound (and the bound itself is accepted
unless strict), the generated Parameters section (read back by numpydoc)
lists every field with its unit and bound, and the sheet columns of the field
carry its SI unit and help line. That the template's header, unit and help
cells stay what they were is ``test_committed_workbooks_are_what_the_code_generates``
in tests/test_excel_check.py (the committed template, byte for byte).
"""
import dataclasses
import math

import pytest
from numpydoc.docscrape import NumpyDocString

from flexbodies.materials import Material
from workbook.errors import CaseError
from workbook.excel import layout
from workbook.model.case import (
    AnalysisSettings,
    Case,
    Effects,
    Engine,
    ForceTransducers,
    Gravity,
    HarmonicForce,
    Hinge,
    Imbalance,
    ImbalancePlane,
    Link,
    PointForce,
    PointMoment,
    RotatingForce,
    Rotor,
    RunUp,
    Simultaneous,
    Sweep,
)
from workbook.model.casing import EngineCasing
from workbook.model.field_spec import FieldSpec, field_spec
from workbook.model.load_cases import LoadCase
from workbook.model.pylon_beam import BoxBeamPylon
from workbook.model.pylon_mesh import MeshPylon
from workbook.model.reference import reference_case, reference_casing
from workbook.model.spectrum import SpeedBand, SpeedSpectrum

CASE = reference_case()
ALUMINIUM = Material("aluminium", 70e9, 0.33, 2800.0)
PLANE = ImbalancePlane((0.2, 0.0, 0.0), unbalance=2e-3, phase_deg=90).check("plane")
#: A valid instance of each described class, and the sheet its fields are read from (None: it has none).
DESCRIBED = {
    Engine: (CASE.engine, layout.ENGINE),
    Link: (CASE.links[0], layout.LINKS),
    Hinge: (CASE.hinges[0], layout.HINGES),
    ForceTransducers: (ForceTransducers((2e8, 2e8, 3e8)), layout.TEST_RIG),
    Rotor: (Rotor("LP spool", 2.5, frequency_hz=80.0), layout.ROTORS),
    AnalysisSettings: (AnalysisSettings(), layout.CASE),
    Effects: (Effects(), layout.CASE),
    EngineCasing: (reference_casing(), layout.CASING),
    PointForce: (PointForce("thrust", (2.3e4, 0.0, 0.0), (0.9, 0.0, 0.0)), layout.STATIC_LOADS),
    PointMoment: (PointMoment("torque", (1e4, 0.0, 0.0)), layout.STATIC_LOADS),
    Gravity: (Gravity(), layout.STATIC_LOADS),
    RotatingForce: (RotatingForce("LP rotor", (0.2, 0.0, 0.0), frequency_hz=50.0, unbalance=0.01), layout.EXCITATIONS),
    HarmonicForce: (HarmonicForce("shaker", (0.2, 0.0, 0.0), (0.0, 0.0, 1.0), 1e3, rpm=3000.0), layout.EXCITATIONS),
    ImbalancePlane: (PLANE, layout.EXCITATIONS),
    Imbalance: (Imbalance("LP rotor", (PLANE, PLANE), rpm=3000.0), layout.EXCITATIONS),
    Sweep: (Sweep("sweep", HarmonicForce("shaker", (0.2, 0.0, 0.0), (0.0, 0.0, 1.0), 1e3, frequency_hz=5.0),
                  (5.0, 50.0)), layout.EXCITATIONS),
    RunUp: (RunUp("run-up", Imbalance("LP rotor", (PLANE,), rpm=600.0), (10.0, 20.0), "Hz"), layout.EXCITATIONS),
    Simultaneous: (Simultaneous("both spools", (Imbalance("LP", (PLANE,), frequency_hz=50.0),
                                                Imbalance("HP", (PLANE,), frequency_hz=200.0))), layout.EXCITATIONS),
    Case: (CASE, layout.CASE),
    LoadCase: (LoadCase("take-off", thrust=110e3, torque=30e3, thrust_point=(1, 0, 0)), layout.LOAD_CASES),
    SpeedBand: (SpeedBand(150, 15, 25), layout.SPEED_SPECTRUM),
    SpeedSpectrum: (SpeedSpectrum("LP rotor", (SpeedBand(150, 15, 25),)), layout.SPEED_SPECTRUM),
    BoxBeamPylon: (BoxBeamPylon((0, 0, 3), (0, 0, 0), 0.3, 0.5, 0.01, ALUMINIUM, up=(1, 0, 0)), None),
    MeshPylon: (MeshPylon("pylon.msh", (0, 0, 3), (0, 0, 1), (0, 1, 0), 0.012, ALUMINIUM, scale=1e-3), None),
}


def _replaced(valid, **changes):
    """*valid* with *changes*, checked (an imbalance plane is checked by the imbalance holding it)."""
    changed = dataclasses.replace(valid, **changes)
    return changed.check("excitation 'LP rotor' plane 1") if isinstance(changed, ImbalancePlane) else changed


def _specs(cls) -> list[tuple[str, FieldSpec]]:
    return [(f.name, field_spec(cls, f.name)) for f in dataclasses.fields(cls)]


BOUNDED = [(cls, name, described) for cls in DESCRIBED for name, described in _specs(cls)
           if described.check != "own" and described.minimum > -math.inf]


def _at(described: FieldSpec, value: float):
    """*value* in the shape of the field: one number, or two or three (one of them *value*)."""
    return {"vector3": (1.0, 1.0, value), "pair": (1.0, value)}.get(described.check, value)


@pytest.mark.parametrize("cls, name, described", BOUNDED, ids=lambda p: getattr(p, "__name__", p))
def test_a_value_below_the_bound_is_refused_naming_the_field_and_the_bound(cls, name, described):
    valid, _ = DESCRIBED[cls]
    below = described.minimum - 1.0
    with pytest.raises(CaseError) as refused:
        _replaced(valid, **{name: _at(described, below)})
    assert f"field '{name}'" in str(refused.value) and described.bound in str(refused.value)
    at_bound = _at(described, described.minimum)
    if described.strictly:
        with pytest.raises(CaseError):
            _replaced(valid, **{name: at_bound})
    else:
        assert _replaced(valid, **{name: at_bound}) is not None


@pytest.mark.parametrize("cls, name, described", [b for b in BOUNDED if b[2].check == "per_direction"],
                         ids=lambda p: getattr(p, "__name__", p))
def test_a_bad_one_of_three_per_direction_values_is_named_by_its_direction(cls, name, described):
    valid, _ = DESCRIBED[cls]
    with pytest.raises(CaseError, match=rf"field '{name}\[axial\]'.*a number {described.bound}"):
        _replaced(valid, **{name: (1.0, 1.0, described.minimum - 1.0)})


@pytest.mark.parametrize("cls, name, described", [(cls, name, described) for cls in DESCRIBED
                                                   for name, described in _specs(cls)
                                                   if described.check in ("choice", "flag")],
                         ids=lambda p: getattr(p, "__name__", p))
def test_a_choice_or_flag_takes_only_its_values(cls, name, described):
    valid, _ = DESCRIBED[cls]
    expected = " or ".join(map(repr, described.choices)) if described.choices else "True or False"
    with pytest.raises(CaseError) as refused:
        _replaced(valid, **{name: "maybe"})
    assert str(refused.value).endswith(f"field '{name}': found 'maybe', expected {expected}")
    for value in described.choices or (True, False):
        assert getattr(_replaced(valid, **{name: value}), name) == value


@pytest.mark.parametrize("cls", DESCRIBED, ids=lambda c: c.__name__)
def test_a_field_is_normalised_to_floats(cls):
    valid, _ = DESCRIBED[cls]
    for name, described in _specs(cls):
        value = getattr(valid, name)
        if described.check == "number" and value is not None:
            assert type(value) is float, name
        if described.check in ("vector3", "pair") and value is not None:
            assert type(value) is tuple and all(type(v) is float for v in value), name


@pytest.mark.parametrize("cls", DESCRIBED, ids=lambda c: c.__name__)
def test_the_docstring_lists_every_field_with_its_unit_and_bound(cls):
    parameters = {p.name: p for p in NumpyDocString(cls.__doc__)["Parameters"]}
    assert list(parameters) == [f.name for f in dataclasses.fields(cls)]
    for name, described in _specs(cls):
        text = " ".join(parameters[name].desc)
        assert described.unit_words in text and described.bound in text, (name, text)
        assert parameters[name].type == described.type_words


@pytest.mark.parametrize("cls", DESCRIBED, ids=lambda c: c.__name__)
def test_the_sheet_columns_of_a_field_carry_its_unit_and_help(cls):
    _, table = DESCRIBED[cls]
    for name, described in _specs(cls):
        if not described.help:
            continue
        key = described.column or name
        keys = table.vector_keys(key) if described.check in ("vector3", "direction") else (key,)
        for column in map(table.column, keys):
            assert column.si_unit == described.unit, (table.sheet, column.key)
            assert column.help.startswith(described.help), (table.sheet, column.key)


def test_a_field_without_a_spec_is_a_key_error():
    with pytest.raises(KeyError, match="Link.length has no field spec"):
        field_spec(Link, "length")
