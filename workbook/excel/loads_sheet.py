"""The table of solved limit load cases written to a case workbook (``Result loads``) and a report (``Loads``).

One row per load case and link (:class:`~workbook.solve.load_cases.LoadCaseResult`):
axial force, nominal shank stress, peak von Mises stress with its region and
point, largest principal stress with its region, and the margins of safety
against yield (limit load) and ultimate strength (ultimate load). Stresses in
MPa, forces in N, points in m; an empty cell is a value not known (a rigid
link has no stress field, a mesh link no shank area).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["NOTE", "QUANTITIES", "loads_frame"]

#: The sheet's note (row 1).
NOTE = ("Limit load cases on the case as its sheets give it (the Runs sheet's overrides do not apply): "
        "MS yield = F_ty / sigma_vM - 1 at limit load, MS ultimate = F_tu / (FS sigma_vM) - 1 at ultimate load")
_MPA = ("nominal stress MPa", "von Mises MPa", "max principal MPa")
_MARGINS = ("MS yield", "MS ultimate")
#: FORMATS key of the columns whose header does not tell it (:func:`~workbook.excel.styling.quantity_of`).
QUANTITIES = {**dict.fromkeys(_MPA, "MPa"), **dict.fromkeys(_MARGINS, "margin"), "FS": "margin",
              **{f"von Mises {axis} m": "m" for axis in "xyz"}}


def _mpa(value: float | None) -> float | None:
    return None if value is None else value / 1e6


def loads_frame(results) -> pd.DataFrame:
    """The table of *results* (a list of LoadCaseResult), one row per load case and link."""
    import pandas as pd

    rows = []
    for result in results:
        load_case = result.load_case
        for name, s in result.links.items():
            point = s.von_mises_point or (None, None, None)
            rows.append([load_case.name, load_case.factor_of_safety, load_case.without_link, name, s.axial_force,
                         _mpa(s.nominal_stress), _mpa(s.von_mises), s.von_mises_region, *point,
                         _mpa(s.max_principal), s.max_principal_region, s.yield_margin, s.ultimate_margin])
    return pd.DataFrame(rows, columns=["load case", "FS", "link removed", "link", "axial force N", _MPA[0], _MPA[1],
                                       "von Mises at", *(f"von Mises {axis} m" for axis in "xyz"), _MPA[2],
                                       "max principal at", *_MARGINS])
