"""The one case loader of every command, and progress bars on stderr.

A command's CASE argument is a case workbook (``.xlsx``/``.xlsm``), a JSON
case (written by :func:`workbook.model.codec.to_json`), or nothing (the
bundled reference mount).
"""
from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from workbook.errors import CaseError, UsageError
from workbook.model.case import AnalysisMethod, Case
from workbook.model.codec import from_json
from workbook.model.pylon_impedance import PylonImpedance, read_impedance_csv
from workbook.model.reference import reference_case

if TYPE_CHECKING:   # the stages module loads the scene builder and SciPy: not for a command's --help
    from workbook.solve.stages import ProgressFactory

__all__ = ["WORKBOOK_SUFFIXES", "is_workbook", "load_case", "progress_factory"]

#: File name endings read as case workbooks.
WORKBOOK_SUFFIXES = (".xlsx", ".xlsm")


def is_workbook(name: str | None) -> bool:
    """True if *name* names a case workbook (by its ending)."""
    return name is not None and Path(name).suffix.lower() in WORKBOOK_SUFFIXES


#: Spreadsheet files not read, by ending, and what they are.
_OTHER_SPREADSHEETS = {".ods": "an OpenDocument spreadsheet", ".xls": "an Excel 97-2003 workbook",
                       ".xlsb": "an Excel binary workbook", ".csv": "a CSV table"}


def _json_case(path: str) -> Case:
    other = _OTHER_SPREADSHEETS.get(Path(path).suffix.lower())
    if other is not None:
        raise UsageError(f"{path}: {other} is not read as a case; save it as an Excel workbook (.xlsx) and give "
                         "that, or give a JSON case")
    try:
        case = from_json(Path(path).read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise UsageError(f"{path}: not a JSON case (not UTF-8 text); give a case workbook (.xlsx/.xlsm) "
                         f"or a JSON case") from None
    except json.JSONDecodeError as error:
        raise UsageError(f"{path}: not a JSON case: {error}") from None
    except OSError as error:
        raise UsageError(f"{path}: the case cannot be read ({error.strerror or error})") from None
    if not isinstance(case, Case):
        raise CaseError(path, "type", type(case).__name__, "a JSON case (type 'Case')")
    return case


def load_case(path: str | None = None, *, run: str | None = None, rigid: bool = False,
              time_budget: float | None = None, method: AnalysisMethod | None = None,
              pylon_impedance: str | None = None) -> Case:
    """The case a command works on.

    Parameters
    ----------
    path : str or None
        A case workbook, a JSON case, or None for the reference mount.
    run : str or None
        A case workbook's Runs row whose case to take (default: the
        workbook's case as it stands).
    rigid : bool
        Make every link rigid.
    time_budget : float or None
        Wall-time budget of one run, s (None: as the case says).
    method : {"auto", "time", "frequency"} or None
        Analysis method (None: as the case says).
    pylon_impedance : str or None
        A CSV table of the pylon's point dynamic stiffness per pin
        (:mod:`workbook.model.pylon_impedance`), the case's pylon in place
        of its own (None: as the case says).

    Raises
    ------
    workbook.errors.WorkbookError, CaseError, UsageError, OSError
        A bad workbook, case, impedance table or file, or a run name given for a case that is
        not a workbook.
    """
    if is_workbook(path):
        from workbook.excel.execute import select_runs
        from workbook.excel.reader import read_workbook

        assert path is not None
        book = read_workbook(path)
        case = book.case if run is None else book.run_case(select_runs(book, [run])[0])
    elif run is not None:
        raise UsageError("--run names a row of a case workbook's Runs sheet; give a .xlsx case")
    else:
        case = reference_case() if path is None else _json_case(path)
    if time_budget is not None:
        case = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, time_budget=time_budget))
    if method is not None:
        case = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method=method))
    if pylon_impedance is not None:
        if case.pylon is not None and not isinstance(case.pylon, PylonImpedance):
            raise UsageError(f"--pylon-impedance {pylon_impedance}: the case already has a {case.pylon.noun} "
                             f"({case.pylon.label}) and a case has one pylon model; leave out --pylon-impedance "
                             "or take the pylon model out of the case")
        case = dataclasses.replace(case, pylon=read_impedance_csv(pylon_impedance))
    return case.with_rigid_links() if rigid else case


def progress_factory() -> ProgressFactory:
    """Progress bars on stderr (tqdm hides them when stderr is not a terminal)."""
    from tqdm import tqdm

    def factory(description: str, total: float):
        bar = tqdm(total=total, desc=description, file=sys.stderr, disable=None, leave=False,
                   bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}<{remaining}")

        def update(done: float):
            bar.update(done - bar.n)

        return update, bar.close

    return factory
