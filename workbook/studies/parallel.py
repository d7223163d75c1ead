"""Run the cases of a parameter study serially, in local processes, or on a Dask cluster.

The parent first builds every row's case and reduces every distinct link
model once (:func:`prepare`), so the disk cache of :mod:`flexbodies`
(``$MOUNTWB_CACHE``, which workers must share) holds every reduction before
a run starts: workers only load, and no two processes ever write the same
cache file. The same function, :func:`run_row`, then runs one row anywhere;
it never raises: a failing row comes back with its error while the others
complete. Results come back in row order and are the same whichever way
they ran (BLAS is single-threaded inside every run).
"""
from __future__ import annotations

import logging
import multiprocessing
import os
import time
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from typing import Callable

from workbook.answers.isolation import efficiency
from workbook.model.case import DIRECTIONS, Case

__all__ = ["RowOutcome", "prepare", "run_row", "run_rows", "SERIAL"]

log = logging.getLogger(__name__)

#: ``workers`` value that runs every row in this process.
SERIAL = 1
#: Rows a worker process runs before it is replaced: a run leaves about 11 MB
#: of Exudyn memory behind (measured on the reference mount), which a fresh
#: process returns.
ROWS_PER_WORKER = 50


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
    """

    index: int
    runs: list = field(default_factory=list)
    status: str = "ok"
    error: str = ""
    wall_time: float = 0.0


def _failed(index: int, error: BaseException, wall_time: float = 0.0) -> RowOutcome:
    log.debug("row %d failed:\n%s", index, "".join(traceback.format_exception(error)))
    return RowOutcome(index, [], "failed", f"{type(error).__name__}: {error}", wall_time)


def prepare(cases: list[Case | BaseException]) -> list[Case | RowOutcome]:
    """Reduce every distinct link of the cases once (filling the disk cache).

    Parameters
    ----------
    cases : list of Case or exception
        Row cases; an exception stands for a row whose case could not be built.

    Returns
    -------
    list of Case or RowOutcome
        The case of each row, or the failed outcome of a row whose case or
        link reduction failed.
    """
    from flexbodies import reduce_link

    reduced, prepared = set(), []
    for index, case in enumerate(cases):
        if isinstance(case, BaseException):
            prepared.append(_failed(index, case))
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
            prepared.append(_failed(index, error))
            continue
        prepared.append(case)
    log.info("%d distinct link reductions for %d rows", len(reduced), len(cases))
    return prepared


def run_row(index: int, case: Case) -> RowOutcome:
    """Run every excitation of one row's case; never raises.

    Parameters
    ----------
    index : int
        Row number.
    case : Case

    Returns
    -------
    RowOutcome
    """
    from threadpoolctl import threadpool_limits

    from workbook.solve.pipeline import run_case

    start = time.perf_counter()
    try:
        with threadpool_limits(limits=1):
            result = run_case(case)
    except Exception as error:
        return _failed(index, error, time.perf_counter() - start)
    runs = []
    for run in result.runs:
        t = run.transmissibility
        runs.append({"run": run.name, "frequency Hz": run.frequency_hz,
                     **{f"T {d}": float(v) for d, v in zip(DIRECTIONS, t)},
                     **{f"eta % {d}": float(v) for d, v in zip(DIRECTIONS, efficiency(t))},
                     "steady": run.steady})
    return RowOutcome(index, runs, wall_time=time.perf_counter() - start)


def run_rows(cases: list[Case | BaseException], *, workers: int = SERIAL, dask: str | None = None,
             progress: Callable[[int, int], None] | None = None) -> list[RowOutcome]:
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

    Returns
    -------
    list of RowOutcome
    """
    prepared = prepare(cases)
    outcomes = {i: p for i, p in enumerate(prepared) if isinstance(p, RowOutcome)}
    pending = {i: p for i, p in enumerate(prepared) if not isinstance(p, RowOutcome)}
    total = len(prepared)

    def done(outcome: RowOutcome):
        outcomes[outcome.index] = outcome
        if progress is not None:
            progress(len(outcomes), total)

    if dask is not None:
        _run_dask(pending, dask, done)
    elif workers <= SERIAL or len(pending) <= 1:
        for index, case in pending.items():
            done(run_row(index, case))
    else:
        _run_processes(pending, workers, done)
    return [outcomes[i] for i in range(total)]


def _run_processes(pending: dict, workers: int, done: Callable) -> None:
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=min(workers, len(pending)), mp_context=context,
                             max_tasks_per_child=ROWS_PER_WORKER) as pool:
        futures = [pool.submit(run_row, index, case) for index, case in pending.items()]
        for future in as_completed(futures):
            done(future.result())


def _run_dask(pending: dict, address: str, done: Callable) -> None:
    from distributed import Client
    from distributed import as_completed as dask_completed

    cache = os.environ.get("MOUNTWB_CACHE")
    with Client(address) as client:
        if cache:  # the workers load the reductions made here (a shared folder on a real cluster)
            client.run(os.environ.__setitem__, "MOUNTWB_CACHE", cache)
        futures = client.map(run_row, list(pending), list(pending.values()), pure=False)
        for future in dask_completed(futures):
            done(future.result())
