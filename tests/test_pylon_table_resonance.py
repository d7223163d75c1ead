"""An impedance table too coarse across a resonance of the pylon is warned.

The single-DOF engine on a pylon whose pins each carry a mass on two
springs (a resonance of the pylon at 43.3 Hz with the pin held, damping
ratio 0.7 %, half-power bandwidth 0.6 Hz): rows 10 Hz apart straddle it,
and linear interpolation between them puts T at 45 Hz 2.6 times below the
closed form (before: no warning). Rows 0.1 Hz apart follow it.
"""
import dataclasses
import math

import numpy as np
import pytest
from test_flexible_pylon import PYLON_DAMPING, PYLON_STIFFNESS, _pins, _sdof
from test_sdof import DAMPING, MASS, STIFFNESS

from workbook.model.pylon_impedance import PylonImpedance
from workbook.solve.pipeline import run_case

#: Between the rows at 40 and 50 Hz, above the pylon's resonance.
ASKED_HZ = 45.0
#: The pylon's mass behind each pin, kg, and its damper to ground, N s/m.
PYLON_MASS, LIGHT_DAMPING = 40.0, 0.1 * PYLON_DAMPING


def _pylon(frequency):
    """Point dynamic stiffness of a pin on a spring to a mass, itself on a
    spring and damper to ground, N/m."""
    w = 2 * math.pi * frequency
    ground, pin = PYLON_STIFFNESS + 1j * w * LIGHT_DAMPING, PYLON_STIFFNESS
    return pin - pin ** 2 / (ground + pin - PYLON_MASS * w ** 2)


def _table(frequencies, case):
    values = np.array([np.broadcast_to(_pylon(f) * np.eye(3), (len(_pins(case)), 3, 3)) for f in frequencies])
    return PylonImpedance.from_array("pylon.csv", frequencies, _pins(case), values)


def _closed_form(frequency):
    """T of the engine on hinges in series with the exact pylon, at *frequency*."""
    w = 2 * math.pi * frequency
    hinge, pylon = STIFFNESS + 1j * w * DAMPING, _pylon(frequency)
    series = hinge * pylon / (hinge + pylon)
    return abs(4 * series / (4 * series - w ** 2 * MASS))


@pytest.fixture(scope="module")
def engine():
    return _sdof((ASKED_HZ / 10.0,))


def _run(engine, step_hz):
    table = _table(np.round(np.arange(10.0, 60.0 + step_hz / 2, step_hz), 6), engine)
    return run_case(dataclasses.replace(engine, pylon=table)).runs[0]


def test_rows_10_hz_apart_across_the_resonance_are_warned(engine):
    run = _run(engine, 10.0)
    assert run.frequency_hz == pytest.approx(ASKED_HZ)
    # the interpolated pylon misses the resonance: T 2.6 times too low
    assert run.transmissibility[1] < _closed_form(ASKED_HZ) / 2
    (warning,) = [w for w in run.warnings if w.startswith("pylon impedance")]
    assert "45 Hz lies between the rows at 40 and 50 Hz, where Re Kxx of pin 'hinge 0' changes sign" in warning
    assert "a resonance of the pylon between the rows" in warning
    assert "Give rows no more than 0.2 Hz apart from 40 to 50 Hz" in warning


def test_rows_a_tenth_of_a_hz_apart_follow_the_resonance_unwarned(engine):
    """Unwarned also between the rows that hold the resonance (43.3 Hz)."""
    table = _table(np.round(np.arange(10.0, 60.0 + 0.05, 0.1), 6), engine)
    assert table.interpolation_warnings([43.33], range(4)) == [[]]
    run = _run(engine, 0.1)
    assert not [w for w in run.warnings if w.startswith("pylon impedance")]
    assert run.transmissibility[1] == pytest.approx(_closed_form(ASKED_HZ), rel=0.01)
