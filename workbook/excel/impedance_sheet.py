"""The optional 'Pylon impedance' sheet of a case workbook.

Laid out as the CSV table of :mod:`workbook.model.pylon_impedance`: a
header row, a units row, one row per frequency and pin. A workbook without
the sheet has a rigid pylon.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

from workbook.errors import CaseError, Problem, WorkbookError
from workbook.excel.sheets import CachedValues, matching_sheets
from workbook.model.case import Case
from workbook.model.pylon_impedance import impedance_from_rows

__all__ = ["SHEET", "with_impedance_sheet"]

#: The sheet's name.
SHEET = "Pylon impedance"


def with_impedance_sheet(case: Case, path: Path, values: CachedValues) -> Case:
    """*case* with the pylon impedance of the workbook's sheet, if it has one
    (found up to letter case and spaces; the reader has refused two such sheets).

    Parameters
    ----------
    case : Case
    path : Path
        The workbook, for messages.
    values : CachedValues
        The workbook's cached values.

    Raises
    ------
    workbook.errors.WorkbookError
        A table that cannot be used (a :class:`~workbook.errors.TableError`
        naming row and column), or a pylon pin without rows.
    """
    titles = matching_sheets(values.sheetnames, SHEET)
    if not titles:
        return case
    impedance = impedance_from_rows(values.rows(titles[0]), path.name, SHEET)
    try:
        return dataclasses.replace(case, pylon=impedance)
    except CaseError as error:
        raise WorkbookError([Problem(path.name, SHEET, None, "pin", error.value, error.expected)]) from None
