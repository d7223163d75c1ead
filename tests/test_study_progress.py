"""The study's progress line (rows per second, time left, a stall made visible) and its table file,
written at most every WRITE_INTERVAL s and always complete after a flush."""
from __future__ import annotations

import io
import time

import pandas as pd
import pytest

from workbook.studies import sensitivity
from workbook.studies.parallel import RowOutcome
from workbook.studies.progress import RATE_SPAN, StudyProgress, duration
from workbook.studies.sensitivity import StudyTable


class Clock:
    """A clock the test moves by hand, s."""

    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


@pytest.mark.parametrize("seconds, words", [(0.4, "0 s"), (44.6, "45 s"), (725, "12 min 5 s"), (12_000, "3 h 20 min")])
def test_durations_read_at_a_glance(seconds, words):
    assert duration(seconds) == words


def test_rate_and_time_left_count_only_the_rows_of_this_run():
    clock = Clock()
    progress = StudyProgress(100, already=10, clock=clock, interval=10.0)
    clock.now += 3.0
    assert progress.line() == "study rows: 10 of 100 done (10.0 %), no row finished yet in 3 s"
    progress.update(12, 100)          # the first rows, after a start-up of 3 s: no rate yet
    assert progress.line() == "study rows: 12 of 100 done (12.0 %)"
    clock.now += 4.0
    progress.update(20, 100)          # 8 rows in 4 s: 2 rows/s, 80 rows left: 40 s
    assert progress.line() == "study rows: 20 of 100 done (20.0 %), 2 rows/s, about 40 s left"


def test_rows_finished_together_give_no_rate_until_rows_finished_over_time():
    """Two workers end their first slow rows together: 1 row in 0.05 s was 20 rows/s, "about 0 s left" of a
    study of a minute; the rate waits for rows over half the first row's time (RATE_SPAN s at most)."""
    clock = Clock()
    progress = StudyProgress(6, clock=clock, interval=10.0)
    clock.now += 20.0
    progress.update(1)
    clock.now += 0.05
    progress.update(2)
    assert progress.line() == "study rows: 2 of 6 done (33.3 %)"
    clock.now += 19.95
    progress.update(4)                # 3 rows in 20 s since the first: 0.15 rows/s, 2 left: 13 s
    assert progress.line() == "study rows: 4 of 6 done (66.7 %), 0.15 rows/s, about 13 s left"
    long = StudyProgress(10_000, clock=clock, interval=10.0)
    clock.now += 3600.0               # an hour of link reductions before the first row
    long.update(1)
    clock.now += RATE_SPAN
    long.update(601)
    assert long.line() == "study rows: 601 of 10000 done (6.0 %), 10 rows/s, about 15 min 40 s left"


def test_a_stall_shows_as_the_time_since_the_last_row():
    clock = Clock()
    progress = StudyProgress(400, clock=clock, interval=10.0)
    clock.now += 20.0
    progress.update(2)                # the start-up: 20 s
    clock.now += 49.0
    progress.update(100)              # 98 rows in 49 s: 2 rows/s, 300 left: 2 min 30 s
    clock.now += 95.0                 # then nothing
    assert progress.line() == ("study rows: 100 of 400 done (25.0 %), 2 rows/s, about 2 min 30 s left "
                               "(last row finished 1 min 35 s ago)")


def test_lines_come_while_running_and_once_at_the_end():
    stream = io.StringIO()
    with StudyProgress(3, stream=stream, interval=0.05) as progress:
        time.sleep(0.3)
        progress.update(1)
        time.sleep(0.01)
        progress.update(3)
    lines = stream.getvalue().splitlines()
    assert len(lines) >= 3            # the heartbeat printed while no row finished
    assert lines[0].startswith("study rows: 0 of 3 done (0.0 %), no row finished yet in")
    assert lines[-1].startswith("study rows: 3 of 3 done (100.0 %)")


def _outcome(index):
    return RowOutcome(index, [{"run": "LP rotor", "frequency Hz": 59.0, "T x": 0.1, "T y": 0.2, "T z": 0.3,
                               "eta % x": 90.0, "eta % y": 80.0, "eta % z": 70.0, "steady": True}], wall_time=0.1)


def test_the_table_file_is_written_at_most_every_interval_and_completely_on_flush(tmp_path, monkeypatch):
    monkeypatch.setattr(sensitivity, "WRITE_INTERVAL", 3600.0)
    rows = tuple({"hinge_stiffness": 1e7 * (i + 1)} for i in range(4))
    path = tmp_path / "study.csv"
    table = StudyTable(path, rows)
    table.add(_outcome(2))            # the first row is written at once
    table.add(_outcome(0))            # within the interval: kept in memory only
    assert list(pd.read_csv(path)["row"]) == [2] and table.kept == 1
    table.flush()
    assert list(pd.read_csv(path)["row"]) == [0, 2] and table.kept == 2
    stamp = path.stat().st_mtime_ns
    table.flush()                     # nothing new: the file is left alone
    assert path.stat().st_mtime_ns == stamp
    monkeypatch.setattr(sensitivity, "WRITE_INTERVAL", 0.0)
    monkeypatch.setattr(sensitivity, "WRITE_SHARE", 0.0)
    table.add(_outcome(1))
    assert list(pd.read_csv(path)["row"]) == [0, 1, 2] and table.kept == 3


def test_a_table_that_takes_long_to_write_is_written_less_often(tmp_path, monkeypatch):
    """The next write waits WRITE_SHARE times the last write's own time: however large the table grows, writing
    it takes at most a share of the study."""
    monkeypatch.setattr(sensitivity, "WRITE_INTERVAL", 0.0)
    monkeypatch.setattr(sensitivity, "WRITE_SHARE", 1e9)
    rows = tuple({"hinge_stiffness": 1e7 * (i + 1)} for i in range(3))
    path = tmp_path / "study.csv"
    table = StudyTable(path, rows)
    table.add(_outcome(0))            # the first write: it took some time, so ...
    table.add(_outcome(1))            # ... the next row waits far longer than the interval
    assert list(pd.read_csv(path)["row"]) == [0] and table.kept == 1
    monkeypatch.setattr(sensitivity, "WRITE_SHARE", 0.0)
    table.add(_outcome(2))
    assert list(pd.read_csv(path)["row"]) == [0, 1, 2]
