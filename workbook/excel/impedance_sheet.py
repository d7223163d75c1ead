"""The optional 'Pylon impedance' sheet of a case workbook.

Laid out as the CSV table of :mod:`workbook.model.pylon_impedance`: a
header row, a units row, one row per frequency and pin. A workbook without
the sheet has a rigid pylon.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

from workbook.errors import CaseError, Problem, WorkbookError
from workbook.model.case import Case
from workbook.model.pylon_impedance import impedance_from_rows

__all__ = ["SHEET", "with_impedance_sheet"]

#: The sheet's name.
SHEET = "Pylon impedance"


def with_impedance_sheet(case: Case, path: Path, values) -> Case:
    """*case* with the pylon impedance of the workbook's sheet, if it has one.

    Parameters
    ----------
    case : Case
    path : Path
        The workbook, for messages.
    values : openpyxl.Workbook
        The workbook opened with its cached values.

    Raises
    ------
    workbook.errors.WorkbookError
        A table that cannot be used (a :class:`~workbook.errors.TableError`
        naming row and column), or a pylon pin without rows.
    """
    if SHEET not in values.sheetnames:
        return case
    impedance = impedance_from_rows(values[SHEET].iter_rows(values_only=True), path.name, SHEET)
    try:
        return dataclasses.replace(case, pylon_impedance=impedance)
    except CaseError as error:
        raise WorkbookError([Problem(path.name, SHEET, None, "pin", error.value, error.expected)]) from None
