"""Shared test set-up: single-threaded BLAS and a per-session reduction cache."""
import os

import pytest
from threadpoolctl import threadpool_limits

# Multithreaded BLAS makes the small dense solves of this package erratic and
# many times slower on a shared 2-core machine.
_blas_limit = threadpool_limits(limits=1)


@pytest.fixture(scope="session", autouse=True)
def cache_dir(tmp_path_factory):
    """A reduction cache shared by all tests of one session (never the user's own cache)."""
    path = tmp_path_factory.mktemp("reduction-cache")
    os.environ["MOUNTWB_CACHE"] = str(path)
    return path
