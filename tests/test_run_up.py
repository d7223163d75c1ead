"""Run-ups: an unbalance over a speed range, force U w^2, against closed forms and single runs."""
import dataclasses
import math

import numpy as np
import pytest
from test_sdof import NATURAL_HZ, ZETA, closed_form, sdof_case

from workbook.model.case import RotatingForce, RunUp
from workbook.model.reference import HP_ROTOR, LP_ROTOR
from workbook.solve.pipeline import run_case
from workbook.solve.run_up import run_up

UNBALANCE = 4e-3       # kg m


@pytest.fixture(scope="module")
def sdof_run_up():
    case = sdof_case(())
    rotor = RotatingForce("rotor", case.engine.center_of_mass, rpm=600.0, unbalance=UNBALANCE)
    item = RunUp.speeds("run-up", rotor, 120.0, 1800.0, 41, unit="rpm")
    return run_up(dataclasses.replace(case, excitations=(item,)), item)


def test_single_dof_run_up_follows_u_omega_squared_times_the_closed_form(sdof_run_up):
    frame = sdof_run_up.frame()
    speeds = frame.index.to_numpy()
    omega = 2 * math.pi * speeds / 60
    ratio = speeds / 60 / NATURAL_HZ
    expected = UNBALANCE * omega ** 2 * np.array([closed_form(r) for r in ratio])
    # the rotating force drives y and z alike, x not at all
    np.testing.assert_allclose(frame["F y N"], expected, rtol=1e-6)
    np.testing.assert_allclose(frame["F z N"], expected, rtol=1e-6)
    assert frame["F x N"].max() < 1e-9 * expected.max()
    np.testing.assert_allclose(frame["excitation N"], UNBALANCE * omega ** 2, rtol=1e-12)
    np.testing.assert_allclose(frame["T z"], frame["F z N"] / frame["excitation N"], rtol=1e-12)
    np.testing.assert_allclose(frame["frequency Hz"], speeds / 60, rtol=1e-12)


def test_the_mounted_modes_are_marked_at_their_speed(sdof_run_up, tmp_path):
    marked = sdof_run_up.mode_speeds()
    # the translations in y and z at f_n = 10 Hz = 600 rpm lie in the range
    translations = [speed for _, kind, speed in marked if abs(speed - 60 * NATURAL_HZ) < 1e-3 * 60 * NATURAL_HZ]
    assert len(translations) >= 2 and all(kind == "mounted" for _, kind, _ in marked)
    damping = sdof_run_up.modes_frame()["damping ratio %"]
    assert np.isclose(damping, 100 * ZETA, rtol=1e-3).sum() >= 2
    figure = sdof_run_up.plot()
    path = tmp_path / "run-up.png"
    figure.savefig(path)
    assert path.stat().st_size > 10_000


@pytest.mark.slow
def test_run_up_gives_the_single_runs_at_the_rotor_speeds(coarse_reference):
    """A run-up from the LP to the HP speed gives at those two speeds the T
    of single-frequency runs of the same imbalance plane (force given in N)."""
    template = dataclasses.replace(LP_ROTOR, name="run-up rotor", amplitude=None, unbalance=2e-3)
    item = RunUp.speeds("run-up", template, LP_ROTOR.frequency, HP_ROTOR.frequency, 6, unit="Hz")
    case = dataclasses.replace(coarse_reference, excitations=(item,))
    answer = run_up(case, item)
    singles = (dataclasses.replace(LP_ROTOR, name="at LP"),
               dataclasses.replace(LP_ROTOR, name="at HP", frequency_hz=HP_ROTOR.frequency))
    single_case = dataclasses.replace(coarse_reference, excitations=singles,
                                      analysis=dataclasses.replace(coarse_reference.analysis, method="frequency"))
    result = run_case(single_case)
    frame = answer.frame()
    for name, row in (("at LP", 0), ("at HP", -1)):
        expected = result.run(name).transmissibility
        got = frame[["T x", "T y", "T z"]].to_numpy()[row]
        np.testing.assert_allclose(got, expected, rtol=2e-3, atol=1e-4 * expected.max(), err_msg=name)
