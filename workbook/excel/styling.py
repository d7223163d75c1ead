"""How the sheets this package writes look on screen and on paper: number formats and print setup.

One home for the number format of each quantity, used by the result sheets
written back into a case workbook, the report workbook and the template.
"""
from __future__ import annotations

from openpyxl.worksheet.properties import PageSetupProperties

__all__ = ["FORMATS", "quantity_of", "print_setup"]

#: Number format of each quantity: eta and errors in %, T in four decimals (scientific below 0.01),
#: levels in dB with one decimal, frequencies in Hz with two, forces in N.
FORMATS = {"eta": '0.00" %"', "T": "[<0.01]0.000E+00;0.0000", "dB": "0.0", "Hz": "0.00", "N": "0.000",
           "error": '0.0" %"', "zeta": '0.00" %"'}


def quantity_of(header: str) -> str | None:
    """The :data:`FORMATS` key of a result column from its header (None: text or a plain number).

    Headers name their unit: ``frequency Hz``, ``T x``, ``eta % y``, ``dB``,
    ``amplitude N``, ``error %``.
    """
    words = str(header).split()
    if not words:
        return None
    if "Hz" in words:
        return "Hz"
    if words[0] == "T":
        return "T"
    if words[0] == "eta":
        return "eta"
    if "dB" in words:
        return "dB"
    if words[0] == "error":
        return "error"
    if words[-1] == "N":
        return "N"
    return None


def print_setup(ws, header_rows: int = 0, one_page: bool = False, freeze: bool = True) -> None:
    """Print *ws* landscape on A4, one page wide (and tall for *one_page*).

    Parameters
    ----------
    header_rows : int
        Rows repeated at the top of every printed page (and frozen on screen
        if *freeze*).
    """
    ws.page_setup.orientation = "landscape"
    ws.page_setup.paperSize = ws.PAPERSIZE_A4
    ws.sheet_properties.pageSetUpPr = PageSetupProperties(fitToPage=True)
    ws.page_setup.fitToWidth = 1
    ws.page_setup.fitToHeight = 1 if one_page else 0
    ws.page_margins.left = ws.page_margins.right = 0.5
    ws.page_margins.top = ws.page_margins.bottom = 0.6
    if header_rows:
        if freeze:
            ws.freeze_panes = f"A{header_rows + 1}"
        ws.print_title_rows = f"1:{header_rows}"
