"""The Optimise sheet of a case workbook: the problem ``mountwb optimise CASE.xlsx`` solves without ``--vary``.

One row per item (:data:`~workbook.excel.layout.OPTIMISE`), SI units:

- ``variable``: a study parameter name with its range (low, high);
- ``constraint``: ``displacement``, ``sag`` or ``rotation`` (value: the
  upper limit, m or rad), ``fatigue`` (value: the lowest Goodman factor
  allowed), ``margin`` (value: the lowest margin of safety under the load
  cases) or ``modes_outside`` (low, high: the band, Hz);
- ``band``: a rotor excitation's speed band (low, high, Hz);
- ``objective``: ``worst`` or ``weighted``; ``starts``: the SLSQP starts.

Each problem is reported at its cell, as every sheet's. :func:`optimise_rows`
writes a problem as the rows the reader reads back (the optimum
``mountwb optimise --output`` writes carries the problem it solved).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from workbook.errors import InputError
from workbook.model.case import SINGLE_FREQUENCY_KINDS, Case

if TYPE_CHECKING:     # the sheet reader loads openpyxl: not for a command's --help
    from workbook.excel.sheets import Record

__all__ = ["OptimiseSheet", "read_optimise_sheet", "optimise_rows"]


@dataclass(frozen=True)
class OptimiseSheet:
    """The problem an Optimise sheet gives.

    Attributes
    ----------
    variables : dict of str to (float, float)
    constraints : tuple of workbook.design.optimise.Constraint
    bands : dict of str to (float, float)
        Rotor excitation name to its speed band, Hz.
    objective, starts : str and int, or None
        None: not given.
    """

    variables: dict = field(default_factory=dict)
    constraints: tuple = ()
    bands: dict = field(default_factory=dict)
    objective: str | None = None
    starts: int | None = None


def _expected(error: InputError) -> str:
    """What an error of the optimiser's readers expected (its text after the item it names)."""
    text = str(error).partition(": ")[2]
    return text.rpartition("expected ")[2] if "expected " in text else text


def _constraint_text(name: str, record: Record) -> str:
    if name == "modes_outside":
        return f"{name}={record.get('low')}:{record.get('high')}"
    return f"{name}{'>=' if name in ('fatigue', 'margin') else '<='}{record.get('value')}"


def read_optimise_sheet(reader, records: list[Record], case: Case) -> OptimiseSheet | None:
    """The Optimise sheet's problem (None: no rows); each bad cell reported to *reader*
    (a :class:`~workbook.excel.sheets.SheetReader`)."""
    if not records:
        return None
    from workbook.design.optimise import OBJECTIVES, constraint, variable, variable_name  # SciPy: only for the sheet

    rotors = [item.name for item in case.excitations if isinstance(item, SINGLE_FREQUENCY_KINDS)]
    variables, constraints, bands = {}, [], {}
    given: dict = {"objective": None, "starts": None}
    for record in records:
        if not record.ok:
            continue
        kind, name = record.get("kind"), record.get("name")
        low, high = record.get("low"), record.get("high")
        if kind in ("variable", "constraint", "band", "objective") and name is None:
            reader.record_problem(record, ("name",), None, f"a name (the {kind}'s)")
            continue
        if kind == "variable":
            try:
                variable_name(name)
            except InputError as error:
                reader.record_problem(record, ("name",), name, f"a study parameter: {_expected(error)}")
                continue
            if name in variables:
                reader.record_problem(record, ("name",), name, "each variable once")
                continue
            try:
                if low is None or high is None:
                    raise InputError(f"variable {name!r}: expected its range, LOW and HIGH")
                chosen = variable(name, low, high)
            except InputError as error:
                reader.record_problem(record, ("low", "high"), record.typed(("low", "high"), None),
                                      _expected(error))
                continue
            variables[name] = (chosen.low, chosen.high)
        elif kind == "constraint":
            try:
                constraints.append(constraint(_constraint_text(name, record)))
            except InputError as error:
                keys = ("low", "high") if name == "modes_outside" else ("name", "value")
                reader.record_problem(record, keys, record.typed(keys, name), _expected(error))
        elif kind == "band":
            if name not in rotors:
                reader.record_problem(record, ("name",), name,
                                      f"a single-frequency excitation of the case ({', '.join(rotors) or 'none'})")
            elif low is None or high is None or not 0 < low < high:
                reader.record_problem(record, ("low", "high"), record.typed(("low", "high"), None),
                                      "the band's speeds in Hz, 0 < LOW < HIGH")
            else:
                bands[name] = (low, high)
        elif kind == "objective":
            if name not in OBJECTIVES:
                reader.record_problem(record, ("name",), name, " or ".join(OBJECTIVES))
            else:
                given["objective"] = name
        else:
            value = record.get("value")
            if value is None or value < 1 or value != int(value):
                reader.record_problem(record, ("value",), record.typed(("value",), None), "a whole number >= 1")
            else:
                given["starts"] = int(value)
    return OptimiseSheet(variables, tuple(constraints), bands, given["objective"], given["starts"])


def optimise_rows(sheet: OptimiseSheet) -> list[dict]:
    """The Optimise sheet's rows of the problem *sheet* (values by column key, SI units): what
    :func:`read_optimise_sheet` reads back to *sheet*."""
    from workbook.design.optimise import MODES_OUTSIDE

    rows = [{"kind": "variable", "name": name, "low": low, "high": high} for name, (low, high) in sheet.variables.items()]
    for rule in sheet.constraints:
        limit = dict(zip(("low", "high"), rule.limit, strict=True)) if rule.quantity == MODES_OUTSIDE else \
            {"value": rule.limit}
        rows.append({"kind": "constraint", "name": rule.quantity, **limit})
    rows += [{"kind": "band", "name": name, "low": low, "high": high} for name, (low, high) in sheet.bands.items()]
    if sheet.objective is not None:
        rows.append({"kind": "objective", "name": sheet.objective})
    if sheet.starts is not None:
        rows.append({"kind": "starts", "value": sheet.starts})
    return rows
