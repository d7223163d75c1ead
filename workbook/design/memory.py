"""Freed memory kept in the process for the next batch of designs.

A batch of designs allocates arrays of a few MB and frees them. glibc's
``malloc`` hands arrays of that size back to the system when they are freed
(above its mmap threshold, or by trimming its heap), so the next batch gets
them anew, every page faulted in and zeroed by the kernel: on the reference
mount about a hundred page faults per design, a fifth of its time
(``benchmarks/bench_design_evaluation.py``). :func:`keep_freed_memory` raises
the allocator's thresholds, through ``mallopt``, so that freed arrays stay in
the process for reuse.
"""
from __future__ import annotations

import ctypes
import functools
import sys

__all__ = ["keep_freed_memory"]

_M_TRIM_THRESHOLD, _M_TOP_PAD, _M_MMAP_THRESHOLD = -1, -2, -3
_SETTINGS = (
    (_M_MMAP_THRESHOLD, 32 << 20),   # arrays below 32 MB (glibc's largest threshold) from the heap
    (_M_TRIM_THRESHOLD, 128 << 20),  # up to 128 MB of freed heap kept
    (_M_TOP_PAD, 16 << 20),          # the heap grown 16 MB at a time
)


@functools.cache
def keep_freed_memory() -> bool:
    """Have the C allocator keep freed arrays of up to 32 MB (and up to 128 MB of freed heap) for reuse.

    The process's memory then stays near its peak instead of being returned
    between batches. Done once per process; a C library without glibc's
    ``mallopt`` is left as it is.

    Returns
    -------
    bool
        Whether the allocator took the settings.
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return all(mallopt(option, value) == 1 for option, value in _SETTINGS)
