"""The report's pictures: one PNG per run, drawn on one reused Agg figure, here or in a forked process.

Importing matplotlib and drawing the pictures take about as long as
writing the results into the case workbook. :func:`start_pictures` forks a
process before the runs are computed, which imports matplotlib on the
second core meanwhile; :meth:`Pictures.add` sends it what the picture of a
run shows as soon as that run is done, and it draws it while the next runs
are computed (and the last one's while this process writes the results);
:meth:`Pictures.result` collects them. Where no process can be forked (no
``fork``, one core, inside a worker process), or the drawing process
fails, the pictures are drawn in this process: the same bytes either way.
A time-domain run's picture (its force histories) is always drawn here.
"""
from __future__ import annotations

import io
import multiprocessing
import os
import signal
from dataclasses import dataclass

from workbook.model.case import DIRECTIONS
from workbook.processes import end_with_parent, stop_workers

__all__ = ["Pictures", "draw_pictures", "start_pictures"]

#: Size of a picture, in: the bar chart of single runs, the transmissibility of a sweep.
_BARS_SIZE, _SWEEP_SIZE = (7, 4), (8, 4.5)
#: Fixed margins of a picture (fractions of the figure): a layout engine's search costs more than
#: drawing the picture.
_MARGINS = {"left": 0.1, "right": 0.97, "bottom": 0.16, "top": 0.91}
#: Resolution of the pictures, dots per inch.
DPI = 80


@dataclass(frozen=True)
class _Point:
    """What a picture shows of one answer (the fields :meth:`MountResult.draw_efficiency` reads)."""

    name: str
    frequency_hz: float
    transmissibility: tuple
    efficiency: tuple


@dataclass(frozen=True)
class _Picture:
    """What the picture of one run shows: plain data, sent to the drawing process."""

    case_name: str
    run_name: str
    points: tuple


def _picture(run) -> _Picture | None:
    """The picture of *run*, or None for a time-domain run (drawn by its own figure, here)."""
    result = run.result
    if len(result.runs) == 1 and result.runs[0].has_histories:
        return None
    points = tuple(_Point(p.name, float(p.frequency_hz), tuple(map(float, p.transmissibility)),
                          tuple(map(float, p.efficiency))) for p in result.runs)
    return _Picture(result.case_name, run.spec.name, points)


def _draw(fig, picture: _Picture) -> None:
    """Draw *picture* on the cleared figure *fig*: the efficiency bars of a single run, T of a sweep."""
    from workbook.answers.results import MountResult

    single = len(picture.points) == 1
    fig.clear()
    fig.set_size_inches(_BARS_SIZE if single else _SWEEP_SIZE)
    fig.subplots_adjust(**_MARGINS)
    ax = fig.add_subplot()
    if single:
        MountResult(picture.case_name, list(picture.points)).draw_efficiency(ax)
        return
    frequencies = [p.frequency_hz for p in picture.points]
    for i, d in enumerate(DIRECTIONS):
        ax.loglog(frequencies, [p.transmissibility[i] for p in picture.points], marker="o", ms=3, label=d)
    ax.axhline(1.0, color="0.6", lw=0.8, ls="--")
    ax.set_xlabel("frequency Hz")
    ax.set_ylabel("pylon transmissibility T")
    ax.legend(title="direction")
    ax.set_title(f"{picture.case_name}: {picture.run_name}", y=1.0)   # placed: matplotlib's search costs a third


def _figure():
    """The figure the pictures are drawn on, one after the other (Agg)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure()
    FigureCanvasAgg(fig)
    return fig


def _drawn(fig, picture: _Picture | None) -> bytes | None:
    """The PNG of *picture* drawn on *fig* (None for None)."""
    if picture is None:
        return None
    _draw(fig, picture)
    return _png(fig)


def _draw_all(pictures: list) -> list:
    """The PNG of each picture (None where the picture is None)."""
    fig = _figure()
    return [_drawn(fig, picture) for picture in pictures]


def _png(fig) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=DPI)
    return buffer.getvalue()


def draw_pictures(runs, drawn: list | None = None) -> list[bytes]:
    """The picture of each run, PNG: the pylon isolation efficiency of a single run (bars), T against
    frequency of a sweep, the force histories of a time-domain run.

    Parameters
    ----------
    runs : list of workbook.excel.writer.RunResult
    drawn : list, optional
        The PNGs drawn already (by the drawing process), None where a run's is still to draw.

    Returns
    -------
    list of bytes
        One PNG per run, in order.
    """
    if drawn is None:
        drawn = _draw_all([_picture(run) for run in runs])
    pictures = []
    for run, png in zip(runs, drawn, strict=True):
        if png is None:
            import matplotlib
            import matplotlib.pyplot as plt

            matplotlib.use("Agg")
            histories = run.result.plot_time_histories()
            png = _png(histories)
            plt.close(histories)
        pictures.append(png)
    return pictures


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


#: What :meth:`Pictures.result` sends the drawing process when every picture has been sent.
_END = "end"


def _draw_and_send(connection) -> None:
    """In the forked process: import matplotlib, draw each picture as it comes, send them all at the end
    (None if drawing failed)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's: it stops this process
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # stopped by the parent: end quietly, not as the parent's handler does
    end_with_parent()
    drawn: list[bytes | None] | None = None
    try:
        fig = _figure()  # the import of matplotlib is the work done while the first run is computed
        drawn = []
    except Exception:  # noqa: BLE001 - the parent draws the pictures and meets the error itself
        pass
    while True:
        try:
            picture = connection.recv()
        except (EOFError, OSError):  # the parent has no (more) pictures for this process
            return
        if picture == _END:
            break
        if drawn is not None:
            try:
                drawn.append(_drawn(fig, picture))
            except Exception:  # noqa: BLE001 - the parent draws them again and meets the error itself
                drawn = None
    connection.send(drawn)
    connection.close()


class Pictures:
    """A forked process that draws the pictures of runs (or, failing that, they are drawn here).

    Made by :func:`start_pictures` before the runs; :meth:`add` hands it each run as it is done,
    :meth:`result` gives their pictures, :meth:`close` stops the process.
    """

    def __init__(self):
        self._runs: list = []
        self._process = None
        self._connection = None
        if _cores() < 2 or "fork" not in multiprocessing.get_all_start_methods() \
                or multiprocessing.current_process().daemon:
            return
        context = multiprocessing.get_context("fork")
        here, there = context.Pipe(duplex=True)
        process = context.Process(target=_draw_and_send, args=(there,), daemon=True, name="mountwb report pictures")
        try:
            process.start()
        except OSError:
            here.close()
            return
        finally:
            there.close()
        self._process, self._connection = process, here

    def add(self, run) -> None:
        """Have the picture of *run* (a workbook.excel.writer.RunResult) drawn, after those added before."""
        self._runs.append(run)
        if self._connection is not None:
            try:
                self._connection.send(_picture(run))
            except OSError:
                self.close()

    def result(self) -> list[bytes]:
        """The PNG of each run given to :meth:`add`, in order: from the forked process, or drawn here."""
        drawn = None
        if self._connection is not None:
            try:
                self._connection.send(_END)
                drawn = self._connection.recv()
            except (EOFError, OSError):
                drawn = None
            finally:
                self.close()
        return draw_pictures(self._runs, drawn)

    def close(self) -> None:
        """Stop the forked process if it still runs (nothing is left to do once :meth:`result` was taken)."""
        if self._connection is not None:
            self._connection.close()
            self._connection = None
        if self._process is not None:
            self._process.join(timeout=1.0)
            stop_workers([self._process])
            self._process = None


def start_pictures() -> Pictures:
    """Fork the process that will draw a report's pictures; it imports matplotlib at once.

    Returns
    -------
    Pictures
        Hand it each run with :meth:`Pictures.add`, take the PNGs with
        :meth:`Pictures.result`; call :meth:`Pictures.close` when they will
        not be taken (an error on the way).
    """
    return Pictures()
