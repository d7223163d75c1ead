"""A mount without static loads: its pin forces are the round-off of the
geometry, which the equilibrium check must pass, while a load that nothing
carries must still fail it.

Before, the check judged the round-off pin forces (8.7e-6 N summed on the
reference mount) against the 1 N scale of a small excitation with the
tolerance 1e-6, and every small excitation and every four-pole set of an
unloaded mount stopped with ``EquilibriumError``.
"""
import dataclasses

import exudyn as exu
import numpy as np
import pytest
from conftest import COARSE_ELEMENT_SIZE

from workbook.answers.isolation import pylon_sum
from workbook.errors import EquilibriumError
from workbook.model.case import HarmonicForce
from workbook.model.reference import ENGINE_CG, reference_case
from workbook.scene.build import build_scene
from workbook.solve.harmonic import excitation_phasor
from workbook.solve.method import FREQUENCY, TIME, MethodChoice
from workbook.solve.pipeline import four_pole, run_case
from workbook.solve.preload import check_equilibrium, geometry_roundoff_force, solve_preload

#: 1 N lateral shaking at 59 Hz on the engine's centre of gravity.
SMALL = HarmonicForce("small shake", point=ENGINE_CG, direction=(0.0, 1.0, 0.0), frequency_hz=59.0,
                      amplitude=1.0)


@pytest.fixture(scope="module")
def unloaded(cache_dir):
    case = reference_case(element_size=COARSE_ELEMENT_SIZE).with_rigid_links()
    return dataclasses.replace(case, static_loads=(), excitations=(SMALL,))


def test_round_off_pin_forces_lie_far_below_the_allowance(unloaded):
    """The pin forces of the unloaded reference mount (2e7 N/m hinges across
    marker offsets up to 1.6e-12 m) exceed the former limit of 1e-6 N but
    lie 100 times below the geometry's round-off allowance."""
    with build_scene(unloaded, SMALL) as scene:
        pins = pylon_sum(scene.hinge_forces(), scene.pylon_channels)
        allowance = geometry_roundoff_force(scene)
    assert 1e-6 < np.linalg.norm(pins) < allowance / 100
    assert allowance == pytest.approx(1e-10 * 2e7 * 1.72)
    assert check_equilibrium("unloaded", pins, np.zeros(3), 1e-6, 1.0, roundoff=allowance) > 1e-6


def test_a_load_nothing_carries_still_fails(unloaded):
    """0.1 N put on the engine behind the solver's back (no static solve runs
    without static loads): the pins carry none of it."""
    with build_scene(unloaded, SMALL) as scene:
        mbs = scene.mbs
        marker = mbs.AddMarker(exu.itemInterface.MarkerBodyPosition(bodyNumber=scene.engine.body,
                                                                    localPosition=[0.0, 0.0, 0.0]))
        mbs.AddLoad(exu.itemInterface.LoadForceVector(markerNumber=marker, loadVector=[0.0, 0.0, -0.1]))
        mbs.Assemble()
        with pytest.raises(EquilibriumError, match=r"relative mismatch 1.00e\+00 > 3.44e-02: .* round-off of 0.0034 N"):
            solve_preload(scene)


def test_a_small_excitation_runs_in_both_domains_and_they_agree(unloaded):
    """The 1 N excitation passes the check; time and frequency domains are
    independent computations of T (measured: within 0.2 %)."""
    timed = run_case(unloaded, method=MethodChoice(TIME, "test")).runs[0]
    linear = run_case(unloaded, method=MethodChoice(FREQUENCY, "test")).runs[0]
    assert timed.transmissibility[1] == pytest.approx(linear.transmissibility[1], rel=0.01)


def test_the_four_pole_set_of_the_unloaded_mount_gives_the_full_solve(unloaded):
    """The four-pole set of the unloaded mount forms (before: EquilibriumError)
    and on a rigid pylon gives run_case's frequency-domain T."""
    pole = four_pole(unloaded, [SMALL.frequency])
    transmissibility = pole.transmissibility(excitation_phasor(SMALL), SMALL.point)[0]
    linear = run_case(unloaded, method=MethodChoice(FREQUENCY, "test")).runs[0]
    np.testing.assert_allclose(transmissibility, linear.transmissibility, rtol=1e-9)
