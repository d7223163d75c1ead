"""A pylon impedance table that gives energy to the mount (an active damper)
is refused naming its rows.

Before, a table with Im Z < 0 on every row was accepted: the coupled mount
was unstable (an eigenvalue with real part +945 1/s), yet a steady T was
returned. The single-DOF engine on such a pylon shows why: its coupled
eigenvalues, computed here from the equations of motion, grow.
"""
import dataclasses
import math

import numpy as np
import pytest
import scipy.linalg as sla
from test_flexible_pylon import PYLON_DAMPING, PYLON_MASS, PYLON_STIFFNESS, _pins, _rows, _sdof, _write
from test_sdof import DAMPING, MASS, NATURAL_HZ, STIFFNESS

from workbook.errors import CaseError
from workbook.model.pylon_impedance import PylonImpedance, read_impedance_csv
from workbook.solve.pipeline import run_case

#: An active damper: the pylon's damping with its sign turned, ten times over.
ACTIVE_DAMPING = -10.0 * PYLON_DAMPING


def _pylon(damping):
    def value(frequency):
        w = 2 * math.pi * frequency
        return (PYLON_STIFFNESS + 1j * w * damping - w ** 2 * PYLON_MASS) * np.eye(3)
    return value


def _largest_growth_rate(pylon_damping):
    """Largest real part of the eigenvalues of the engine (mass M on four
    hinges k, d) on four pins (each a pylon mass, spring and damper), 1/s:
    one direction, the four pins moving alike."""
    mass = np.diag([MASS, 4 * PYLON_MASS])
    stiffness = 4 * np.array([[STIFFNESS, -STIFFNESS], [-STIFFNESS, STIFFNESS + PYLON_STIFFNESS]])
    damping = 4 * np.array([[DAMPING, -DAMPING], [-DAMPING, DAMPING + pylon_damping]])
    inverse = np.linalg.inv(mass)
    state = np.block([[np.zeros((2, 2)), np.eye(2)], [-inverse @ stiffness, -inverse @ damping]])
    return float(sla.eigvals(state).real.max())


def test_the_active_pylon_makes_the_mount_unstable_and_is_refused(tmp_path):
    assert _largest_growth_rate(PYLON_DAMPING) < 0 < _largest_growth_rate(ACTIVE_DAMPING)
    case = _sdof()
    frequencies = [1.0, 5.0, 10.0, 30.0, 100.0]
    table = _write(tmp_path / "active.csv", _rows(frequencies, _pins(case), _pylon(ACTIVE_DAMPING)))
    with pytest.raises(CaseError) as error:
        read_impedance_csv(table)
    words = str(error.value)
    assert words.startswith('pylon impedance active.csv, field \'imag\': found "20 of 20 rows giving energy')
    w = 2 * math.pi * 1.0
    assert f"pin 'hinge 0' at 1 Hz (least eigenvalue {w * ACTIVE_DAMPING:.3g} N/m)" in words
    assert "and 17 more" in words and "a passive pylon" in words


def test_a_passive_table_with_an_undamped_and_a_coupled_row_is_accepted():
    """Zero damping (Im Z = 0) and a coupled but passive imaginary part,
    [[2, 1], [1, 2]] (eigenvalues 1 and 3), pass; [[1, 2], [2, 1]] (eigenvalue
    -1, though every diagonal entry is positive) does not."""
    passive = np.array([[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 1.0]])
    active = np.array([[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    values = np.stack([np.eye(3) * 1e7, np.eye(3) * 1e7 + 1j * 1e6 * passive])[:, None]
    PylonImpedance.from_array("passive", [1.0, 2.0], ["hinge 0"], values)
    values[1, 0] = np.eye(3) * 1e7 + 1j * 1e6 * active
    with pytest.raises(CaseError, match=r"1 of 2 rows .* pin 'hinge 0' at 2 Hz \(least eigenvalue -1e\+06 N/m\)"):
        PylonImpedance.from_array("active", [1.0, 2.0], ["hinge 0"], values)


def test_the_passive_pylon_still_answers():
    """The same table with the pylon's own damping gives the series closed form at 11 Hz."""
    case = _sdof((1.1,))
    frequency = 1.1 * NATURAL_HZ
    table = PylonImpedance.from_array("passive", [frequency], _pins(case),
                                      np.broadcast_to(_pylon(PYLON_DAMPING)(frequency), (1, 4, 3, 3)))
    run = run_case(dataclasses.replace(case, pylon=table)).runs[0]
    w = 2 * math.pi * frequency
    hinge, pylon = STIFFNESS + 1j * w * DAMPING, _pylon(PYLON_DAMPING)(frequency)[0, 0]
    series = hinge * pylon / (hinge + pylon)
    np.testing.assert_allclose(run.transmissibility[1], abs(4 * series / (4 * series - w ** 2 * MASS)), rtol=1e-6)
