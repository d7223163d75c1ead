"""The progress line of a running study: rows done, rows per second, time left.

:class:`StudyProgress` takes the count of finished rows as they come and
prints one line every :data:`PROGRESS_INTERVAL` s from a background thread,
also while no row finishes, so that a stalled study shows as a growing
"last row ... ago" instead of as silence.
"""
from __future__ import annotations

import threading
import time
from typing import Callable, TextIO

__all__ = ["PROGRESS_INTERVAL", "RATE_SPAN", "StudyProgress", "duration"]

#: Seconds between two progress lines.
PROGRESS_INTERVAL = 10.0
#: Most seconds of finished rows the rate waits for (:meth:`StudyProgress.rate`).
RATE_SPAN = 60.0


def duration(seconds: float) -> str:
    """*seconds* in words an engineer reads at a glance: ``"45 s"``, ``"12 min 5 s"``, ``"3 h 20 min"``."""
    seconds = round(seconds)
    if seconds < 60:
        return f"{seconds} s"
    minutes, seconds = divmod(seconds, 60)
    if minutes < 60:
        return f"{minutes} min {seconds} s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h {minutes} min"


class StudyProgress:
    """Rows per second and the time left of a study; a context manager that prints its line.

    Parameters
    ----------
    total : int
        Rows of the study.
    already : int
        Rows finished before this run (a resumed study); not counted in the rate.
    stream : file, optional
        Where :meth:`__enter__` starts printing a line every *interval* s
        (none: only :meth:`line`).
    interval : float
        s between two lines.
    clock : callable
        Seconds of a monotonic clock (a test's own clock).
    """

    def __init__(self, total: int, already: int = 0, *, stream: TextIO | None = None,
                 interval: float = PROGRESS_INTERVAL, clock: Callable[[], float] = time.monotonic):
        self.total, self.already, self.done = total, already, already
        self.stream, self.interval, self.clock = stream, interval, clock
        self.started = self.last_row = clock()
        self.first_row: tuple[float, int] | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def update(self, done: int, total: int | None = None) -> None:
        """Take the count of finished rows (the ``progress`` callback of :func:`workbook.studies.parallel.run_rows`)."""
        if done != self.done:
            now = self.clock()
            if self.first_row is None:
                self.first_row = (now, done)
            self.done, self.last_row = done, now

    def rate(self) -> float | None:
        """Rows per second, counted from the first row this run finished (the start-up, link
        reductions included, does not slow it); None until rows finished over at least half the time
        the first took (:data:`RATE_SPAN` s at most): rows that workers finish together at first gave
        rates of rows per millisecond, "about 0 s left" of a study of minutes."""
        if self.first_row is None:
            return None
        when, done = self.first_row
        last, now_done = self.last_row, self.done
        if now_done > done and last - when >= max(min((when - self.started) / 2, RATE_SPAN), 1e-9):
            return (now_done - done) / (last - when)
        return None

    def line(self) -> str:
        """``study rows: 664 of 3000 done (22.1 %), 26.5 rows/s, about 1 min 28 s left``."""
        now = self.clock()
        text = f"study rows: {self.done} of {self.total} done ({100.0 * self.done / max(self.total, 1):.1f} %)"
        if self.done == self.already:
            return f"{text}, no row finished yet in {duration(now - self.started)}"
        rate = self.rate()
        if rate is not None:
            text += f", {rate:.3g} rows/s, about {duration((self.total - self.done) / rate)} left"
        if now - self.last_row >= self.interval:
            text += f" (last row finished {duration(now - self.last_row)} ago)"
        return text

    def _print(self) -> None:
        print(self.line(), file=self.stream, flush=True)

    def _beat(self) -> None:
        while not self._stop.wait(self.interval):
            self._print()

    def __enter__(self) -> StudyProgress:
        if self.stream is not None:
            self._thread = threading.Thread(target=self._beat, name="study progress", daemon=True)
            self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            if exc[0] is None:
                self._print()
