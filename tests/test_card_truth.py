"""The model card is the whole truth and nothing is built that cannot
change the answer: the links' spin restraints are listed with the mode each
adds (found among the linearised modes), rotors whose spin momenta cancel
build no gyroscopic object (and the answer is the rotor-free one), and a
contact stiffness without a gap, or rigid links excited above the
low-frequency limit, are warned. Real Exudyn runs, rigid links."""
import dataclasses

import numpy as np
import pytest

from workbook.model.case import Rotor
from workbook.model.reference import HP_ROTOR, LP_ROTOR
from workbook.solve.pipeline import prepare, run_case


def _run_frequency(case):
    """*case* answered in the frequency domain."""
    return run_case(dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method="frequency")))


@pytest.fixture(scope="module")
def rigid(coarse_reference):
    return dataclasses.replace(coarse_reference.with_rigid_links(), excitations=(LP_ROTOR,))


def _entry(card, name):
    return next(e for e in card.effects if e.name == name)


@pytest.mark.slow
def test_the_spin_restraints_are_on_the_card_with_the_modes_they_add(rigid):
    result = _run_frequency(rigid)
    entry = _entry(result.model_cards[LP_ROTOR.name], "link spin restraints")
    assert entry.on and entry.detail.startswith("8 torsional springs") and "2000 Hz" in entry.detail
    # the restraint k = J_spin (2 pi 2000 Hz)^2 adds one mode per link at 2000 Hz (spin of a link alone)
    modes = prepare(rigid, LP_ROTOR).modes
    spin = [m for m in modes if abs(m.frequency_hz / 2000.0 - 1) < 0.01]
    assert len(spin) == len(rigid.links)
    assert all(m.engine_share < 1e-6 for m in spin)


def test_counter_rotating_rotors_of_equal_momentum_build_nothing(rigid):
    pair = (Rotor("forward", polar_inertia=50.0, frequency_hz=100.0),
            Rotor("backward", polar_inertia=50.0, frequency_hz=100.0, axis=(-1.0, 0.0, 0.0)))
    effects = dataclasses.replace(rigid.effects, gyroscopics=True)
    cancelled = _run_frequency(dataclasses.replace(rigid, rotors=pair, effects=effects))
    alone = _run_frequency(dataclasses.replace(rigid, rotors=pair[:1], effects=effects))
    none = _run_frequency(rigid)
    entry = _entry(cancelled.model_cards[LP_ROTOR.name], "gyroscopic rotor")
    assert not entry.on and "cancel" in entry.detail
    assert any("momenta cancel" in w for w in cancelled.runs[0].warnings)
    np.testing.assert_array_equal(cancelled.runs[0].transmissibility, none.runs[0].transmissibility)
    # one rotor alone does change the answer
    assert not np.allclose(alone.runs[0].transmissibility, none.runs[0].transmissibility, rtol=1e-6)


def test_a_contact_stiffness_without_a_gap_is_warned_and_does_not_act(rigid):
    hinges = (dataclasses.replace(rigid.hinges[0], contact_stiffness=1e11),) + rigid.hinges[1:]
    given = _run_frequency(dataclasses.replace(rigid, hinges=hinges))
    plain = _run_frequency(rigid)
    name = rigid.hinges[0].name
    assert any(w.startswith(f"hinge {name!r}: contact_stiffness 1e+11 N/m is ignored") for w in given.runs[0].warnings)
    assert f"contact_stiffness ignored on {name}" in _entry(given.model_cards[LP_ROTOR.name], "hinge clearance").detail
    np.testing.assert_array_equal(given.runs[0].transmissibility, plain.runs[0].transmissibility)


def test_rigid_links_above_the_low_frequency_limit_are_warned(rigid):
    """At 248.5 Hz the thrust rods (mounted fundamental about 100 Hz) are
    excited far above it; at 5 Hz no link is."""
    high = _run_frequency(dataclasses.replace(rigid, excitations=(HP_ROTOR,))).runs[0]
    warned = {w.split("'")[1] for w in high.warnings if "is rigid although" in w}
    assert {"thrust-left", "thrust-right"} <= warned
    low = _run_frequency(dataclasses.replace(rigid, excitations=(
        dataclasses.replace(LP_ROTOR, frequency_hz=5.0),))).runs[0]
    assert not any("is rigid although" in w for w in low.warnings)
