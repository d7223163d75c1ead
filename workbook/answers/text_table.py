"""A table of numbers as text, laid out as ``pandas.DataFrame.to_string`` lays it out, without pandas.

Importing pandas costs a quarter of a second; ``mountwb run`` prints two
small tables and needs nothing else of it. :func:`text_table` gives the
text ``DataFrame.to_string(float_format=...)`` gives for a frame of finite
floats with a named index of strings (``tests/test_warm_paths.py`` checks
the two against each other).
"""
from __future__ import annotations

import math
from typing import Callable, Mapping, Sequence

__all__ = ["text_table"]

#: pandas cuts a text longer than its ``display.max_colwidth`` (50); such a table is left to pandas.
_LONGEST = 50


def text_table(index_name: str, rows: Mapping[str, Sequence[float]], columns: Sequence[str],
               float_format: Callable[[float], str]) -> str | None:
    """The text of a table of floats, one row per label.

    Parameters
    ----------
    index_name : str
        The index's name, on its own line under the header.
    rows : mapping of str to sequence of float
        Row label -> one value per column.
    columns : sequence of str
        Column headers.
    float_format : callable
        Text of one value.

    Returns
    -------
    str or None
        The table; None when a value is not a finite number or a label is
        empty (pandas lays those out by rules of its own: ask pandas).
    """
    labels = list(rows)
    if not labels or not all(labels) or any(not math.isfinite(float(v)) for values in rows.values() for v in values):
        return None
    cells = [[float_format(float(v)) for v in rows[label]] for label in labels]
    if any(len(row) != len(columns) for row in cells):
        raise ValueError(f"every row needs {len(columns)} values")
    if any(len(text) > _LONGEST for text in [index_name, *labels, *columns, *(c for row in cells for c in row)]):
        return None
    # pandas: a numeric column's header gets a leading space; the columns are joined by one space
    headers = [" " + header for header in columns]
    index_width = max(len(index_name), *(len(label) for label in labels))
    widths = [max(len(header), *(len(row[j]) for row in cells)) for j, header in enumerate(headers)]
    header = " " * index_width + "".join(" " + h.rjust(w) for h, w in zip(headers, widths, strict=True))
    lines = [header, index_name.ljust(len(header))]
    for label, row in zip(labels, cells, strict=True):
        lines.append(label.ljust(index_width) + "".join(" " + c.rjust(w) for c, w in zip(row, widths, strict=True)))
    return "\n".join(lines)
