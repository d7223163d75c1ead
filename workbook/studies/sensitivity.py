"""The table of a parameter study, its sensitivity plots and its files.

One table row per study row and run (excitation): the row number, the
parameter values, the run, its frequency, T and eta per direction, whether
it was steady, the row's wall time, status and error (a failed row has one
table row with its error and no answers).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from workbook.model.case import DIRECTIONS
from workbook.studies.parametric import PARAMETERS

__all__ = ["study_frame", "plot_sensitivity", "write_study", "TABLE_FORMATS"]

#: File formats of the study table.
TABLE_FORMATS = ("csv", "parquet")


def study_frame(rows: tuple, outcomes: list):
    """The study table.

    Parameters
    ----------
    rows : tuple of dict
        Parameter values of each study row.
    outcomes : list of RowOutcome
        In row order.

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd

    records = []
    for row, outcome in zip(rows, outcomes):
        common = {"row": outcome.index, **row}
        tail = {"wall time s": outcome.wall_time, "status": outcome.status, "error": outcome.error}
        for run in outcome.runs or [{}]:
            records.append({**common, **run, **tail})
    frame = pd.DataFrame.from_records(records)
    answers = ["run", "frequency Hz", *(f"T {d}" for d in DIRECTIONS), *(f"eta % {d}" for d in DIRECTIONS),
               "steady"]
    for column in answers:  # a study whose rows all failed still has every column
        if column not in frame:
            frame[column] = np.nan
    names = list(rows[0]) if rows else []
    return frame[["row", *names, *answers, "wall time s", "status", "error"]]


def plot_sensitivity(frame, parameters: list[str]):
    """T per direction against each parameter, one panel per parameter and run.

    Parameters
    ----------
    frame : pandas.DataFrame
        From :func:`study_frame`.
    parameters : list of str
        The varied parameters (columns of *frame*).

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    ok = frame[frame["status"] == "ok"]
    runs = list(dict.fromkeys(ok["run"])) or [""]
    fig, axes = plt.subplots(len(runs), max(len(parameters), 1), squeeze=False, constrained_layout=True,
                             figsize=(3.6 * max(len(parameters), 1), 2.8 * len(runs)))
    for i, run in enumerate(runs):
        data = ok[ok["run"] == run]
        for j, name in enumerate(parameters):
            ax = axes[i, j]
            if PARAMETERS[name].numeric:
                x = data[name].astype(float)
            else:
                labels = list(dict.fromkeys(ok[name]))
                x = data[name].map(labels.index)
                ax.set_xticks(range(len(labels)), labels)
            for axis in DIRECTIONS:
                ax.plot(x, data[f"T {axis}"], "o", ms=4, alpha=0.7, label=f"T {axis}")
            unit = PARAMETERS[name].unit
            ax.set_xlabel(name if unit in ("-", "text") else f"{name} [{unit}]")
            if j == 0:
                ax.set_ylabel(f"{run}\nT")
    axes[0, 0].legend(fontsize="small")
    fig.suptitle(f"sensitivity of the pylon transmissibility ({int((frame['status'] != 'ok').sum())} "
                 f"failed rows not shown)")
    return fig


def write_study(frame, parameters: list[str], folder: str | Path, table_format: str = "csv") -> list[Path]:
    """Write the table (CSV or Parquet, and a sheet) and the sensitivity plot.

    Returns
    -------
    list of Path
        ``parameter-study.<csv|parquet>``, ``parameter-study.xlsx``,
        ``parameter-study.png`` in *folder*.
    """
    if table_format not in TABLE_FORMATS:
        raise ValueError(f"table format must be one of {', '.join(TABLE_FORMATS)}, got {table_format!r}")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    table = folder / f"parameter-study.{table_format}"
    if table_format == "csv":
        frame.to_csv(table, index=False)
    else:
        frame.to_parquet(table, index=False)
    sheet = folder / "parameter-study.xlsx"
    frame.to_excel(sheet, sheet_name="Parameter study", index=False)
    plot = folder / "parameter-study.png"
    figure = plot_sensitivity(frame, parameters)
    figure.savefig(plot, dpi=120)
    import matplotlib.pyplot as plt

    plt.close(figure)
    return [table, sheet, plot]
