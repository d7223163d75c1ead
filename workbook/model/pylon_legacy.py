"""The per-kind pylon fields of version 0.1.0, kept as a deprecation path.

Cases of version 0.1.0 held the pylon in three fields, ``pylon_impedance``,
``pylon_beam`` and ``pylon_mesh``, at most one of them set; now
``Case.pylon`` holds any :class:`~workbook.model.pylon.PylonModel`. Case
files with the three fields are still read (:mod:`workbook.model.codec`),
and ``Case(pylon_beam=...)``, ``dataclasses.replace(case, pylon_beam=...)``
and ``case.pylon_beam`` still work with a :class:`DeprecationWarning`.
"""
from __future__ import annotations

import functools
import warnings
from typing import Any

from workbook.errors import CaseError
from workbook.model.pylon import PylonModel
from workbook.model.pylon_beam import BoxBeamPylon
from workbook.model.pylon_impedance import PylonImpedance
from workbook.model.pylon_mesh import MeshPylon

__all__ = ["LEGACY_PYLON_FIELDS", "accept_legacy_pylons", "legacy_pylon"]

#: The pylon fields of version 0.1.0, each holding one kind of pylon model.
LEGACY_PYLON_FIELDS: dict[str, type[PylonModel]] = {
    kind.legacy_field: kind for kind in (PylonImpedance, BoxBeamPylon, MeshPylon)}


def _deprecated(name: str, stacklevel: int) -> None:
    warnings.warn(f"Case.{name} is deprecated: use Case.pylon (one field for every pylon model)",
                  DeprecationWarning, stacklevel=stacklevel + 1)


def legacy_pylon(pylon: PylonModel | None, name: str) -> Any:
    """*pylon* if it is of the kind field *name* held, else None (warned as deprecated)."""
    _deprecated(name, 3)
    return pylon if isinstance(pylon, LEGACY_PYLON_FIELDS[name]) else None


def _with_legacy_pylons(pylon: Any, given: dict[str, Any]) -> Any:
    """*pylon* changed by the fields *given* (name to model or None).

    A model given replaces a pylon of its own kind; None removes a pylon of
    its kind and leaves another kind in place.

    Raises
    ------
    workbook.errors.CaseError
        Models of two kinds (a case has one pylon model).
    """
    for name, value in given.items():
        kind = LEGACY_PYLON_FIELDS[name]
        if value is None:
            pylon = None if isinstance(pylon, kind) else pylon
        elif pylon is None or isinstance(pylon, kind):
            pylon = value
        else:
            raise CaseError("case", name, getattr(value, "label", value),
                            f"no {kind.noun} when a {pylon.noun} is given (one pylon model)")
    return pylon


def accept_legacy_pylons(init):
    """*init* of :class:`~workbook.model.case.Case` also taking the fields of version 0.1.0 as keywords
    (and so ``dataclasses.replace`` with them)."""
    @functools.wraps(init)
    def __init__(self, *args, **kwargs):
        given = {name: kwargs.pop(name) for name in LEGACY_PYLON_FIELDS if name in kwargs}
        if given:
            _deprecated("/".join(given), 2)
            kwargs["pylon"] = _with_legacy_pylons(kwargs.get("pylon"), given)
        init(self, *args, **kwargs)
    return __init__
