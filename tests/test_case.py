"""The case model: validation messages, serialisation, excitation laws."""
import dataclasses
import math
import pickle

import numpy as np
import pytest

from workbook.errors import CaseError
from workbook.model.case import ENGINE, PYLON, Engine, HarmonicForce, Hinge, Link, RotatingForce, Sweep
from workbook.model.codec import from_json, to_json
from workbook.model.reference import reference_case
from workbook.scene.excitation import ExcitationSignal


@pytest.fixture(scope="module")
def reference():
    return reference_case(sweep=True)


def test_reference_mount_topology(reference):
    assert len(reference.links) == 8
    assert len(reference.hinges) == 16
    pins = {tuple(np.round(h.position, 9)) for h in reference.hinges}
    assert len(pins) == 14
    link_to_link = [h for h in reference.hinges if ENGINE not in h.bodies and PYLON not in h.bodies]
    assert {h.name for h in link_to_link} == {"thrust-aft-left", "thrust-aft-right"}
    assert {h.name for h in reference.hinges if h.name.startswith("front")} == {
        "front-up-left", "front-up-right", "front-down-left", "front-down-right"}
    assert reference.engine.mass * 9.81 == pytest.approx(35_000, rel=1e-3)


def test_case_survives_json_and_pickle(reference):
    assert from_json(to_json(reference)) == reference
    assert pickle.loads(pickle.dumps(reference)) == reference


def test_unknown_item_type_is_refused(reference):
    text = to_json(reference).replace('"type": "Gravity"', '"type": "os.system"')
    with pytest.raises(ValueError, match="unknown item type 'os.system'"):
        from_json(text)


def test_hinge_off_the_link_eye_names_the_field(reference):
    hinge = dataclasses.replace(reference.hinges[0], position=(0.0, -0.22, 0.86))
    with pytest.raises(CaseError, match="hinge 'front-up-left', field 'position'") as error:
        dataclasses.replace(reference, hinges=(hinge,) + reference.hinges[1:])
    assert error.value.field == "position"


def test_invalid_values_name_item_field_value_and_expectation():
    with pytest.raises(CaseError, match=r"hinge 'h', field 'stiffness': found -1.0, expected a number > 0"):
        Hinge("h", PYLON, ENGINE, (0, 0, 0), stiffness=-1.0)
    with pytest.raises(CaseError, match="either amplitude or unbalance"):
        RotatingForce("r", (0, 0, 0), frequency_hz=59.0, amplitude=1.0, unbalance=1e-3)
    with pytest.raises(CaseError, match="frequency_hz"):
        HarmonicForce("h", (0, 0, 0), (0, 0, 1), amplitude=1.0)
    with pytest.raises(CaseError, match="engine, field 'inertia'"):
        Engine(100.0, (0, 0, 0), ((1, 0, 0), (0, 1, 0), (0, 0, 5)))
    with pytest.raises(CaseError, match="link 'l', field 'end_b'"):
        Link("l", (0, 0, 0), (0, 0, 0), model=None)


def test_unbalance_and_rpm_give_the_centrifugal_force():
    rotor = RotatingForce("LP", (0.35, 0, 0), rpm=3540.0, unbalance=0.01)
    omega = 2 * math.pi * 59.0
    assert rotor.frequency == pytest.approx(59.0)
    assert rotor.force_amplitude == pytest.approx(0.01 * omega ** 2)


def test_rotating_force_turns_from_lateral_to_vertical():
    signal = ExcitationSignal.of(RotatingForce("r", (0, 0, 0), frequency_hz=10.0, amplitude=1000.0), 0.0)
    # 10 Hz: a whole period, then a quarter and a half more; right-handed about +x
    force = signal.force(np.array([0.1, 0.125, 0.15]))
    np.testing.assert_allclose(force, [[0, 1000, 0], [0, 0, 1000], [0, -1000, 0]], atol=1e-9)
    assert np.allclose(np.linalg.norm(signal.force(np.linspace(0.01, 0.2, 50)), axis=1), 1000.0)


def test_smooth_start_rises_from_zero(reference):
    signal = ExcitationSignal.of(reference.excitations[0], ramp_periods=10)
    t = np.linspace(-0.1, 0.5, 2001)
    ramp = signal.ramp(t)
    assert ramp[t <= 0].max() == 0.0 and ramp[t >= signal.ramp_time].min() == 1.0
    assert np.all(np.diff(ramp) >= 0)


def test_sweep_expands_into_single_frequency_runs(reference):
    sweep = next(e for e in reference.excitations if isinstance(e, Sweep))
    runs = sweep.expand()
    assert len(runs) == len(sweep.frequencies_hz) == 25
    assert runs[0].frequency == pytest.approx(5.0) and runs[-1].frequency == pytest.approx(300.0)
    assert len(reference.single_frequency_excitations()) == 2 + 25
