"""Worker processes: they end with their parent and stop when told.

Two kinds of work run in worker processes: the rows of a parameter study
(:mod:`workbook.studies.parallel`) and the reduction of a case's distinct
links (:mod:`workbook.scene.link_workers`). Both need the same two
guarantees, kept here:

- a worker whose parent is killed outright (SIGKILL, no chance to stop it)
  ends within :data:`PARENT_CHECK_INTERVAL`;
- a parent that is interrupted stops its workers: SIGTERM first, SIGKILL
  after :data:`WORKER_STOP_TIMEOUT`.
"""
from __future__ import annotations

import os
import threading
import time

__all__ = ["PARENT_CHECK_INTERVAL", "WORKER_STOP_TIMEOUT", "end_with_parent", "stop_workers"]

#: Seconds a worker process gets to end after SIGTERM before it is killed.
WORKER_STOP_TIMEOUT = 5.0
#: Seconds between a worker's checks that its parent still lives.
PARENT_CHECK_INTERVAL = 1.0


def end_with_parent() -> None:
    """In a worker process: end it (exit code 1) once its parent is gone, checked every
    :data:`PARENT_CHECK_INTERVAL` s from a daemon thread."""
    threading.Thread(target=_watch_parent, args=(os.getppid(),), daemon=True).start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(PARENT_CHECK_INTERVAL)
    os._exit(1)


def stop_workers(workers) -> None:
    """SIGTERM every living worker process, then SIGKILL those still alive after :data:`WORKER_STOP_TIMEOUT`.

    Parameters
    ----------
    workers : iterable of multiprocessing.Process
    """
    workers = list(workers)
    for process in workers:
        if process.is_alive():
            process.terminate()
    deadline = time.monotonic() + WORKER_STOP_TIMEOUT
    for process in workers:
        process.join(max(0.0, deadline - time.monotonic()))
        if process.is_alive():
            process.kill()
            process.join()
