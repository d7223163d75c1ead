"""The design evaluation keeps the arrays it frees for its next batch (glibc's ``mallopt``)."""
from __future__ import annotations

import resource
import sys

import numpy as np
import pytest

from workbook.design.memory import keep_freed_memory


def _page_faults_of_batches(rounds: int, held: int, size: int) -> int:
    """Minor page faults of *rounds* batches, each holding *held* arrays of *size* floats at once, then freeing
    them all (as a batch of designs does with its temporaries)."""
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(rounds):
        arrays = [np.ones(size) for _ in range(held)]
        del arrays
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="mallopt is glibc's")
def test_freed_batches_are_reused_without_page_faults():
    """After :func:`keep_freed_memory`, ten batches of six 4 MB arrays fault in fewer pages than one batch
    holds (6144): glibc's own thresholds give the freed heap back after each batch and fault every page
    again, about 30,000 faults."""
    assert keep_freed_memory()
    size = 1 << 19
    _page_faults_of_batches(2, 6, size)                  # the heap grown once
    assert _page_faults_of_batches(10, 6, size) < 6 * size * 8 // 4096
