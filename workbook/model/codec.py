"""Cases to and from JSON-ready dictionaries.

Every dataclass becomes a dictionary of its fields plus ``"type"`` (the class
name), tuples become lists; decoding reverses that, turning every list back
into a tuple (the case model stores sequences as tuples). Only the classes
registered here are decoded, so a case file cannot construct arbitrary
objects. A case's pylon model is written as ``"pylon"``; the per-kind pylon
fields of earlier versions' files are still read.
"""
from __future__ import annotations

import dataclasses
import json
from typing import Any

from workbook.errors import CaseFileError
from workbook.model import case as _case
from workbook.model.casing import CasingGeometry, EngineCasing, MountRing
from workbook.model.load_cases import LoadCase
from workbook.model.pylon_beam import BoxBeamPylon
from workbook.model.pylon_impedance import PylonImpedance
from workbook.model.pylon_legacy import LEGACY_PYLON_FIELDS
from workbook.model.pylon_mesh import MeshPylon
from workbook.model.spectrum import SpeedBand, SpeedSpectrum

__all__ = ["to_dict", "from_dict", "to_json", "from_json"]


def _registry() -> dict[str, type]:
    """Classes a case may contain, by name."""
    import flexbodies
    from flexbodies.bores import BoreSpec

    classes = [_case.Case, _case.Engine, _case.Link, _case.Hinge, _case.PointForce,
               _case.PointMoment, _case.Gravity, _case.RotatingForce, _case.HarmonicForce,
               _case.ImbalancePlane, _case.Imbalance, _case.RunUp, _case.Simultaneous,
               _case.Sweep, _case.Rotor, _case.ForceTransducers, _case.AnalysisSettings, _case.Effects,
               PylonImpedance, BoxBeamPylon, MeshPylon, EngineCasing, CasingGeometry, MountRing, LoadCase,
               SpeedSpectrum, SpeedBand,
               flexbodies.LinkModel,
               flexbodies.LinkGeometry, flexbodies.Material, flexbodies.MeshSource, BoreSpec]
    return {cls.__name__: cls for cls in classes}


def to_dict(obj: Any) -> Any:
    """Encode a case (or any part of it) as JSON-ready data."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        data = {"type": type(obj).__name__}
        data.update({f.name: to_dict(getattr(obj, f.name)) for f in dataclasses.fields(obj)})
        return data
    if isinstance(obj, (tuple, list)):
        return [to_dict(item) for item in obj]
    if isinstance(obj, dict):
        return {str(key): to_dict(value) for key, value in obj.items()}
    if hasattr(obj, "item") and callable(obj.item):      # numpy scalar
        return obj.item()
    return obj


def from_dict(data: Any, _classes: dict[str, type] | None = None) -> Any:
    """Decode data written by :func:`to_dict`.

    Raises
    ------
    ValueError
        For an unknown ``"type"``, fields that class does not have, or
        required fields it lacks; the case
        classes raise :class:`~workbook.model.case.CaseError` for invalid values.
    """
    classes = _registry() if _classes is None else _classes
    if isinstance(data, list):
        return tuple(from_dict(item, classes) for item in data)
    if isinstance(data, dict):
        if "type" not in data:
            return {key: from_dict(value, classes) for key, value in data.items()}
        kind = data["type"]
        if kind not in classes:
            raise CaseFileError(f"unknown item type {kind!r}; expected one of {', '.join(sorted(classes))}")
        cls = classes[kind]
        if cls is _case.Case:
            data = _one_pylon(data)
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = set(data) - known - {"type"}
        if unknown:
            raise CaseFileError(f"{kind}: unknown fields {sorted(unknown)}; expected {sorted(known)}")
        missing = sorted(f.name for f in dataclasses.fields(cls) if f.name not in data
                         and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING)
        if missing:
            raise CaseFileError(f"{kind}: fields {missing} missing; expected {sorted(known)}")
        fields = {key: from_dict(value, classes) for key, value in data.items() if key != "type"}
        if cls is _case.Link and isinstance(fields.get("modes"), float):
            fields["modes"] = _case.ModeCutoff(fields["modes"])     # a number with a fraction: a cut-off, Hz
        try:
            return cls(**fields)
        except (TypeError, AttributeError) as error:
            # a value of the wrong kind (a list where a number belongs, ...)
            raise CaseFileError(f"{kind}: a field holds a value of the wrong kind ({error})") from None
    return data


def _one_pylon(data: dict) -> dict:
    """A case's data with the pylon fields of earlier versions (``pylon_impedance``, ``pylon_beam``,
    ``pylon_mesh``, at most one of them not null) read as its ``pylon``."""
    given = {key: data[key] for key in LEGACY_PYLON_FIELDS if key in data}
    if not given:
        return data
    models = {key: value for key, value in {**given, "pylon": data.get("pylon")}.items() if value is not None}
    if len(models) > 1:
        raise CaseFileError(f"Case: pylon models in {sorted(models)}; expected one pylon model (field 'pylon')")
    upgraded = {key: value for key, value in data.items() if key not in given}
    upgraded["pylon"] = next(iter(models.values()), None)
    return upgraded


def to_json(obj: Any, **kwargs) -> str:
    """Encode as a JSON text (keyword arguments go to :func:`json.dumps`)."""
    return json.dumps(to_dict(obj), **kwargs)


def from_json(text: str) -> Any:
    """Decode a JSON text written by :func:`to_json`."""
    return from_dict(json.loads(text))
