"""Shared test set-up: single-threaded BLAS, a per-session reduction cache and
the coarse reference mount several test modules run."""
import os

import pytest
from threadpoolctl import threadpool_limits

from workbook.model.case import AnalysisSettings
from workbook.model.reference import reference_case

# Multithreaded BLAS makes the small dense solves of this package erratic and
# many times slower on a shared 2-core machine.
_blas_limit = threadpool_limits(limits=1)

#: Link mesh element size of the coarse reference mount, m: the checks that
#: use it compare runs with each other, not with the converged mesh.
COARSE_ELEMENT_SIZE = 0.03

#: Short but steady time runs: the 10-period smooth start leaves the mounted
#: modes almost unexcited, so half a decay time constant of settling and
#: 10-period windows suffice (the steady checks of the tests confirm it).
SHORT = AnalysisSettings(settle_time_constants=0.5, measured_periods=10)


@pytest.fixture(scope="session", autouse=True)
def cache_dir(tmp_path_factory):
    """A reduction cache shared by all tests of one session (never the user's own cache).

    Under pytest-xdist the workers of a session share it (the cache locks its
    entries), so each link is reduced once per session, not once per worker.
    """
    base = tmp_path_factory.getbasetemp()
    path = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "reduction-cache"
    path.mkdir(exist_ok=True)
    os.environ["MOUNTWB_CACHE"] = str(path)
    return path


@pytest.fixture(scope="session")
def coarse_reference(cache_dir):
    """The reference mount (LP and HP rotors) with coarse link meshes and short time runs.

    Its hinges keep the former viscous damping (``hinge_damping="viscous"``): the checks
    that use it compare runs with each other, many in the time domain, where the loss
    factor's viscous equivalent at the rotor frequency damps the mounted modes so little
    that a run settles 6 (LP) to 29 (HP) times longer. tests/test_damping.py runs the
    loss factor on the whole mount.
    """
    return reference_case(element_size=COARSE_ELEMENT_SIZE, analysis=SHORT, hinge_damping="viscous")
