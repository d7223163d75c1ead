"""The report's pictures: one PNG per run, drawn on one reused Agg figure, here or in a forked process.

Importing matplotlib and drawing the pictures take about as long as
writing the results into the case workbook: :func:`start_pictures` draws
them in a forked process meanwhile, on the second core, and
:meth:`Pictures.result` collects them. Where no process can be forked (no
``fork``, one core, inside a worker process), or the drawing process fails,
the pictures are drawn in this process: the same bytes either way.
"""
from __future__ import annotations

import io
import multiprocessing
import os
import signal

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


def _draw(fig, run) -> bool:
    """Draw the picture of *run* on the cleared figure *fig*; False for a time-domain run, whose
    histories are drawn by :meth:`~workbook.answers.results.MountResult.plot_time_histories`."""
    result = run.result
    single = len(result.runs) == 1
    if single and result.runs[0].has_histories:
        return False
    fig.clear()
    fig.set_size_inches(_BARS_SIZE if single else _SWEEP_SIZE)
    fig.subplots_adjust(**_MARGINS)
    ax = fig.add_subplot()
    if single:
        result.draw_efficiency(ax)
        return True
    frequencies = [p.frequency_hz for p in result.runs]
    for i, d in enumerate(DIRECTIONS):
        ax.loglog(frequencies, [p.transmissibility[i] for p in result.runs], marker="o", ms=3, label=d)
    ax.axhline(1.0, color="0.6", lw=0.8, ls="--")
    ax.set_xlabel("frequency Hz")
    ax.set_ylabel("pylon transmissibility T")
    ax.legend(title="direction")
    ax.set_title(f"{result.case_name}: {run.spec.name}", y=1.0)   # placed: matplotlib's search costs a third
    return True


def _png(fig) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=DPI)
    return buffer.getvalue()


def draw_pictures(runs) -> list[bytes]:
    """The picture of each run, PNG: the pylon isolation efficiency of a single run (bars), T against
    frequency of a sweep, the force histories of a time-domain run.

    Parameters
    ----------
    runs : list of workbook.excel.writer.RunResult

    Returns
    -------
    list of bytes
        One PNG per run, in order.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure()
    FigureCanvasAgg(fig)
    pictures = []
    for run in runs:
        if _draw(fig, run):
            pictures.append(_png(fig))
            continue
        import matplotlib
        import matplotlib.pyplot as plt

        matplotlib.use("Agg")
        histories = run.result.plot_time_histories()
        pictures.append(_png(histories))
        plt.close(histories)
    return pictures


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _draw_and_send(runs, connection) -> None:
    """In the forked process: draw the pictures and send them (None if drawing failed)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's: it stops this process
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # stopped by the parent: end quietly, not as the parent's handler does
    end_with_parent()
    try:
        pictures = draw_pictures(runs)
    except Exception:  # noqa: BLE001 - the parent draws them again and meets the error itself
        pictures = None
    connection.send(pictures)
    connection.close()


class Pictures:
    """The pictures of runs, being drawn in a forked process (or, failing that, to be drawn here).

    Parameters
    ----------
    runs : list of workbook.excel.writer.RunResult
    """

    def __init__(self, runs):
        self._runs = list(runs)
        self._process = None
        self._connection = None
        if _cores() < 2 or "fork" not in multiprocessing.get_all_start_methods() \
                or multiprocessing.current_process().daemon:
            return
        context = multiprocessing.get_context("fork")
        receive, send = context.Pipe(duplex=False)
        process = context.Process(target=_draw_and_send, args=(self._runs, send), daemon=True,
                                  name="mountwb report pictures")
        try:
            process.start()
        except OSError:
            receive.close()
            return
        finally:
            send.close()
        self._process, self._connection = process, receive

    def result(self) -> list[bytes]:
        """The PNG of each run, in order: from the forked process, or drawn here if it has none."""
        pictures = None
        if self._connection is not None:
            try:
                pictures = self._connection.recv()
            except (EOFError, OSError):
                pictures = None
            finally:
                self.close()
        return draw_pictures(self._runs) if pictures is None else pictures

    def close(self) -> None:
        """Stop the forked process if it still runs (nothing else to do once :meth:`result` was taken)."""
        if self._connection is not None:
            self._connection.close()
            self._connection = None
        if self._process is not None:
            self._process.join(timeout=1.0)
            stop_workers([self._process])
            self._process = None


def start_pictures(runs) -> Pictures:
    """Start drawing the pictures of *runs* in a forked process; :meth:`Pictures.result` gives them.

    Parameters
    ----------
    runs : list of workbook.excel.writer.RunResult

    Returns
    -------
    Pictures
        Call :meth:`Pictures.close` when the pictures will not be taken (an error on the way).
    """
    return Pictures(runs)
