"""Distinct links reduced side by side in worker processes give the links a serial reduction gives."""
import numpy as np
import pytest

from flexbodies.link import is_reduced, reduce_link_set
from workbook.model.reference import reference_case
from workbook.scene.build import link_jobs, reduce_links
from workbook.scene.link_workers import LinkJob, reduce_in_workers

#: A mesh coarse enough for a quick reduction; the checks compare two ways of reducing the same FE model.
ELEMENT_SIZE = 0.04


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch):
    """An empty reduction cache of the test's own."""
    monkeypatch.setenv("MOUNTWB_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _three_distinct_jobs():
    case = reference_case(element_size=ELEMENT_SIZE)
    jobs = link_jobs(case)
    assert len(jobs) == 3  # front links, rear links, thrust rods
    return case, jobs


@pytest.mark.slow
def test_workers_fill_the_cache_with_the_links_a_serial_reduction_gives(fresh_cache):
    _, jobs = _three_distinct_jobs()
    finished, spared = [], []
    assert reduce_in_workers(list(jobs), done=finished.append, workers=2,
                             spare=lambda: spared.append(len(finished))) == 3
    assert sorted(map(id, finished)) == sorted(map(id, jobs))
    assert len(spared) <= 1 and all(count < len(jobs) for count in spared)  # once at most, while a job ran
    for job in jobs:
        assert is_reduced(job.model, job.modes, job.excitations_hz, stiffening=job.stiffening)
        loaded = job.reduce()
        serial = reduce_link_set(job.model, job.modes, job.excitations_hz, use_cache=False)
        for a, b in zip(loaded, serial, strict=True):
            assert a.cache_hit and not b.cache_hit
            assert a.frequencies["mounted_hz"] == pytest.approx(b.frequencies["mounted_hz"], rel=1e-9)
            assert len(a.frequencies["reduced_hz"]) == len(b.frequencies["reduced_hz"])
            assert np.allclose(a.frequencies["reduced_hz"], b.frequencies["reduced_hz"], rtol=1e-7)
            # same reduced mass: the same floating-frame body (mode signs may differ; the mass may not)
            assert float(a.ffrf["totalMass"]) == pytest.approx(float(b.ffrf["totalMass"]), rel=1e-12)
            assert np.allclose(np.linalg.eigvalsh(a.ffrf["stiffnessMatrixReduced"]),
                               np.linalg.eigvalsh(b.ffrf["stiffnessMatrixReduced"]), rtol=1e-7, atol=1e-6)


@pytest.mark.slow
def test_nothing_runs_in_workers_when_the_cache_holds_the_links(fresh_cache):
    _, jobs = _three_distinct_jobs()
    for job in jobs:
        job.reduce()
    assert reduce_in_workers(list(jobs), workers=2) == 0


def test_one_worker_or_one_job_leaves_the_work_to_the_caller(fresh_cache):
    _, jobs = _three_distinct_jobs()
    assert reduce_in_workers(list(jobs), workers=1) == 0
    assert reduce_in_workers(list(jobs)[:1], workers=2) == 0
    assert not any(job.cached() for job in jobs)


@pytest.mark.slow
def test_a_job_that_fails_in_a_worker_is_left_to_the_serial_pass_which_reports_it(fresh_cache):
    _, jobs = _three_distinct_jobs()
    job, *others = jobs
    broken = LinkJob(job.model, "auto", (0.0,), job.stiffening)  # 'auto' without an excitation frequency
    assert reduce_in_workers([broken, *others], workers=2) == 3  # the worker's error is not raised here
    assert all(j.cached() for j in others)
    with pytest.raises(ValueError, match="'auto' needs the highest excitation frequency"):
        broken.reduce()


@pytest.mark.slow
def test_progress_grows_to_every_link_of_the_case(fresh_cache):
    case, _ = _three_distinct_jobs()
    seen = []
    reduced = reduce_links(case, progress=seen.append)
    assert list(reduced) == [link.name for link in case.links]
    assert seen == sorted(seen) and len(set(seen)) == len(seen) and seen[-1] == len(case.links)
