"""Run the cases of a parameter study serially, in local processes, or on a Dask cluster.

The parent first builds every row's case and reduces every distinct link
model once (:func:`prepare`), so the disk cache of :mod:`flexbodies`
(``$MOUNTWB_CACHE``, which workers must share) holds every reduction before
a run starts: workers only load, and no two processes ever write the same
cache file. The same function, :func:`run_batch`, then runs a batch of rows
anywhere (:func:`batches`: the rows the study's prepared linear mount
follows, :data:`BATCH_ROWS` at a time, answered together in NumPy; every
other row alone, through Exudyn); it never raises for a row's own trouble: a
failing row comes back with its error while the others complete. Results
are the same whichever way they ran, to the preload solve's tolerance (BLAS
is single-threaded inside every run).

Local processes run the rows in chunks of ``workers * rows_per_worker``
rows, each chunk in a fresh pool that is shut down before the next starts:
that bounds the memory a worker process can gather. (The process pool's own
worker replacement, ``max_tasks_per_child``, deadlocks on the Python
versions supported once the first worker retires, so it is not used.)

Faults (local processes):

- A worker process that dies (killed, out of memory) takes its pool down.
  Rows not started yet simply run in a new pool. The rows it and the other
  workers were running are retried at the end in a fresh one-worker pool;
  when that worker dies too, the batch it was running is split in halves,
  each retried in a pool of its own, until a row whose worker dies alone is
  marked failed with the reason (one death costs one pool's start-up, not
  one per row). After :data:`START_TRIES` pools in a row that broke before
  any row started (its workers died as they started), the remaining rows
  are marked failed.
- An interrupt (Ctrl-C, or SIGTERM raised as :class:`workbook.errors.Terminated`)
  stops every worker process of the study before it propagates; workers
  ignore Ctrl-C themselves, so only the parent decides. A worker whose
  parent was killed outright (SIGKILL) ends within :data:`workbook.processes.PARENT_CHECK_INTERVAL`.

Every finished row is handed to ``record`` at once (the study table is
written as rows finish), so an interrupt loses only the rows in flight.
"""
from __future__ import annotations

import contextlib
import dataclasses
import itertools
import logging
import mmap
import multiprocessing
import os
import pickle
import signal
import sys
import tempfile
import threading
import time
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from multiprocessing import reduction
from typing import TYPE_CHECKING, Callable, cast

from workbook.answers.isolation import efficiency
from workbook.errors import OutsideDesignModel, Terminated, UsageError, interruption
from workbook.model.case import DIRECTIONS, Case
from workbook.processes import WORKER_STOP_TIMEOUT, end_with_parent, loosen_allocator, stop_workers

if TYPE_CHECKING:
    from workbook.design.linear_mount import LinearMount

__all__ = ["RowOutcome", "prepare", "prepare_design_model", "run_row", "run_batch", "batches", "run_rows", "SERIAL",
           "ROWS_PER_WORKER", "BATCH_ROWS", "START_TRIES", "NUMPY_PATH", "EXUDYN_PATH",
           "SCHEDULER_TIMEOUT", "check_scheduler"]

log = logging.getLogger(__name__)

#: ``workers`` value that runs every row in this process.
SERIAL = 1
#: Rows per worker process in one chunk of rows; each chunk runs in a fresh
#: pool, which bounds the memory a run might still leave behind (measured in
#: docs/reliability.md, "Memory over many runs").
ROWS_PER_WORKER = 200
#: Rows per worker in one chunk when the study has a prepared linear mount: its NumPy rows gather no
#: memory (the bound is for Exudyn's runs), and each fresh pool costs seconds of start-up.
DESIGN_ROWS_PER_WORKER = 5000
#: Process pools in a row that may break before any row starts (a worker process died as it started) before
#: the study's remaining rows are reported failed.
START_TRIES = 3
#: Seconds a Dask scheduler gets to accept a study's connection.
SCHEDULER_TIMEOUT = 10.0
#: Rows the prepared linear mount answers together, in one NumPy batch (one task of a worker).
BATCH_ROWS = 128
#: The row was answered by the prepared linear mount in NumPy.
NUMPY_PATH = "NumPy"
#: The row was answered by the Exudyn pipeline.
EXUDYN_PATH = "Exudyn"

#: The linear mount prepared for the study's base case, in this process (None: every row through Exudyn).
_design_model: LinearMount | None = None


@dataclass
class RowOutcome:
    """What one study row gave.

    Attributes
    ----------
    index : int
        Row number.
    runs : list of dict
        Per run (excitation): ``run``, ``frequency Hz``, ``T x/y/z``,
        ``eta % x/y/z``, ``steady``.
    status : str
        ``"ok"`` or ``"failed"``.
    error : str
        ``"<ErrorType>: message"`` of a failed row, else "".
    wall_time : float
        s.
    path : str
        How the row was answered: :data:`NUMPY_PATH` (the prepared linear
        mount, :class:`workbook.LinearMount`) or :data:`EXUDYN_PATH`
        (:func:`workbook.run_case`); "" for a row that did not run.
    """

    index: int
    runs: list = field(default_factory=list)
    status: str = "ok"
    error: str = ""
    wall_time: float = 0.0
    path: str = ""


def _failed(index: int, error: BaseException, wall_time: float = 0.0) -> RowOutcome:
    log.debug("row %d failed:\n%s", index, "".join(traceback.format_exception(error)))
    return RowOutcome(index, [], "failed", f"{type(error).__name__}: {error}", wall_time)


def prepare(cases: dict[int, Case | BaseException]) -> dict[int, Case | RowOutcome]:
    """Reduce every distinct link of the cases once (filling the disk cache).

    Parameters
    ----------
    cases : dict of int to Case or exception
        Case of each row to run, by row number; an exception stands for a
        row whose case could not be built.

    Returns
    -------
    dict of int to Case or RowOutcome
        The case of each row, or the failed outcome of a row whose case or
        link reduction failed.
    """
    from flexbodies import reduce_link

    reduced, prepared = set(), dict[int, Case | RowOutcome]()
    for index, case in cases.items():
        if isinstance(case, BaseException):
            prepared[index] = _failed(index, case)
            continue
        try:
            for item in case.excitations:
                frequency = item.frequency  # run_case reduces for a sweep's highest frequency
                for link in case.links:
                    modes = case.link_modes(link.name)
                    key = (link.model, modes, frequency if modes == "auto" else None)
                    if key not in reduced:
                        reduce_link(link.model, modes=modes, excitation_hz=frequency)
                        reduced.add(key)
        except Exception as error:  # a row's links may fail to mesh; the others go on
            prepared[index] = _failed(index, error)
            continue
        prepared[index] = case
    log.info("%d distinct link reductions for %d rows", len(reduced), len(cases))
    return prepared


def prepare_design_model(base: Case):
    """The linear mount of a study's *base* case, or the reason it has none.

    Returns
    -------
    LinearMount or str
        The prepared mount, or the plain-words reason (a time-domain case,
        a flexible pylon...) why every row goes through Exudyn.
    """
    from threadpoolctl import threadpool_limits

    from workbook.design.linear_mount import LinearMount
    from workbook.errors import SimulationError

    try:
        with threadpool_limits(limits=1):
            return LinearMount.prepare(base)
    except SimulationError as error:     # OutsideDesignModel, or the base case itself does not solve
        return str(error)


def run_row(index: int, case: Case, design_model: LinearMount | None = None) -> RowOutcome:
    """Run every excitation of one row's case; never raises but for an interrupt.

    A row the study's prepared linear mount follows (its springs, engine
    mass properties or excitation amplitudes changed) is answered by it in
    NumPy, any other by :func:`workbook.run_case`.

    Parameters
    ----------
    index : int
        Row number.
    case : Case
    design_model : LinearMount, optional
        The study's prepared linear mount (default: this process's, set for
        the study's rows here or in a worker process).

    Returns
    -------
    RowOutcome

    Raises
    ------
    KeyboardInterrupt
        Ctrl-C or SIGTERM (also when Exudyn wrapped it in an error of its own).
    """
    return run_batch([(index, case)], design_model)[0]


def run_batch(rows: list[tuple[int, Case]], design_model: LinearMount | None = None) -> list[RowOutcome]:
    """Run several rows (``(index, case)``) as :func:`run_row` does, the ones the prepared linear mount follows
    together (:meth:`~workbook.LinearMount.evaluate_many`: NumPy on all of them at once); never raises but for
    an interrupt.

    Returns
    -------
    list of RowOutcome
        In the order of *rows*; the wall time of a row answered in NumPy is its share of the batch's.
    """
    from threadpoolctl import threadpool_limits

    model = _design_model if design_model is None else design_model
    with threadpool_limits(limits=1):
        if model is None:
            return [_exudyn_row(index, case) for index, case in rows]
        start = time.perf_counter()
        try:
            answers = model.evaluate_many([case for _, case in rows])
        except Exception as error:
            interrupt = interruption(error)
            if interrupt is not None:
                raise interrupt from None
            share = (time.perf_counter() - start) / len(rows)
            return [dataclasses.replace(_failed(index, error, share), path=NUMPY_PATH) for index, _ in rows]
        share = (time.perf_counter() - start) / len(rows)
        outcomes = []
        for (index, case), answer in zip(rows, answers, strict=True):
            if isinstance(answer, OutsideDesignModel):      # a change the prepared mount does not follow
                outcomes.append(_exudyn_row(index, case))
            elif isinstance(answer, Exception):
                outcomes.append(dataclasses.replace(_failed(index, answer, share), path=NUMPY_PATH))
            else:
                outcomes.append(_outcome(index, answer.result, share, NUMPY_PATH))
        return outcomes


def _exudyn_row(index: int, case: Case) -> RowOutcome:
    """One row through :func:`workbook.run_case` (BLAS limits set by the caller)."""
    from workbook.solve.pipeline import run_case

    start = time.perf_counter()
    try:
        result = run_case(case)
    except Exception as error:
        interrupt = interruption(error)
        if interrupt is not None:
            raise interrupt from None
        return dataclasses.replace(_failed(index, error, time.perf_counter() - start), path=EXUDYN_PATH)
    return _outcome(index, result, time.perf_counter() - start, EXUDYN_PATH)


def _outcome(index: int, result, wall_time: float, path: str) -> RowOutcome:
    """The outcome of a row answered with *result* (a MountResult)."""
    runs = []
    for run in result.runs:
        t = run.transmissibility
        runs.append({"run": run.name, "frequency Hz": run.frequency_hz,
                     **{f"T {d}": float(v) for d, v in zip(DIRECTIONS, t, strict=True)},
                     **{f"eta % {d}": float(v) for d, v in zip(DIRECTIONS, efficiency(t), strict=True)},
                     "steady": run.steady})
    return RowOutcome(index, runs, wall_time=wall_time, path=path)


def batches(pending: dict, design_model: LinearMount | None, size: int | None = None) -> list[list[tuple[int, Case]]]:
    """The rows *pending* (index to case) in the batches they run in: the rows *design_model* follows
    :data:`BATCH_ROWS` (or *size*) at a time, every other row alone."""
    size = BATCH_ROWS if size is None else size
    together: list[tuple[int, Case]] = []
    out: list[list[tuple[int, Case]]] = []
    for index, case in pending.items():
        if design_model is not None and design_model.follows(case):
            together.append((index, case))
        else:
            out.append([(index, case)])
    return [together[k:k + size] for k in range(0, len(together), size)] + out


def run_rows(cases: list[Case | BaseException], *, workers: int = SERIAL, dask: str | None = None,
             progress: Callable[[int, int], None] | None = None,
             finished: dict[int, RowOutcome] | None = None,
             record: Callable[[RowOutcome], None] | None = None,
             rows_per_worker: int = ROWS_PER_WORKER, design_model: LinearMount | None = None) -> list[RowOutcome]:
    """Run the rows' cases and return their outcomes in row order.

    Parameters
    ----------
    cases : list of Case or exception
        Row cases (an exception: the row's case could not be built).
    workers : int
        Local processes (1: in this process). Ignored with *dask*.
    dask : str, optional
        Address of a Dask scheduler (``tcp://host:8786``) to run on instead.
    progress : callable, optional
        ``progress(done, total)`` after each row.
    finished : dict of int to RowOutcome, optional
        Rows already done (a resumed study): not run again, returned as they are.
    record : callable, optional
        ``record(outcome)`` as soon as each row finishes, in finishing order.
    rows_per_worker : int
        Local processes: rows per worker in one chunk of rows (a fresh pool each chunk).
    design_model : LinearMount, optional
        The base case's prepared linear mount (:func:`prepare_design_model`):
        the rows it follows are answered by it, here, in local processes and
        on a Dask cluster (sent to each worker once).

    Returns
    -------
    list of RowOutcome

    Raises
    ------
    KeyboardInterrupt
        Ctrl-C or SIGTERM: every worker process has been stopped; *record*
        has had every row finished before it.
    """
    outcomes = dict(finished or {})
    todo = {i: case for i, case in enumerate(cases) if i not in outcomes}
    total = len(cases)

    def done(outcome: RowOutcome):
        outcomes[outcome.index] = outcome
        if record is not None:
            record(outcome)
        if progress is not None:
            progress(len(outcomes), total)

    pending = {}
    for index, item in prepare(todo).items():
        if isinstance(item, RowOutcome):
            done(item)
        else:
            pending[index] = item
    if dask is not None:
        _run_dask(pending, dask, done, design_model)
    elif workers <= SERIAL or len(pending) <= 1 or (design_model is not None and len(pending) <= BATCH_ROWS) \
            or not _main_importable():
        with _signals_seen() as seen, _using(design_model):
            for batch in batches(pending, design_model):
                answered = run_batch(batch)
                if seen:        # a signal a library swallowed during the rows: their outcomes are dropped, --resume reruns them
                    raise Terminated() if signal.SIGTERM in seen else KeyboardInterrupt()
                for outcome in answered:
                    done(outcome)
    else:
        chunk = rows_per_worker if design_model is None else max(rows_per_worker, DESIGN_ROWS_PER_WORKER)
        _run_processes(pending, workers, done, chunk, design_model)
    return [outcomes[i] for i in range(total)]


def _main_importable() -> bool:
    """Whether a worker process can be started: it imports this process's main module again (a script read
    from standard input, ``python -``, cannot be; the rows then run in this process)."""
    main = sys.modules.get("__main__")
    if getattr(getattr(main, "__spec__", None), "name", None):
        return True
    path = getattr(main, "__file__", None)
    started_in = getattr(multiprocessing.process, "ORIGINAL_DIR", None) or os.getcwd()   # where spawn looks
    if path is None or os.path.isfile(os.path.join(started_in, path)):
        return True
    log.warning("the main module (%s) cannot be imported by a worker process: the rows run in this process", path)
    return False


@contextlib.contextmanager
def _using(design_model: LinearMount | None):
    """Answer the rows of this process with *design_model* where it follows them."""
    global _design_model
    previous, _design_model = _design_model, design_model
    try:
        yield
    finally:
        _design_model = previous


@contextlib.contextmanager
def _signals_seen():
    """Note every Ctrl-C and SIGTERM while rows run in this process, then handle it as before.

    Yields
    ------
    list of int
        The signals received. A signal that a library (Exudyn) turned into an
        error of its own without its cause is still seen here, so that a row
        it ended is never recorded as failed and the study stops.
    """
    seen: list[int] = []
    previous = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}

    def note(signum, frame):
        seen.append(signum)
        handler = previous[signum]
        if callable(handler):
            handler(signum, frame)

    watched = [signum for signum, handler in previous.items() if callable(handler)]
    if threading.current_thread() is not threading.main_thread():
        watched = []                         # only the main thread may set signal handlers
    for signum in watched:
        signal.signal(signum, note)
    try:
        yield seen
    finally:
        for signum in watched:
            signal.signal(signum, previous[signum])


#: In a worker process: where the worker reports the row it starts.
_started = None


class _SharedFile:
    """An open file whose descriptor a spawned worker process gets a copy of as it starts.

    A payload of megabytes (the prepared linear mount) goes to the workers in
    such a file, read by each in its initialiser, and not in the start-up data
    of a process: :mod:`multiprocessing` writes that into a pipe the parent
    itself keeps open until the write ends, so a worker that died before
    reading it all (killed, out of memory) left the parent blocked there for
    ever. The file has no name (:func:`tempfile.TemporaryFile`): nothing is
    left on disk, also when the study is killed outright.
    """

    def __init__(self, payload):
        self.file = tempfile.TemporaryFile()
        pickle.dump(payload, self.file, protocol=pickle.HIGHEST_PROTOCOL)
        self.file.flush()

    def __reduce__(self):
        # a descriptor for the process being started (multiprocessing passes it on as it spawns the process)
        return _load_shared, (reduction.DupFd(self.file.fileno()),)

    def close(self) -> None:
        self.file.close()


def _load_shared(descriptor):
    """In a worker: the payload of a :class:`_SharedFile` (read without moving the file position it shares)."""
    fd = descriptor.detach()
    try:
        with mmap.mmap(fd, 0, access=mmap.ACCESS_READ) as view:
            return pickle.loads(view)
    finally:
        os.close(fd)


def _worker_init(started, design_model: LinearMount | None) -> None:
    """Set up a worker: Ctrl-C is the parent's to handle (it stops the workers),
    the worker ends when its parent is gone (killed with no chance to stop it),
    and it answers the rows *design_model* (a :class:`_SharedFile`'s, read as the
    process starts) follows with it (its allocator keeping freed memory for NumPy's
    temporaries, :func:`~workbook.processes.loosen_allocator`)."""
    global _started, _design_model
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _started, _design_model = started, design_model
    end_with_parent()
    if design_model is not None:
        loosen_allocator()


def _reported_batch(batch: list[tuple[int, Case]]) -> list[RowOutcome]:
    assert _started is not None
    for index, _ in batch:
        _started.put((index, os.getpid()))
    return run_batch(batch)


def _death(exitcode: int | None) -> str:
    """Plain words for how a worker process ended."""
    if exitcode is None:
        return "ended abruptly"
    if exitcode < 0:
        try:
            return f"was killed by {signal.Signals(-exitcode).name}"
        except ValueError:
            return f"was killed by signal {-exitcode}"
    return f"exited with code {exitcode}"


def _pool_round(pending: dict, workers: int, done: Callable, context, design_model: LinearMount | None,
                shared: _SharedFile | None) -> tuple[dict, dict, dict]:
    """Run *pending* in a fresh pool until every row is done or the pool breaks (*shared*: *design_model*
    for the workers).

    Returns
    -------
    lost : dict of int to Case
        Rows started but not finished when a worker process died.
    unstarted : dict of int to Case
        Rows the broken pool never started.
    deaths : dict of int to str
        How the process of each lost row ended.
    """
    started = context.SimpleQueue()
    before = set(multiprocessing.active_children())
    pool = ProcessPoolExecutor(max_workers=min(workers, len(pending)), mp_context=context,
                               initializer=_worker_init,
                               initargs=(started, cast("LinearMount | None", shared)))  # the mount once unpickled
    processes = set()
    broken: dict = {}
    pids: dict = {}

    def read_started():
        # read as rows finish: a worker blocks on a full pipe (about 2000 rows of notes) until it is read
        while not started.empty():
            index, pid = started.get()
            pids[index] = pid

    try:
        size = max(1, min(BATCH_ROWS, -(-len(pending) // (2 * workers))))       # at least two batches per worker
        futures = {}
        for batch in batches(pending, design_model, size):
            try:
                futures[pool.submit(_reported_batch, batch)] = batch
            except BrokenProcessPool:        # a worker died while the rows were handed out: not started
                broken.update(batch)
        processes.update(set(multiprocessing.active_children()) - before)  # to read their exit codes later
        for future in as_completed(futures):
            processes.update(set(multiprocessing.active_children()) - before)
            try:
                for outcome in future.result():
                    done(outcome)
            except BrokenProcessPool:
                broken.update(futures[future])
            read_started()
    except BaseException:
        processes.update(set(multiprocessing.active_children()) - before)
        pool.shutdown(wait=False, cancel_futures=True)
        stop_workers(processes)
        raise
    # the workers end as the pool tells them; one left waiting on the call queue's lock that a killed worker
    # held would keep the pool's shutdown waiting for ever: each gets WORKER_STOP_TIMEOUT s, then is stopped
    processes.update(set(multiprocessing.active_children()) - before)
    pool.shutdown(wait=False)
    deadline = time.monotonic() + WORKER_STOP_TIMEOUT
    for process in processes:
        process.join(max(0.0, deadline - time.monotonic()))
    stop_workers(processes)
    pool.shutdown(wait=True)
    read_started()
    exitcodes = {process.pid: process.exitcode for process in processes}
    lost = {i: case for i, case in broken.items() if i in pids}
    deaths = {i: _death(exitcodes.get(pids[i])) for i in lost}
    return lost, {i: case for i, case in broken.items() if i not in pids}, deaths


def _run_processes(pending: dict, workers: int, done: Callable, rows_per_worker: int,
                   design_model: LinearMount | None) -> None:
    if rows_per_worker < 1:
        raise ValueError(f"rows_per_worker must be at least 1, got {rows_per_worker}")
    shared = None if design_model is None else _SharedFile(design_model)
    try:
        _pool_rounds(pending, workers, done, rows_per_worker, design_model, shared)
    finally:
        if shared is not None:
            shared.close()


def _pool_rounds(pending: dict, workers: int, done: Callable, rows_per_worker: int,
                 design_model: LinearMount | None, shared: _SharedFile | None) -> None:
    """The pools of :func:`_run_processes`: a chunk of rows each, then the rows lost in a worker's death
    (module text)."""
    context = multiprocessing.get_context("spawn")
    suspects: dict = {}
    unstarting = 0                           # pools in a row that broke before any row started
    while pending:
        chunk = dict(itertools.islice(pending.items(), workers * rows_per_worker))
        later = {i: case for i, case in pending.items() if i not in chunk}
        lost, unstarted, _ = _pool_round(chunk, workers, done, context, design_model, shared)
        unstarting = unstarting + 1 if len(unstarted) == len(chunk) else 0
        if unstarting == START_TRIES:
            _unstartable({**unstarted, **later, **suspects}, done)
            return
        _said_unstarted(unstarting)
        pending = {**unstarted, **later}
        suspects.update(lost)
    if suspects:
        log.warning("a worker process died; rows %s, which were running, are retried in a process of their own",
                    _row_ranges(suspects))
    groups = [suspects] if suspects else []
    unstarting = 0
    while groups:                            # one worker: a death is that of the batch it was running
        group = groups.pop()
        lost, unstarted, deaths = _pool_round(group, 1, done, context, design_model, shared)
        unstarting = unstarting + 1 if len(unstarted) == len(group) else 0
        if unstarting == START_TRIES:
            _unstartable({index: case for rows in (unstarted, *groups) for index, case in rows.items()}, done)
            return
        _said_unstarted(unstarting)
        if unstarted:
            groups.append(unstarted)
        if len(lost) == 1:
            index = next(iter(lost))
            done(RowOutcome(index, [], "failed", f"WorkerDied: the worker process running this row {deaths[index]}, "
                                                 f"also when the row was retried"))
        elif lost:                           # its halves apart, until a row that ends its worker is alone
            rows = sorted(lost.items())
            groups += [dict(rows[:len(rows) // 2]), dict(rows[len(rows) // 2:])]


def _said_unstarted(unstarting: int) -> None:
    """Warn of the *unstarting*-th pool in a row that broke before any row started (none: nothing)."""
    if unstarting:
        log.warning("a worker process died as it started, before any row ran; a new pool is started (%d of %d)",
                    unstarting + 1, START_TRIES)


def _unstartable(rows: dict, done: Callable) -> None:
    """Report *rows* failed: :data:`START_TRIES` process pools in a row broke before any row started."""
    for index in sorted(rows):
        done(RowOutcome(index, [], "failed", f"WorkerDied: no worker process could start a row ({START_TRIES} "
                                             f"process pools in a row broke before any row ran)"))


def _row_ranges(rows) -> str:
    """Row numbers in ranges: ``0 to 127, 256, 300 to 301``."""
    numbers = sorted(rows)
    ranges = [[numbers[0], numbers[0]]] if numbers else []
    for number in numbers[1:]:
        if number == ranges[-1][1] + 1:
            ranges[-1][1] = number
        else:
            ranges.append([number, number])
    return ", ".join(str(low) if low == high else f"{low} to {high}" for low, high in ranges)


def check_scheduler(address: str, timeout: float | None = None) -> None:
    """Refuse a Dask scheduler address that is malformed or where nothing answers, at once.

    Parameters
    ----------
    address : str
        ``tcp://host:port`` (or ``host:port``; ``tls://`` too). Other
        transports are only read.
    timeout : float, optional
        s to wait for the connection (default :data:`SCHEDULER_TIMEOUT`).

    Raises
    ------
    UsageError
        Naming the address and why (Dask's own client retries a refused
        connection for 30 s before it says so).
    """
    import socket

    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, location = parse_address(address)
        if scheme not in ("tcp", "tls"):
            return
        host, port = parse_host_port(location)
    except ValueError as error:
        raise UsageError(f"--dask {address!r}: {error}; expected tcp://HOST:PORT") from None
    try:
        socket.create_connection((host, port), timeout=SCHEDULER_TIMEOUT if timeout is None else timeout).close()
    except OSError as error:
        raise UsageError(f"--dask {address!r}: no Dask scheduler answers there ({error})") from None


def _run_dask(pending: dict, address: str, done: Callable, design_model: LinearMount | None) -> None:
    from distributed import Client
    from distributed import as_completed as dask_completed

    cache = os.environ.get("MOUNTWB_CACHE")
    with Client(address, timeout=SCHEDULER_TIMEOUT) as client:
        if cache:  # the workers load the reductions made here (a shared folder on a real cluster)
            client.run(os.environ.__setitem__, "MOUNTWB_CACHE", cache)
        client.run(loosen_allocator)    # Dask's own setting slows NumPy's large temporaries (workbook.processes)
        # the prepared mount goes to every worker once; each task gets it by reference
        model = None if design_model is None else client.scatter(design_model, broadcast=True)
        work = batches(pending, design_model)
        futures = client.map(run_batch, work, design_model=model, pure=False)
        rows = {future.key: batch for future, batch in zip(futures, work, strict=True)}
        for future in dask_completed(futures):
            try:
                outcomes = future.result()
            except Exception as error:  # e.g. KilledWorker: Dask gave up on the batch's worker
                outcomes = [_failed(index, error) for index, _ in rows[future.key]]
            for outcome in outcomes:
                done(outcome)
