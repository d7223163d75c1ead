"""Stability at the preloaded equilibrium: an upward push on the engine puts
the links in compression, whose geometric stiffness is negative; beyond a
critical push the preloaded mount tips. The run must stop in plain words
in both domains, never report a clipped 0 Hz mode. Real Exudyn runs on the
reference mount with rigid links."""
import dataclasses

import numpy as np
import pytest

from workbook.errors import DivergenceError, SimulationError, UnstablePreloadError
from workbook.model.case import PointForce
from workbook.model.reference import LP_ROTOR
from workbook.scene.build import build_scene
from workbook.solve.modes import linearize, modes_of
from workbook.solve.pipeline import run_case
from workbook.solve.preload import link_compression, solve_preload
from workbook.solve.time_domain import integrate, plan_run


@pytest.fixture(scope="module")
def rigid(coarse_reference):
    return dataclasses.replace(coarse_reference.with_rigid_links(), excitations=(LP_ROTOR,))


def _pushed(case, newtons, method="frequency"):
    push = PointForce("push", point=case.engine.center_of_mass, force=(0.0, 0.0, newtons))
    return dataclasses.replace(case, static_loads=case.static_loads + (push,),
                               analysis=dataclasses.replace(case.analysis, method=method))


def _preloaded_unchecked(case):
    """The scene solved for its preload by Exudyn alone (no stability check)."""
    import exudyn as exu

    scene = build_scene(case, case.excitations[0])
    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    settings.staticSolver.verboseMode = 0
    with scene.excitation_paused():
        assert scene.mbs.SolveStatic(settings, updateInitialValues=True)
    return scene


@pytest.mark.parametrize("method", ["time", "frequency"])
def test_a_push_that_tips_the_mount_stops_in_both_domains(rigid, method):
    with pytest.raises(UnstablePreloadError, match=r"the preload makes the mount unstable.*negative.*engine roll"
                                                   r".*'push' 1\.9e\+06 N.*links in compression: 'front") as caught:
        run_case(_pushed(rigid, 1.9e6, method))
    assert isinstance(caught.value, SimulationError) and caught.value.omega_squared[0] < 0


def test_the_refused_preload_really_diverges_and_the_accepted_one_does_not(rigid):
    """An independent method: integrate from the preload without the check.
    At 1.9 MN (refused, w^2 < 0) the engine runs away within 3 s; at 1.8 MN
    (accepted: the lowest mode at the preload is still above 0.05 Hz) it
    stays put, and the check agrees with the sign of w^2."""
    outcomes = {}
    for push in (1.8e6, 1.9e6):
        case = _pushed(rigid, push, "time")
        case = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, settle_time=3.0))
        scene = _preloaded_unchecked(case)
        lowest = modes_of(linearize(scene), gyroscopic=False)[0].omega_squared
        plan = plan_run(case.analysis, scene.excitation.signal, [])
        try:
            integrate(scene, plan)
            outcomes[push] = ("bounded", lowest)
        except DivergenceError:
            outcomes[push] = ("diverged", lowest)
    assert outcomes[1.8e6][0] == "bounded" and outcomes[1.8e6][1] > 0
    assert outcomes[1.9e6][0] == "diverged" and outcomes[1.9e6][1] < 0
    assert np.all(np.isfinite(run_case(_pushed(rigid, 1.8e6)).runs[0].transmissibility))
    with pytest.raises(UnstablePreloadError):
        run_case(_pushed(rigid, 1.9e6))


def test_link_compression_agrees_at_both_eyes_of_every_rigid_link(rigid):
    """A rigid link carries the same axial force at both eyes up to its own
    weight: the per-eye halves of link_compression differ by no more than
    m g; the push puts the
    front links in compression, gravity alone leaves them in tension."""
    for newtons, front in ((0.0, -1.0), (1.0e6, 1.0)):
        scene = build_scene(_pushed(rigid, newtons))
        solve_preload(scene)
        forces = scene.hinge_forces()
        compression = link_compression(scene, forces)
        for link in rigid.links:
            halves = []
            for eye in (link.end_a, link.end_b):
                at_eye = {h.name for h in rigid.hinges if link.name in h.bodies and np.allclose(h.position, eye)}
                halves.append(link_compression(scene, {h: (f if h in at_eye else 0 * f) for h, f in forces.items()})
                              [link.name])
            weight = scene.links[link.name].mass * 9.81
            assert abs(halves[0] - halves[1]) <= weight
        assert np.sign(compression["front-left"]) == front
