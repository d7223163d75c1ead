"""How the sheets this package writes look on screen and on paper: number formats and print setup.

One home for the number format of each quantity, used by the result sheets
written back into a case workbook, the report workbook and the template.
"""
from __future__ import annotations

import textwrap
from copy import copy

from openpyxl.cell.cell import Cell
from openpyxl.chart import Series
from openpyxl.styles import Alignment, Font, PatternFill
from openpyxl.styles.cell_style import StyleArray
from openpyxl.utils import get_column_letter
from openpyxl.worksheet.pagebreak import Break
from openpyxl.worksheet.properties import PageSetupProperties

__all__ = ["FORMATS", "DIRECTION_COLOURS", "quantity_of", "print_setup", "style_series", "write_text_lines",
           "write_table", "write_frame"]

#: Number format of each quantity: eta and errors in %, T in four decimals (scientific below 0.01),
#: levels in dB with one decimal, frequencies in Hz with two, forces in N, dynamic stiffness in N/m
#: with four digits, phases in degrees with one decimal, plain numbers with five significant digits,
#: wall times in s with three decimals, stresses in MPa with one, margins of safety and factors with two,
#: positions in m with four.
FORMATS = {"eta": '0.00" %"', "T": "[<0.01]0.000E+00;0.0000", "dB": "0.0", "Hz": "0.00", "N": "0.000",
           "error": '0.0" %"', "zeta": '0.00" %"', "N/m": "0.000E+00", "deg": "0.0", "number": "0.0000E+00", "s": "0.000",
           "MPa": "0.0", "margin": "0.00", "m": "0.0000"}
#: Line and marker colour of each direction in the charts, as in the pictures (matplotlib's first three).
DIRECTION_COLOURS = {"x": "1F77B4", "y": "FF7F0E", "z": "2CA02C"}
#: Dash of the lines of the first, second, ... curve group of a chart.
_DASHES = ("solid", "dash", "sysDot", "dashDot", "lgDash")
#: Width of a text sheet's column (characters of the default font), the characters of its monospaced
#: lines wrapped within it, their font size and line height, pt: one A4 landscape page wide.
_TEXT_WIDTH, _TEXT_CHARACTERS, _TEXT_SIZE, _TEXT_LINE_HEIGHT = 130, 135, 8, 10.5


def quantity_of(header: str) -> str | None:
    """The :data:`FORMATS` key of a result column from its header (None: text or a plain number).

    Headers name their unit: ``frequency Hz``, ``T x``, ``eta % y``, ``dB``,
    ``amplitude N``, ``error %``, ``wall time s``.
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
    if words[-1] == "s":
        return "s"
    return None


def print_setup(ws, header_rows: int = 0, one_page: bool = False, freeze: bool = True,
                table_below: int = 0) -> None:
    """Print *ws* landscape on A4, one page wide (and tall for *one_page*).

    Parameters
    ----------
    header_rows : int
        Rows repeated at the top of every printed page (and frozen on screen
        if *freeze*).
    table_below : int
        Row of the caption of a table below a chart (its header is the next
        row): the table starts a new page, and its caption and header are
        repeated on every page it continues on.
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
    if table_below:
        ws.row_breaks.append(Break(id=table_below - 1))
        ws.print_title_rows = f"{table_below}:{table_below + 1}"


def style_series(series: Series, direction: str, group: int = 0, markers: bool = False) -> None:
    """Draw a chart curve readably on screen and paper: straight lines, its direction's colour, its group's dash.

    Parameters
    ----------
    series : openpyxl.chart.Series
    direction : str
        ``x``, ``y`` or ``z`` (:data:`DIRECTION_COLOURS`).
    group : int
        Number of the curve's group (a run) in the chart: its dash.
    markers : bool
        Filled markers and no line (points that are not a curve), else a line and no markers.
    """
    colour = DIRECTION_COLOURS[direction]
    series.smooth = False
    line = series.graphicalProperties.line
    if markers:
        series.marker.symbol, series.marker.size = "circle", 7
        series.marker.graphicalProperties.solidFill = colour
        series.marker.graphicalProperties.line.solidFill = colour
        line.noFill = True
    else:
        series.marker.symbol = "none"
        line.solidFill, line.width = colour, 19050        # 1.5 pt
        line.dashStyle = _DASHES[group % len(_DASHES)]


def _unwrapped(line: str) -> str:
    """A line as it was before :func:`write_text_lines` wrapped it (a sheet's lines read back and written again)."""
    first, *rest = line.split("\n")
    return " ".join([first.rstrip(), *(part.strip() for part in rest)]) if rest else line


def write_text_lines(ws, lines: list[str], top: int = 1) -> None:
    """Write text *lines* one per row from row *top*, wrapped to one printed page width.

    A line longer than the page wraps within its row as a paragraph, its
    continuation indented under its text (the row is as high as its
    lines); a monospaced font keeps the columns of tabular lines aligned; a
    line starting with ``Run '`` is bold.
    """
    styles: dict[bool, StyleArray] = {}     # of the plain and the bold lines, each made once and shared
    for row, line in enumerate(lines, start=top):
        line = _unwrapped(line)
        if len(line) <= _TEXT_CHARACTERS and line.isprintable():
            paragraph = [line]              # as textwrap gives it, which takes longer to find out
        else:
            indent = " " * (len(line) - len(line.lstrip()) + 2)
            paragraph = textwrap.wrap(line, _TEXT_CHARACTERS, subsequent_indent=indent, drop_whitespace=False) or [""]
        cell = ws.cell(row, 1, "\n".join(part.rstrip() for part in paragraph))
        bold = line.startswith("Run '")
        if bold in styles:
            cell._style = copy(styles[bold])
        else:
            cell.font = Font(name="Consolas", size=_TEXT_SIZE, bold=bold)
            cell.alignment = Alignment(wrap_text=True, vertical="top")
            styles[bold] = copy(cell._style)
        if len(paragraph) > 1:
            ws.row_dimensions[row].height = _TEXT_LINE_HEIGHT * len(paragraph)
    ws.column_dimensions["A"].width = _TEXT_WIDTH


def write_table(ws, columns, rows, top: int = 1, fill: PatternFill | None = None,
                quantities: dict | None = None) -> None:
    """Write a table with its header in row *top*, each number formatted by its quantity.

    The header is bold (on *fill*), frozen and repeated on every printed
    page; each column is as wide as its header and its texts; a missing
    value (None or NaN) is an empty cell. The rows below *top* are to be
    empty: the table's rows are appended after its header.

    Parameters
    ----------
    columns : sequence of str
        The column headers.
    rows : sequence of sequence
        One value per column each.
    quantities : dict of str to str, optional
        :data:`FORMATS` key per column header, where :func:`quantity_of` does not tell it.
    """
    formats = [FORMATS.get((quantities or {}).get(name) or quantity_of(name) or "") for name in columns]
    for col, name in enumerate(columns, start=1):
        cell = ws.cell(top, col, name)
        cell.font = Font(bold=True)
        if fill is not None:
            cell.fill = fill
        texts = [str(values[col - 1]) for values in rows if isinstance(values[col - 1], str)]
        ws.column_dimensions[get_column_letter(col)].width = max([11, len(str(name)) + 2, *(len(t) + 2 for t in texts)])
    # a column's number cells share the style of its first (setting each cell's format looks it up again: the
    # most of the time of a long table)
    styles: list = [None] * len(formats)
    for values in rows:
        cells = []
        for col, value in enumerate(values):
            if isinstance(value, float) and value != value:     # NaN: no value
                value = None
            elif hasattr(value, "item"):
                value = value.item()
            number = formats[col] is not None and isinstance(value, (int, float)) and not isinstance(value, bool)
            cell = Cell(ws, value=value, style_array=styles[col] if number else None)
            if number and styles[col] is None:
                cell.number_format = formats[col]
                styles[col] = cell._style
            cells.append(cell)
        ws.append(cells)
    print_setup(ws, header_rows=top)


def write_frame(ws, frame, top: int = 1, fill: PatternFill | None = None, quantities: dict | None = None) -> None:
    """Write a pandas DataFrame as :func:`write_table` writes a table (its columns and rows, not its index)."""
    write_table(ws, list(frame.columns), list(frame.itertuples(index=False, name=None)), top, fill, quantities)
