"""The table of a parameter study, its sensitivity plots and its files.

One table row per study row and run (excitation): the row number, the
parameter values, the run, its frequency, T and eta per direction, whether
it was steady, the row's wall time, status and error (a failed row has one
table row with its error and no answers).

While a study runs, :class:`StudyTable` keeps its table file up to date:
the whole table is written to a temporary file and renamed over the old
one, so the file never holds half of a row. It is written when a row
finishes at least :data:`WRITE_INTERVAL` s after the last write, and at
least :data:`WRITE_SHARE` times the last write's own time after it (a long
study does not spend its time rewriting a growing table), and once more by
:meth:`StudyTable.flush` at the end or on an interrupt: an interrupted
study keeps every finished row, a study killed outright (SIGKILL) those of
its last write.
:func:`read_finished` reads such a table back to resume the study.
"""
from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Literal, get_args

from flexbodies.atomic import replacing
from workbook.answers.saving import free_stem, save_csv, save_figure
from workbook.errors import UsageError
from workbook.model.case import DIRECTIONS
from workbook.studies.parallel import RowOutcome
from workbook.studies.parametric import parameter

__all__ = ["study_frame", "plot_sensitivity", "write_study", "TABLE_FORMATS", "StudyTable", "table_path",
           "new_study_table", "STUDY_STEM", "read_finished", "WRITE_INTERVAL", "WRITE_SHARE"]

TableFormat = Literal["csv", "parquet"]
#: File formats of the study table.
TABLE_FORMATS: tuple[TableFormat, ...] = get_args(TableFormat)
#: Least time between two writes of a running study's table file, s: written
#: after every row, a long study's growing table would cost more than its rows
#: (docs/reliability.md, ``benchmarks/bench_study_table.py``).
WRITE_INTERVAL = 2.0
#: Rows wait for the next write at least this many times the last write's time: writing takes a tenth of a
#: study's time at most, however long its table grows.
WRITE_SHARE = 10.0
#: Columns of a row's wall time, how it was answered (:data:`workbook.studies.parallel.NUMPY_PATH` or
#: ``EXUDYN_PATH``), its status and error.
TAIL = ("wall time s", "path", "status", "error")
#: Columns of a run's answers.
ANSWERS = ("run", "frequency Hz", *(f"T {d}" for d in DIRECTIONS), *(f"eta % {d}" for d in DIRECTIONS), "steady")


def study_frame(rows: tuple, outcomes: list):
    """The study table.

    Parameters
    ----------
    rows : tuple of dict
        Parameter values of each study row.
    outcomes : list of RowOutcome
        In row order (all rows, or those finished so far).

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd

    records = []
    for outcome in outcomes:
        common = {"row": outcome.index, **rows[outcome.index]}
        tail = {"wall time s": outcome.wall_time, "path": outcome.path, "status": outcome.status,
                "error": outcome.error}
        for run in outcome.runs or [{}]:
            records.append({**common, **run, **tail})
    names = list(rows[0]) if rows else []
    columns = ["row", *names, *ANSWERS, *TAIL]
    # every column, also when every row failed
    return pd.DataFrame.from_records(records, columns=columns)


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
            if parameter(name).numeric:
                x = data[name].astype(float)
            else:
                labels = list(dict.fromkeys(ok[name]))
                x = data[name].map(labels.index)
                ax.set_xticks(range(len(labels)), labels)
            for axis in DIRECTIONS:
                ax.plot(x, data[f"T {axis}"], "o", ms=4, alpha=0.7, label=f"T {axis}")
            unit = parameter(name).unit
            ax.set_xlabel(name if unit in ("-", "text") else f"{name} [{unit}]")
            if j == 0:
                ax.set_ylabel(f"{run}\nT")
    axes[0, 0].legend(fontsize="small")
    fig.suptitle(f"sensitivity of the pylon transmissibility ({int((frame['status'] != 'ok').sum())} "
                 f"failed rows not shown)")
    return fig


#: Name of a study's files, before ``-2``, ``-3``... (another study's files in the folder) and the ending.
STUDY_STEM = "parameter-study"


def table_path(folder: str | Path, table_format: TableFormat = "csv", stem: str = STUDY_STEM) -> Path:
    """The study table's file in *folder*: ``<stem>.<csv|parquet>`` (``parameter-study.csv``)."""
    if table_format not in TABLE_FORMATS:
        raise ValueError(f"table format must be one of {', '.join(TABLE_FORMATS)}, got {table_format!r}")
    return Path(folder) / f"{stem}.{table_format}"


def new_study_table(folder: str | Path, table_format: TableFormat = "csv", stem: str = STUDY_STEM) -> Path:
    """The table file of a new study in *folder*: ``<stem>`` (``parameter-study``), or ``<stem>-2``... when a
    file of an earlier study (its table, sheet or plot) is there, which is kept."""
    return table_path(folder, table_format, free_stem(folder, stem, (f".{table_format}", ".xlsx", ".png")))


def _write_table(frame, path: Path) -> None:
    """Write *frame* to *path* (format by its ending) all at once."""
    if path.suffix == ".csv":
        save_csv(frame, path, index=False)
        return
    with replacing(path, suffix=".parquet.tmp") as temporary:
        frame.to_parquet(temporary, index=False)


class StudyTable:
    """The table file of a running study, rewritten atomically as rows finish.

    Parameters
    ----------
    path : Path
        From :func:`table_path`.
    rows : tuple of dict
        Parameter values of every study row.
    finished : dict of int to RowOutcome, optional
        Rows already in the table (a resumed study).
    """

    def __init__(self, path: Path, rows: tuple, finished: dict | None = None):
        self.path, self.rows = Path(path), rows
        self.outcomes = dict(finished or {})
        #: Rows the table file holds.
        self.kept = len(self.outcomes)
        self._written_at = -math.inf
        self._write_seconds = 0.0

    def add(self, outcome: RowOutcome) -> None:
        """Take a finished row; write the table file if the last write is old enough (module text)."""
        self.outcomes[outcome.index] = outcome
        if time.monotonic() - self._written_at >= max(WRITE_INTERVAL, WRITE_SHARE * self._write_seconds):
            self.flush()

    def flush(self) -> None:
        """Write every row taken so far to the table file (if any is not there yet)."""
        if self.kept == len(self.outcomes):
            return
        count, start = len(self.outcomes), time.monotonic()
        _write_table(self.to_pandas(), self.path)
        self.kept, self._written_at = count, time.monotonic()
        self._write_seconds = self._written_at - start

    def to_pandas(self):
        """The table of the rows finished so far, in row order."""
        return study_frame(self.rows, [self.outcomes[i] for i in sorted(self.outcomes)])


def _same_value(stored, value) -> bool:
    if isinstance(value, str):
        return str(stored) == value
    try:
        return math.isclose(float(stored), float(value), rel_tol=1e-12, abs_tol=0.0)
    except (TypeError, ValueError):
        return False


def read_finished(path: str | Path, rows: tuple) -> dict[int, RowOutcome]:
    """The rows a study table already holds, to resume the study.

    Parameters
    ----------
    path : str or Path
        A table written by :class:`StudyTable` (a missing file holds no rows).
    rows : tuple of dict
        The study's rows: the table's must be the same study.

    Returns
    -------
    dict of int to RowOutcome
        Every row in the table (finished, or failed with its error).

    Raises
    ------
    UsageError
        The table is unreadable or belongs to another study (other
        parameters, or other values in a row), naming the row and value.
    """
    import pandas as pd

    path = Path(path)
    if not path.exists():
        return {}
    try:
        frame = pd.read_csv(path, keep_default_na=False, na_values=[""]) if path.suffix == ".csv" \
            else pd.read_parquet(path)
    except (ValueError, OSError, ImportError) as error:
        raise UsageError(f"{path}: cannot resume from it, it is not a readable study table ({error})") from None
    names = list(rows[0]) if rows else []
    expected = ["row", *names, *ANSWERS, *TAIL]
    if list(frame.columns) == [name for name in expected if name != "path"]:
        frame = frame.assign(path="")                # a table written before the path column
        frame = frame[expected]
    if list(frame.columns) != expected:
        raise UsageError(f"{path}: cannot resume from it: its columns are {', '.join(map(str, frame.columns))}; "
                         f"this study's are {', '.join(expected)}")
    finished = {}
    for index, table in frame.groupby("row", sort=True):
        index = int(index)
        if not 0 <= index < len(rows):
            raise UsageError(f"{path}: cannot resume from it: it has row {index}; this study has rows 0 to "
                             f"{len(rows) - 1}")
        first = table.iloc[0]
        for name, value in rows[index].items():
            if not _same_value(first[name], value):
                stored = first[name].item() if hasattr(first[name], "item") else first[name]
                raise UsageError(f"{path}: cannot resume from it: its row {index} has {name} = {stored!r}; "
                                 f"this study's row {index} has {value!r}")
        status = str(first["status"])
        runs = [] if status != "ok" else [
            {"run": str(r["run"]), "frequency Hz": float(r["frequency Hz"]),
             **{f"T {d}": float(r[f"T {d}"]) for d in DIRECTIONS},
             **{f"eta % {d}": float(r[f"eta % {d}"]) for d in DIRECTIONS},
             "steady": str(r["steady"]).lower() == "true"} for _, r in table.iterrows()]
        message = "" if pd.isna(first["error"]) else str(first["error"])
        path_taken = "" if pd.isna(first["path"]) else str(first["path"])
        finished[index] = RowOutcome(index, runs, status, message, float(first["wall time s"]), path_taken)
    return finished


def _study_workbook(frame, parameters: list[str], title: str, sheets: dict):
    """The study table as a workbook that prints readably: each parameter headed by its words and
    unit (``hinge stiffness N/m``), every number formatted by its quantity, the header on every page;
    then a sheet per table of *sheets* (title: frame)."""
    from openpyxl import Workbook

    from workbook.excel.styling import write_frame

    headers = {name: f"{name.replace('_', ' ')} {parameter(name).unit}" for name in parameters
               if parameter(name).numeric}
    workbook = Workbook()
    workbook.active.title = title
    write_frame(workbook.active, frame.rename(columns=headers),
                quantities={header: "number" for header in headers.values()})
    for name, table in sheets.items():
        write_frame(workbook.create_sheet(name), table)
    return workbook


def write_study(frame, parameters: list[str], table: str | Path, *, title: str = "Parameter study",
                sheets: dict | None = None, figure=None, table_written: bool = False) -> list[Path]:
    """Write the table (CSV or Parquet, and a sheet) and the sensitivity plot, each all at once.

    Parameters
    ----------
    frame : pandas.DataFrame
    parameters : list of str
    table : str or Path
        The table file (:func:`table_path`); the sheet and the plot go beside it under its name.
    title : str
        Title of the table's sheet.
    sheets : dict of str to pandas.DataFrame, optional
        More sheets of the workbook, by title.
    figure : matplotlib.figure.Figure, optional
        The plot to write (closed after), instead of :func:`plot_sensitivity`'s.
    table_written : bool
        The table file holds *frame* already (:meth:`StudyTable.flush`): it is not written again.

    Returns
    -------
    list of Path
        ``<table>``, ``<table stem>.xlsx``, ``<table stem>.png``.
    """
    table = Path(table)
    if not table_written:
        _write_table(frame, table)
    sheet = table.with_suffix(".xlsx")
    with replacing(sheet, suffix=".xlsx.tmp") as temporary:
        _study_workbook(frame, parameters, title, sheets or {}).save(temporary)
    plot = table.with_suffix(".png")
    figure = plot_sensitivity(frame, parameters) if figure is None else figure
    save_figure(figure, plot, dpi=120)
    import matplotlib.pyplot as plt

    plt.close(figure)
    return [table, sheet, plot]
