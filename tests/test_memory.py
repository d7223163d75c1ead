"""Memory stays flat over many runs in one process: every scene frees Exudyn's
system when it is dropped (without that, each run of the reference mount with
flexible links left about 13 MB behind)."""
import dataclasses

import psutil
import pytest

from workbook.model.reference import reference_case
from workbook.solve.pipeline import run_case

#: Growth allowed per run, MB (a run that kept its Exudyn system grew by ~13 MB).
GROWTH_PER_RUN_MB = 1.0


def _static_mode_case(method: str, **analysis):
    """The reference mount with static-mode flexible links (cheap, but Exudyn
    FFRF bodies like the real thing), one excitation, answered by *method*."""
    case = reference_case()
    links = tuple(dataclasses.replace(link, modes="static") for link in case.links)
    return dataclasses.replace(case, links=links, excitations=case.excitations[:1],
                               analysis=dataclasses.replace(case.analysis, method=method, **analysis))


def _growth_per_run(case, runs: int) -> float:
    process = psutil.Process()
    run_case(case)  # caches, imports and allocator pools settle in the first run
    run_case(case)
    before = process.memory_info().rss
    for _ in range(runs):
        run_case(case)
    return (process.memory_info().rss - before) / 2**20 / runs


@pytest.mark.slow
def test_frequency_domain_runs_do_not_grow_memory():
    assert _growth_per_run(_static_mode_case("frequency"), 8) < GROWTH_PER_RUN_MB


@pytest.mark.slow
def test_time_domain_runs_do_not_grow_memory():
    case = _static_mode_case("time", steps_per_period=20, measured_periods=4, ramp_periods=2.0)
    assert _growth_per_run(case, 5) < GROWTH_PER_RUN_MB


def test_a_closed_scene_has_freed_its_system(coarse_reference):
    from workbook.scene.build import build_scene

    case = coarse_reference.with_rigid_links()
    with build_scene(case) as scene:
        assert scene.mbs.systemData.ODE2Size() > 0
    assert scene.system.NumberOfSystems() == 0
    scene.close()  # closing twice does nothing
