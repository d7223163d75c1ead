"""A case's distinct links reduced side by side, in worker processes.

A cold run spends most of its time reducing links, and each distinct link
model is an independent job (mesh, assembly, one factorisation, eigen-solves).
:func:`reduce_in_workers` runs the jobs the cache lacks in up to one process
per available core; each worker writes its reductions to the shared disk
cache of :mod:`flexbodies` (its files are written all at once, under the
link's cache lock), and the caller's serial pass then only loads them.

It is a head start, never a second path: a job that fails in a worker is
left to the serial pass, which meets the same error and reports it as a
serial run would. Ctrl-C or SIGTERM of the parent stops the workers (see
:mod:`workbook.processes`); a worker stopped by SIGTERM unwinds, so the
cache file it was writing is removed.

Workers are forked: they start at once with the parent's modules (those
that reduce a link imported once, before the fork) and its logging. Where
``fork`` is unavailable, or the cache cannot be written, the links are
reduced in the calling process only.
"""
from __future__ import annotations

import logging
import math
import multiprocessing
import os
import signal
import time
from dataclasses import dataclass
from typing import Any, Callable

from flexbodies.cache import BodyCache
from flexbodies.geometry import default_element_size
from flexbodies.link import LinkModel, is_reduced, reduce_link_set
from workbook.processes import end_with_parent, stop_workers

__all__ = ["LinkJob", "reduce_in_workers", "available_cores"]

log = logging.getLogger(__name__)

#: Seconds between the parent's looks at its workers' progress.
_POLL_SECONDS = 0.05


@dataclass(frozen=True)
class LinkJob:
    """One distinct reduction: the arguments of :func:`flexbodies.link.reduce_link_set`.

    Attributes
    ----------
    model : flexbodies.LinkModel
    modes : {"auto", "static"} or int or float
    excitations_hz : tuple of float
        Every excitation frequency the reduction serves, Hz.
    stiffening : bool
        Keep the link's geometric stiffness too.
    """

    model: LinkModel
    modes: Any
    excitations_hz: tuple
    stiffening: bool

    def reduce(self) -> tuple:
        """Reduce (or load) the link in this process: one ``ReducedBody`` per excitation frequency."""
        return reduce_link_set(self.model, self.modes, self.excitations_hz, stiffening=self.stiffening)

    def expected_work(self) -> float:
        """A rough measure of the job's cost, to start the largest first: the parametric link's
        volume in elements of its mesh size (a mesh file's jobs count as the largest)."""
        geometry = self.model.geometry
        if geometry is None:
            return math.inf
        size = self.model.element_size or default_element_size(geometry)
        eyes = 2 * math.pi * geometry.eye_outer_radius ** 2 * geometry.thickness
        return (geometry.length * geometry.shank_width * geometry.shank_thickness + eyes) / size ** 3

    def cached(self) -> bool:
        """True when the cache already holds everything this job would compute."""
        return is_reduced(self.model, self.modes, self.excitations_hz, stiffening=self.stiffening)


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _unwind(signum, frame):
    raise SystemExit(128 + signum)


def _work(jobs: list, next_job, finished) -> None:
    """A worker: take the next job until none is left, and report each one done."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's: it stops the workers
    signal.signal(signal.SIGTERM, _unwind)        # unwinding removes a cache file being written
    end_with_parent()
    while True:
        with next_job.get_lock():
            index = next_job.value
            next_job.value += 1
        if index >= len(jobs):
            return
        try:
            jobs[index].reduce()
        except Exception as error:  # noqa: BLE001 - the serial pass meets it again and reports it
            log.debug("link reduction %d failed in a worker (%s); left to the serial pass", index, error)
        finished.put(index)


def _report(finished, pending: list, done) -> int:
    """Hand every job the workers have reported finished since the last call to *done*; how many."""
    count = 0
    while not finished.empty():
        job = pending[finished.get()]
        count += 1
        if done is not None:
            done(job)
    return count


def reduce_in_workers(jobs, done: Callable[[LinkJob], None] | None = None, workers: int | None = None,
                      spare: Callable[[], None] | None = None) -> int:
    """Reduce the jobs the cache lacks in worker processes, side by side.

    Parameters
    ----------
    jobs : sequence of LinkJob
        Distinct reductions.
    done : callable, optional
        Called in this process with each job once its worker has finished it.
    workers : int, optional
        Most worker processes (default: the cores available). Fewer than two
        jobs to compute, or one worker, run nothing here.
    spare : callable, optional
        Called once in this process on the core the first worker to run out
        of jobs leaves idle while another still works: work the caller needs
        next (it must not raise).

    Returns
    -------
    int
        The number of jobs run in workers (0 when the serial pass does all).
    """
    limit = available_cores() if workers is None else workers
    if (limit < 2 or "fork" not in multiprocessing.get_all_start_methods() or multiprocessing.current_process().daemon
            or not BodyCache().writable()):
        return 0
    # the largest first: a long job started last would decide when the workers are done
    pending = sorted((job for job in jobs if not job.cached()), key=LinkJob.expected_work, reverse=True)
    if len(pending) < 2:
        return 0
    context = multiprocessing.get_context("fork")
    next_job, finished = context.Value("i", 0), context.SimpleQueue()
    processes = [context.Process(target=_work, args=(pending, next_job, finished), daemon=True,
                                 name=f"mountwb link reduction {i + 1}")
                 for i in range(min(limit, len(pending)))]
    start = time.perf_counter()
    try:
        for process in processes:
            process.start()
        reported = 0
        while reported < len(pending) and any(p.is_alive() for p in processes):
            reported += _report(finished, pending, done)
            if spare is not None and reported < len(pending) and not all(p.is_alive() for p in processes):
                spare()
                spare = None
            time.sleep(_POLL_SECONDS)
        for process in processes:
            process.join()
    except BaseException:
        stop_workers(processes)
        raise
    _report(finished, pending, done)
    died = [p for p in processes if p.exitcode]
    if died:
        log.warning("%d of %d link-reduction workers ended with exit code %s; their links are reduced here",
                    len(died), len(processes), ", ".join(str(p.exitcode) for p in died))
    log.info("%d links reduced in %d worker processes in %.2f s", len(pending), len(processes),
             time.perf_counter() - start)
    return len(pending)
