"""A run-up or sweep whose grid steps over a lightly damped mode is warned
with the missed peak and a grid that resolves it.

The single-DOF engine (10 Hz on four hinges) with the hinges' loss factor
0.002 only: T peaks at |(1 + i eta) / (i eta)| = 500 at 10 Hz, within a
half-power bandwidth of eta f_n = 0.02 Hz. Before, a run-up of 12 speeds
tabulated a peak of 11 with no warning.
"""
import dataclasses

import numpy as np
import pytest
from test_sdof import NATURAL_HZ, sdof_case

from workbook.model.case import RotatingForce, RunUp
from workbook.solve.pipeline import run_case
from workbook.solve.run_up import run_up
from workbook.solve.sweep_grid import grid_warnings

ETA = 0.002
#: T at the mode: |1 + i eta| / eta.
PEAK = abs(1 + 1j * ETA) / ETA
UNBALANCE = RotatingForce("imbalance", point=(0.2, -0.1, 0.3), rpm=600.0, unbalance=1e-3)


@pytest.fixture(scope="module")
def lightly_damped():
    case = sdof_case(())
    hinges = tuple(dataclasses.replace(h, damping=0.0, loss_factor=ETA) for h in case.hinges)
    return dataclasses.replace(case, hinges=hinges, analysis=dataclasses.replace(case.analysis, method="auto"))


def _peak(answer):
    return float(answer.transmissibility()[:, 1].max())


def test_twelve_speeds_miss_the_peak_and_say_so(lightly_damped):
    coarse = run_up(lightly_damped, RunUp.speeds("run-up", UNBALANCE, 300.0, 900.0, 12))
    assert _peak(coarse) < PEAK / 10                          # measured: 11 against 500
    warned = [(run.name, w) for run in coarse.result.runs for w in run.warnings if "steps over the peak" in w]
    assert len(warned) >= 1
    name, words = warned[0]
    assert "mounted mode" in words and "at 600 rpm" in words and "half-power bandwidth is 1.2 rpm" in words
    assert "Add points no more than 0.3 rpm apart from 598.8 to 601.2 rpm" in words


def test_the_advised_grid_finds_the_peak_unwarned(lightly_damped):
    """Speeds 0.3 rpm apart from 598.8 to 601.2 rpm, as advised: the table's
    peak within 3 % of the closed form, and no warning."""
    fine = run_up(lightly_damped, RunUp("run-up", UNBALANCE, tuple(np.arange(598.8, 601.21, 0.3) / 60), "rpm"))
    assert not [w for run in fine.result.runs for w in run.warnings if "steps over the peak" in w]
    assert _peak(fine) == pytest.approx(PEAK, rel=0.03)


def test_a_sweep_in_a_case_is_warned_too(lightly_damped):
    sweep = RunUp.speeds("run-up", UNBALANCE, 5.0, 15.0, 12, unit="Hz")
    result = run_case(dataclasses.replace(lightly_damped, excitations=(sweep,)))
    assert any("steps over the peak" in w and "at 10 Hz" in w for run in result.runs for w in run.warnings)


def test_a_grid_point_on_the_mode_is_not_warned(lightly_damped):
    modes = run_up(lightly_damped, RunUp.speeds("run-up", UNBALANCE, 300.0, 900.0, 12)).modes
    assert grid_warnings([9.0, NATURAL_HZ, 11.0], modes) == {}
    assert list(grid_warnings([9.0, 10.1, 11.0], modes)) == [1]
