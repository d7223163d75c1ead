"""Parameter studies keep their work: a killed worker, Ctrl-C and SIGTERM with
real processes and signals; the table on disk holds every finished row, no
worker outlives the study, and --resume runs only the missing rows."""
from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import pandas as pd
import psutil
import pytest
from cli_signals import ROOT, SIGNAL_EXIT, alive, descendants, files_in, start

from workbook.errors import EXIT_FAILED_ROWS, UsageError
from workbook.model.codec import to_json
from workbook.model.reference import LP_ROTOR, reference_case
from workbook.studies.parallel import START_TRIES, RowOutcome
from workbook.studies.sensitivity import StudyTable, read_finished, table_path

#: Six rows of a few seconds each (rigid links, LP rotor, time domain from rest).
STIFFNESS = "1e7:3.5e7:6"
#: CPU time after which a worker is surely running its row, s (its start-up took about 0.3 s).
WORKING_CPU_S = 1.5


def _time_domain(case):
    """*case* answered in the time domain from rest (rows that take seconds, so a signal finds them running)."""
    return dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method="time", start="rest"))


@pytest.fixture()
def case_file(tmp_path):
    case = _time_domain(dataclasses.replace(reference_case().with_rigid_links(), excitations=(LP_ROTOR,)))
    path = tmp_path / "case.json"
    path.write_text(to_json(case))
    return path


def _study(case_file, output, *extra, group=False):
    return start("study", "params", str(case_file), "--output", str(output), f"--vary=hinge_stiffness={STIFFNESS}",
                 *extra, cwd=case_file.parent, group=group)


def _table(output) -> pd.DataFrame:
    path = table_path(output)
    return pd.read_csv(path) if path.exists() else pd.DataFrame({"row": [], "status": []})


def _wait(condition, timeout=240.0, what="condition"):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for {what}")


def _workers(pid: int) -> list[psutil.Process]:
    """The study's worker processes (not multiprocessing's resource tracker)."""
    found = []
    for child in psutil.Process(pid).children(recursive=True):
        try:
            if "resource_tracker" not in " ".join(child.cmdline()):
                found.append(child)
        except psutil.NoSuchProcess:
            pass
    return found


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
@pytest.mark.parametrize("workers", ["1", "2"])
def test_an_interrupted_study_stops_its_workers_keeps_its_rows_and_resumes(case_file, tmp_path, signum, workers):
    output = tmp_path / "out"
    process = _study(case_file, output, "--workers", workers)
    _wait(lambda: len(_table(output)) >= 1, what="a finished row")
    family = descendants(process.pid)
    process.send_signal(signum)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == SIGNAL_EXIT[signum]
    assert "Traceback" not in stderr
    # no orphans: the workers are stopped, multiprocessing's resource tracker ends once its parent has
    _wait(lambda: not alive(family), timeout=10, what=f"the study's processes {alive(family)} to end")
    last = stderr.strip().splitlines()[-1]
    table = _table(output)
    kept = len(table)
    assert 1 <= kept < 6 and set(table["status"]) == {"ok"}
    assert f"{kept} of 6 rows finished and kept in" in last
    assert not [name for name in files_in(output) if name.endswith(".tmp")]

    resumed = _study(case_file, output, "--workers", workers, "--resume")
    _, stderr = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, stderr
    assert f"6 study rows ({kept} already in" in stderr
    final = _table(output)
    assert list(final["row"]) == list(range(6)) and set(final["status"]) == {"ok"}
    # the kept rows were not run again: every value, their wall times too, as written before the interrupt
    pd.testing.assert_frame_equal(final.set_index("row").loc[table["row"]], table.set_index("row"))


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_to_the_whole_process_group_ends_the_study_within_seconds(case_file, tmp_path, signum):
    """As ``timeout``, a job scheduler or Ctrl-C at a terminal do: the signal reaches the workers too."""
    output = tmp_path / "out"
    process = _study(case_file, output, "--workers", "2", group=True)
    _wait(lambda: len(_table(output)) >= 1, what="a finished row")
    family = descendants(process.pid)
    sent = time.monotonic()
    os.killpg(process.pid, signum)
    _, stderr = process.communicate(timeout=60)
    assert time.monotonic() - sent < 15, "the study took more than 15 s to end after the signal"
    assert process.returncode == SIGNAL_EXIT[signum]
    assert "Traceback" not in stderr
    _wait(lambda: not alive(family), timeout=10, what=f"the study's processes {alive(family)} to end")
    kept = len(_table(output))
    assert 1 <= kept < 6
    assert f"{kept} of 6 rows finished and kept in" in stderr.strip().splitlines()[-1]


#: A study of more rows than ``workers * rows_per_worker``: three chunks, each in a fresh pool.
_CHUNKED_STUDY = textwrap.dedent("""
    import dataclasses, json, sys
    from workbook.model.reference import LP_ROTOR, reference_case
    from workbook.studies.parallel import run_rows
    from workbook.studies.parametric import grid, linear_range, study_cases

    if __name__ == "__main__":
        case = dataclasses.replace(reference_case().with_rigid_links(), excitations=(LP_ROTOR,))
        cases = study_cases(case, grid({"hinge_stiffness": linear_range(1e7, 3e7, 9)}))
        workers = int(sys.argv[1])
        outcomes = run_rows(cases, workers=workers, rows_per_worker=2)
        print(json.dumps([[o.status, o.runs[0]["T z"] if o.runs else None] for o in outcomes]))
""")


@pytest.mark.slow
def test_a_study_of_more_rows_than_its_workers_chunk_finishes(tmp_path):
    """Nine rows on two workers of two rows each: the chunks run in fresh pools and give the serial answers."""
    script = tmp_path / "chunked.py"
    script.write_text(_CHUNKED_STUDY)
    environment = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
    answers = {}
    for workers in ("2", "1"):
        done = subprocess.run([sys.executable, str(script), workers], env=environment, capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        answers[workers] = json.loads(done.stdout.strip().splitlines()[-1])
    assert [status for status, _ in answers["2"]] == ["ok"] * 9
    assert answers["2"] == answers["1"]
    t_z = [t for _, t in answers["1"]]
    assert len(set(t_z)) == 9        # every row ran with its own stiffness


#: Rows of a script read from standard input (``python -``), whose main module a spawned worker cannot import.
_FROM_STDIN = textwrap.dedent("""
    import dataclasses, json, sys
    from workbook.model.reference import LP_ROTOR, reference_case
    from workbook.studies.parallel import _run_processes, run_rows
    from workbook.studies.parametric import grid, linear_range, study_cases

    case = dataclasses.replace(reference_case().with_rigid_links(), excitations=(LP_ROTOR,))
    cases = study_cases(case, grid({"hinge_stiffness": linear_range(1e7, 3e7, 3)}))
    if sys.argv[1] == "run_rows":
        outcomes = run_rows(cases, workers=2)
    else:                                  # the pool itself, as it would start its workers
        outcomes = []
        _run_processes(dict(enumerate(cases)), 2, outcomes.append, 2, None)
    print(json.dumps([[o.index, o.status, o.error, o.runs[0]["T z"] if o.runs else None] for o in outcomes]))
""")


@pytest.mark.slow
def test_a_study_from_standard_input_runs_its_rows_here_and_a_pool_that_cannot_start_ends(tmp_path):
    """``python -`` has no main module file for spawned workers to import: the rows run in the process
    itself, with the answers of a script file; a process pool whose workers cannot start reports its rows
    failed instead of starting new pools for ever."""
    script = tmp_path / "chunked.py"
    script.write_text(_CHUNKED_STUDY.replace("linear_range(1e7, 3e7, 9)", "linear_range(1e7, 3e7, 3)"))
    environment = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
    from_file = subprocess.run([sys.executable, str(script), "2"], env=environment, capture_output=True, text=True,
                               timeout=300)
    assert from_file.returncode == 0, from_file.stderr
    expected = [t for _, t in json.loads(from_file.stdout.strip().splitlines()[-1])]
    here = subprocess.run([sys.executable, "-", "run_rows"], input=_FROM_STDIN, env=environment, cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert here.returncode == 0, here.stderr
    assert "cannot be imported by a worker process: the rows run in this process" in here.stderr
    rows = json.loads(here.stdout.strip().splitlines()[-1])
    assert [status for _, status, _, _ in rows] == ["ok"] * 3 and [t for *_, t in rows] == expected
    pool = subprocess.run([sys.executable, "-", "pool"], input=_FROM_STDIN, env=environment, cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert pool.returncode == 0, pool.stderr
    rows = json.loads(pool.stdout.strip().splitlines()[-1])
    assert sorted(index for index, *_ in rows) == [0, 1, 2]
    assert all(status == "failed" and error.startswith("WorkerDied: no worker process could start a row")
               for _, status, error, _ in rows)


#: A study of rows the prepared linear mount answers, whose worker processes are killed (SIGKILL) as they start,
#: before they read the mount sent to them: always ("always"), or the first one only (the file it creates).
_DYING_WORKERS = textwrap.dedent("""
    import os, signal
    if __name__ == "__mp_main__":                 # a worker process imports the main script as it starts
        marker = os.environ["WORKERS_DIE"]
        if marker == "always" or not os.path.exists(marker):
            if marker != "always":
                open(marker, "w").close()
            os.kill(os.getpid(), signal.SIGKILL)

    import dataclasses, json, sys
    from workbook.model.reference import LP_ROTOR, reference_case
    from workbook.studies.parallel import _run_processes, prepare_design_model, run_rows
    from workbook.studies.parametric import grid, linear_range, study_cases

    if __name__ == "__main__":
        case = dataclasses.replace(reference_case().with_rigid_links(), excitations=(LP_ROTOR,))
        if sys.argv[1] == "mount":
            cases = study_cases(case, grid({"hinge_stiffness": linear_range(1e7, 3e7, 300)}))
            outcomes = run_rows(cases, workers=2, design_model=prepare_design_model(case))
        else:                                     # rows handed to the pool one by one, 100,000 of them
            outcomes = []
            _run_processes(dict.fromkeys(range(100_000), case), 2, outcomes.append, 100_000, None)
        print(json.dumps([len(outcomes), sorted({(o.status, o.error) for o in outcomes})]))
""")


@pytest.mark.slow
@pytest.mark.parametrize(("die", "rows"), [("always", "mount"), ("first", "mount"), ("always", "many")])
def test_workers_killed_as_they_start_never_hang_the_study(tmp_path, die, rows):
    """The prepared linear mount (megabytes) goes to each worker as it starts: a worker killed before it read
    it all blocked the study for ever. Now a pool whose workers die as they start is started again, at most
    START_TRIES times, then its rows are reported failed; one death costs nothing but a new pool. A death while
    the rows were still handed to the pool ("many") ended the study with an internal error (BrokenProcessPool)."""
    script = tmp_path / "dying.py"
    script.write_text(_DYING_WORKERS)
    marker = "always" if die == "always" else str(tmp_path / "died")
    environment = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1", "WORKERS_DIE": marker}
    done = subprocess.run([sys.executable, str(script), rows], env=environment, capture_output=True, text=True,
                          timeout=240)
    assert done.returncode == 0, done.stderr
    count, answers = json.loads(done.stdout.strip().splitlines()[-1])
    assert count == (300 if rows == "mount" else 100_000)
    if die == "always":
        assert {tuple(answer) for answer in answers} == {("failed", f"WorkerDied: no worker process could start a row "
                                                           f"({START_TRIES} process pools in a row broke before "
                                                           f"any row ran)")}
    else:
        assert os.path.exists(marker) and {tuple(answer) for answer in answers} == {("ok", "")}


def _busy(pid: int, exclude=()) -> list[psutil.Process]:
    """Workers of *pid* not in *exclude* that have used more CPU time than their start-up takes."""
    busy = []
    for worker in _workers(pid):
        try:
            if worker.pid not in exclude and worker.cpu_times().user > WORKING_CPU_S:
                busy.append(worker)
        except psutil.NoSuchProcess:
            pass
    return busy


@pytest.mark.slow
def test_a_killed_worker_is_retried_and_a_twice_killed_row_is_marked_failed(tmp_path):
    case = dataclasses.replace(reference_case().with_rigid_links(), excitations=(LP_ROTOR,))
    case = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method="time", steps_per_period=400,
                                                                  start="rest"))
    case_file = tmp_path / "long.json"
    case_file.write_text(to_json(case))
    output = tmp_path / "out"
    process = start("study", "params", str(case_file), "--output", str(output), "--vary=hinge_stiffness=1e7,2e7",
                    "--workers", "2", cwd=tmp_path)
    first = _wait(lambda: _busy(process.pid), what="a worker running a row")
    first[0].kill()                                   # SIGKILL: both rows in flight are lost
    lines = []
    for line in process.stderr:                       # the lost rows are retried in a pool of their own
        lines.append(line)
        if "retried in a process of their own" in line:
            break
    assert "a worker process died; rows" in lines[-1]
    seen = {p.pid for p in _workers(process.pid)} | {first[0].pid}
    retry = _wait(lambda: _busy(process.pid, seen), what="the retry's worker running its row")
    retry[0].kill()                                   # killed again: the row fails with the reason
    stdout, stderr = process.communicate(timeout=600)
    assert process.returncode == EXIT_FAILED_ROWS
    assert "Traceback" not in stderr + "".join(lines) and "BrokenProcessPool" not in stdout + stderr
    table = _table(output)
    failed = table[table["status"] == "failed"]
    assert len(table) == 2 and len(failed) == 1      # the other row succeeded when retried
    assert failed["error"].iloc[0].startswith("WorkerDied: the worker process running this row was killed by SIGKILL")
    summary = stdout.strip().splitlines()[-1]
    assert summary == f"1 of 2 rows ok, 1 failed (rows {failed['row'].iloc[0]}; exit code {EXIT_FAILED_ROWS})"


#: Worker processes a study of two may start in all when one of them is killed: two pools of two and the pool
#: of one that retries the rows in flight (each row retried in a pool of its own started hundreds).
_WORKERS_AFTER_A_KILL = 6
#: Rows of the study whose worker is killed.
_ROWS = 6000


@pytest.mark.slow
def test_a_worker_killed_in_a_batch_of_rows_costs_one_more_pool(tmp_path):
    """Rows answered in NumPy run 128 to a batch: the rows in flight when a worker was killed (two batches)
    were retried each in a fresh pool of its own, a start-up of a second or more per row (minutes); now they
    are retried together in one pool, and the study ends with every row."""
    output = tmp_path / "out"
    # enough rows that the workers are still at them when the first batches are in the table
    process = start("study", "params", "--rigid", "--output", str(output), f"--vary=hinge_stiffness=1e7:3e7:{_ROWS}",
                    "--workers", "2", cwd=tmp_path)
    _wait(lambda: table_path(output).exists(), what="a first batch of rows")   # the others running theirs
    workers = {worker.pid for worker in _workers(process.pid)}
    psutil.Process(min(workers)).kill()
    end = time.monotonic() + 120
    try:
        while process.poll() is None and len(workers) <= _WORKERS_AFTER_A_KILL and time.monotonic() < end:
            workers.update(worker.pid for worker in _workers(process.pid))
            time.sleep(0.05)
        assert len(workers) <= _WORKERS_AFTER_A_KILL, f"{len(workers)} worker processes started"
        stdout, stderr = process.communicate(timeout=max(1.0, end - time.monotonic()))
    finally:
        if process.poll() is None:             # Ctrl-C: the study stops its workers
            process.send_signal(signal.SIGINT)
            process.communicate(timeout=60)
    assert process.returncode == 0, stderr
    # a worker killed between its batches loses no row (then nothing is retried); the study ends all the same
    assert ("a worker process died; rows " in stderr) == ("retried in a process of their own" in stderr)
    table = _table(output)
    assert sorted(set(table["row"])) == list(range(_ROWS)) and set(table["status"]) == {"ok"}
    assert set(table["path"]) == {"NumPy"} and stdout.strip().splitlines()[-1] == f"{_ROWS} of {_ROWS} rows ok, 0 failed"


def test_resuming_from_the_table_of_another_study_is_refused(tmp_path):
    rows = ({"hinge_stiffness": 1e7}, {"hinge_stiffness": 2e7})
    path = table_path(tmp_path)
    StudyTable(path, rows).add(RowOutcome(1, [], "failed", "CaseError: bad", 0.5))
    assert read_finished(path, rows) == {1: RowOutcome(1, [], "failed", "CaseError: bad", 0.5)}
    with pytest.raises(UsageError, match="row 1 has hinge_stiffness = 20000000.0; this study's row 1 has 30000000.0"):
        read_finished(path, ({"hinge_stiffness": 1e7}, {"hinge_stiffness": 3e7}))
    with pytest.raises(UsageError, match="its columns are"):
        read_finished(path, ({"hinge_damping": 1e3}, {"hinge_damping": 2e3}))
    assert read_finished(tmp_path / "none.csv", rows) == {}


@pytest.mark.slow
def test_workers_end_when_the_study_is_killed_outright(case_file, tmp_path):
    output = tmp_path / "out"
    process = _study(case_file, output, "--workers", "2")
    _wait(lambda: len(_table(output)) >= 1, what="a finished row")
    workers = [worker.pid for worker in _workers(process.pid)]
    assert workers
    process.kill()                                    # SIGKILL: the study cannot stop its workers itself
    process.communicate()
    _wait(lambda: not alive(workers), timeout=60, what="the orphaned workers to end")
    table = _table(output)
    assert len(table) >= 1 and set(table["status"]) == {"ok"}



@pytest.fixture()
def small_disk(tmp_path):
    """A folder on a file system of 64 kB of its own (tmpfs; skipped where this process may not mount one)."""
    folder = tmp_path / "small"
    folder.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(folder)], capture_output=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a small file system: {mounted.stderr.decode().strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", "-l", str(folder)], check=True)


@pytest.mark.slow
def test_a_study_whose_disk_fills_says_which_rows_it_kept(small_disk, capsys):
    """The table's disk filled mid-study: the message was the system's alone; now it says how many rows the
    table holds and how to go on, as after Ctrl-C."""
    from workbook.cli.main import main

    output = small_disk / "out"
    argv = ["study", "params", "--rigid", "--output", str(output), "--vary=hinge_stiffness=1e7:3e7:3000",
            "--workers", "1"]
    assert main(argv) == 2
    last = capsys.readouterr().err.strip().splitlines()[-1]
    kept = len(set(_table(output)["row"]))
    assert 1 <= kept < 3000
    assert last == (f"mountwb study: [Errno 28] No space left on device; {kept} of 3000 rows finished and kept in "
                    f"{table_path(output)}; --resume runs the rest")
    assert not [name for name in files_in(output) if name.endswith(".tmp")]
