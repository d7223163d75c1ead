"""A time run started in the steady state of its linearised scene.

The single-DOF isolator of tests/test_damping.py (a rigid mass on four
identical hinges with loss factor eta) transmits

    T(r) = sqrt(1 + eta^2) / sqrt((1 - r^2)^2 + eta^2)

in the steady state; the time domain holds the loss factor as its viscous
equivalent eta k / w at the run's frequency, exact there. With eta = 0.01 the
mounted modes are damped so little (zeta = eta / (2 r)) that a start from
rest plans 287 settle periods at r = 3; started in the steady state, the two
measured windows are the whole run.
"""
import dataclasses
import math

import numpy as np
import pytest

from workbook.errors import CaseError
from workbook.model.case import ENGINE, PYLON, AnalysisSettings, Case, Engine, Hinge, RotatingForce, Simultaneous
from workbook.solve.pipeline import prepare, run_case
from workbook.solve.steady_start import REST, STEADY, choose_start, steady_start
from workbook.solve.time_domain import extract, integrate, plan_run

MASS = 500.0              # kg
NATURAL_HZ = 10.0
STIFFNESS = MASS * (2 * math.pi * NATURAL_HZ) ** 2 / 4      # per hinge, N/m
CG = (0.2, -0.1, 0.3)
CORNERS = [(1, 1), (1, -1), (-1, 1), (-1, -1)]


def closed_form(ratio: float, eta: float) -> float:
    return math.sqrt((1 + eta ** 2) / ((1 - ratio ** 2) ** 2 + eta ** 2))


def shake(ratio: float) -> RotatingForce:
    return RotatingForce(f"r = {ratio:g}", point=CG, frequency_hz=ratio * NATURAL_HZ, amplitude=1000.0)


def isolator(eta: float, *ratios: float, damping: float = 0.0, **analysis) -> Case:
    hinges = tuple(Hinge(f"hinge {i}", PYLON, ENGINE, (CG[0] + sx * 0.4, CG[1] + sy * 0.3, CG[2]), STIFFNESS,
                         damping, loss_factor=eta)
                   for i, (sx, sy) in enumerate(CORNERS))
    return Case("isolator", Engine(MASS, CG, ((20.0, 0, 0), (0, 30.0, 0), (0, 0, 40.0))), links=(), hinges=hinges,
                excitations=tuple(shake(r) for r in ratios),
                analysis=AnalysisSettings(steps_per_period=80, method="time", **analysis))


@pytest.fixture(scope="module")
def steady_runs():
    return run_case(isolator(0.01, 0.5, 3.0))


@pytest.mark.parametrize("ratio", [0.5, 3.0])
def test_steady_start_meets_the_closed_form_in_its_two_windows(steady_runs, ratio):
    run = steady_runs.run(f"r = {ratio:g}")
    assert run.steady
    # the rotating force drives y and z alike
    np.testing.assert_allclose(run.transmissibility[1:], closed_form(ratio, 0.01), rtol=0.005)
    card = steady_runs.model_cards[run.name]
    assert card.solver["steps"] == 2 * 20 * 80
    assert card.solver["start"].startswith("steady: auto: the scene is linear")
    assert card.solver["windows beyond the plan"] == "none"
    assert card.solver["ramp"].startswith("none")
    assert card.to_dict()["solver"]["start"] == card.solver["start"]


def test_a_start_from_rest_plans_the_settling_the_steady_start_skips(steady_runs):
    case = isolator(0.01, 3.0)
    prepared = prepare(case, case.excitations[0], harmonic=False)
    with prepared.scene as scene:
        rest = plan_run(case.analysis, scene.excitation.signal, prepared.modes, start=REST)
        steady = plan_run(case.analysis, scene.excitation.signal, prepared.modes, start=STEADY)
    assert rest.settle_periods == 287 and rest.ramp_periods == 10
    assert steady.ramp_periods == steady.settle_periods == 0
    assert steady.extension_periods == rest.ramp_periods + rest.settle_periods
    assert steady_runs.model_cards["r = 3"].solver["steps"] == steady.steps == 2 * 20 * 80
    assert rest.steps > 8 * steady.steps


def test_from_rest_the_same_short_plan_is_not_steady():
    """The excitation in full from t = 0 and no settling: the plan of the steady
    start, but from rest; the free vibration shows and the guard says so."""
    mount = run_case(isolator(0.01, 3.0, start="rest", ramp_periods=0.0, settle_time=0.0))
    run = mount.run()
    assert mount.model_cards[run.name].solver["steps"] == 2 * 20 * 80
    assert not run.steady and run.steady_change > 0.05
    assert run.warnings[0].startswith("not steady: the pylon-force amplitudes of the last two 20-period windows")
    assert mount.model_cards[run.name].solver["start"] == "rest: the case asks for it (start 'rest')"


def _wrong_start(case: Case, scale: float):
    """Run *case*'s excitation from its steady start with every phasor times *scale*."""
    excitation = case.excitations[0]
    prepared = prepare(case, excitation, harmonic=False, linear_model=True)
    with prepared.scene as scene:
        plan = plan_run(case.analysis, scene.excitation.signal, prepared.modes, start=STEADY)
        start = steady_start(prepared.model, excitation)
        dataclasses.replace(start, phasors=scale * start.phasors).apply(scene)
        histories = integrate(scene, plan, steady=lambda h: extract(scene, plan, h).steady)
        return plan, histories, extract(scene, plan, histories)


def test_a_wrong_start_is_integrated_until_the_windows_agree():
    """5 % short of the steady state: the windows disagree, the run goes on and ends at the
    closed form (a start at half the amplitude needs longer than the allowance: reported
    as below)."""
    plan, histories, result = _wrong_start(isolator(0.01, 3.0, ramp_periods=0.0), 0.95)
    assert 0 < histories.extended_periods <= plan.extension_periods
    assert len(histories.time) == 2 * 20 * 80 + 1
    assert result.steady
    np.testing.assert_allclose(result.transmissibility[1:], closed_form(3.0, 0.01), rtol=0.005)


def test_a_wrong_start_that_does_not_settle_in_time_is_reported():
    """20 % too much with a short allowance (the 29 settle periods of eta = 0.1): not steady, in words."""
    plan, histories, result = _wrong_start(isolator(0.1, 3.0, ramp_periods=0.0), 1.2)
    assert plan.extension_periods == 29 and histories.extended_periods == 20
    assert not result.steady
    assert ("the run started in the steady state of its linearised scene and went on 20 periods beyond its plan "
            "without settling") in result.warnings[0]


def test_both_frequencies_start_together_in_their_steady_state():
    """Two rotating forces at once (viscous hinges: one model in both domains): the
    sum of the two steady states is the start; each part matches the frequency domain."""
    zeta = 0.01
    damping = 2 * zeta * math.sqrt(4 * STIFFNESS * MASS) / 4
    case = dataclasses.replace(isolator(0.0, damping=damping),
                               excitations=(Simultaneous("both", (shake(0.5), shake(3.0))),))
    timed = run_case(case)
    exact = run_case(dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method="frequency")))
    for name in ("both / r = 0.5", "both / r = 3"):
        assert timed.run(name).steady
        np.testing.assert_allclose(timed.run(name).transmissibility[1:], exact.run(name).transmissibility[1:],
                                   rtol=0.005)
    assert timed.model_cards["both / r = 3"].solver["windows beyond the plan"] == "none"


def test_a_clearance_starts_at_rest_unless_asked():
    gaps = dataclasses.replace(isolator(0.01, 3.0), hinges=tuple(
        dataclasses.replace(h, radial_clearance=1e-4) for h in isolator(0.01, 3.0).hinges))
    assert choose_start(isolator(0.01, 3.0)).start == STEADY
    assert choose_start(gaps).start == REST
    assert "nonlinear" in choose_start(gaps).reason
    asked = dataclasses.replace(gaps, analysis=dataclasses.replace(gaps.analysis, start="steady"))
    assert choose_start(asked).start == STEADY


def test_a_bad_start_is_named():
    with pytest.raises(CaseError, match="start"):
        AnalysisSettings(start="sometimes")


def test_the_case_sheet_sets_the_start(tmp_path):
    from excel_helpers import copy_reference, set_cells

    from workbook.excel.reader import read_workbook

    path = copy_reference(tmp_path)
    assert read_workbook(path).case.analysis.start == "auto"
    set_cells(path, {("Case", "start", 3): "rest"})
    assert read_workbook(path).case.analysis.start == "rest"


@pytest.mark.slow
def test_reference_mount_time_domain_from_the_steady_start_matches_the_frequency_domain(cache_dir):
    """The coarse reference mount with its loss-factor hinges (the mounted modes damped
    0.2 % on the LP rotor): two windows of the steady start give the exact T to 1 %."""
    from conftest import COARSE_ELEMENT_SIZE, SHORT

    from workbook.model.reference import LP_ROTOR, reference_case

    case = dataclasses.replace(reference_case(element_size=COARSE_ELEMENT_SIZE, analysis=SHORT),
                               excitations=(LP_ROTOR,))
    assert all(h.loss_factor > 0 and h.damping == 0 for h in case.hinges)
    timed = run_case(dataclasses.replace(case, analysis=dataclasses.replace(SHORT, method="time")))
    exact = run_case(dataclasses.replace(case, analysis=dataclasses.replace(SHORT, method="frequency"))).run()
    assert timed.run().steady
    assert timed.model_cards[LP_ROTOR.name].solver["steps"] == 2 * SHORT.measured_periods * SHORT.steps_per_period
    # x and z; the nearly cancelled lateral force (T_y about 0.001) carries the step error of 40 steps per period
    np.testing.assert_allclose(timed.run().transmissibility[[0, 2]], exact.transmissibility[[0, 2]], rtol=0.01)
