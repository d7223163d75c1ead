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

import multiprocessing
import os
import threading
import time

__all__ = ["PARENT_CHECK_INTERVAL", "WORKER_STOP_TIMEOUT", "ALLOCATOR_KEEPS", "end_with_parent", "stop_workers",
           "loosen_allocator"]

#: Seconds a worker process gets to end after SIGTERM before it is killed.
WORKER_STOP_TIMEOUT = 5.0
#: Seconds between a worker's checks that its parent still lives.
PARENT_CHECK_INTERVAL = 1.0
#: Bytes of freed memory glibc may keep for reuse, and the allocation size from which it maps memory of its own,
#: in a worker that evaluates designs (:func:`loosen_allocator`).
ALLOCATOR_KEEPS = 64 * 2 ** 20


def end_with_parent() -> None:
    """In a worker process: end it (exit code 1) once its parent is gone, checked every
    :data:`PARENT_CHECK_INTERVAL` s from a daemon thread.

    The parent is the process that started this one (:func:`multiprocessing.parent_process`), also when it
    was killed before this worker got here: the parent this worker has now would be another process (init),
    and the worker would outlive the study for ever.
    """
    parent = multiprocessing.parent_process()
    threading.Thread(target=_watch_parent, args=(os.getppid() if parent is None else parent.pid,),
                     daemon=True).start()


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


def loosen_allocator() -> bool:
    """In a worker that evaluates designs: let glibc keep up to :data:`ALLOCATOR_KEEPS` bytes of freed
    memory for reuse.

    Dask's nanny starts its workers with ``MALLOC_TRIM_THRESHOLD_=65536`` (to
    give memory back to the system), which also fixes glibc's mmap threshold:
    every NumPy temporary above 128 kB is then mapped and unmapped anew, and a
    batch of design evaluations ran 2.4 times slower than in a local process.
    A local process with glibc's own settings gives back the top of its heap
    whenever a batch's temporaries (several MB each) are freed, and a fifth of
    its time went to the kernel mapping those pages again
    (``benchmarks/bench_uq.py``). Memory above the limit is still given back.

    Returns
    -------
    bool
        Whether it was set (False where the C library is not glibc).
    """
    import ctypes
    import ctypes.util

    name = ctypes.util.find_library("c")
    try:
        library = ctypes.CDLL(name) if name else None
        mallopt = getattr(library, "mallopt", None)
    except OSError:
        return False
    if mallopt is None:
        return False
    trim_threshold, mmap_threshold = -1, -3          # glibc's M_TRIM_THRESHOLD and M_MMAP_THRESHOLD
    return bool(mallopt(trim_threshold, ALLOCATOR_KEEPS)) and bool(mallopt(mmap_threshold, ALLOCATOR_KEEPS))
