"""Test-rig force transducers under the pylon pins: a closed form, "off is not built", the rigid limit.

The two-DOF chain: the rigid mass M of ``test_sdof`` on four hinges (k_h,
d_h), each pin on its own transducer (k_s, moving mass m_s, no damping). By
symmetry a force F at the centre of gravity moves the mass by x and every
transducer by y:

    M x'' + 4 d_h (x' - y') + 4 k_h (x - y) = F,
    4 m_s y'' + 4 d_h (y' - x') + 4 k_h (y - x) + 4 k_s y = 0,

and the rig measures the pylon force 4 k_s y. Harmonically, with
K_h = 4 (k_h + i w d_h), K_s = 4 k_s and m = 4 m_s,

    Y / X = K_h / (K_h + K_s - w^2 m),   X = F / (K_h - w^2 M - K_h Y / X),
    T = |K_s Y / F|.

Under gravity the transducers carry no weight of their own, so the mass
sinks by W / (4 k_h) + W / (4 k_s) and each transducer carries W / 4.
"""
import dataclasses
import math
import pickle

import exudyn as exu
import numpy as np
import pytest
from test_sdof import DAMPING, MASS, STIFFNESS, closed_form, sdof_case

from workbook.errors import CaseError
from workbook.model.case import AnalysisSettings, Effects, ForceTransducers, Gravity
from workbook.model.codec import from_json, to_json
from workbook.model.reference import reference_case
from workbook.scene.build import build_scene
from workbook.solve.pipeline import run_case
from workbook.solve.preload import solve_preload

SENSOR_STIFFNESS = 2 * STIFFNESS      # per transducer, N/m: the pin's compliance triples
SENSOR_MASS = 1.0                     # kg
RIG = ForceTransducers((SENSOR_STIFFNESS,) * 3, mass=SENSOR_MASS)
FREQUENCIES = (5.0, 15.0)             # Hz: below and above the chain's first resonance (8.2 Hz)


def chain_transmissibility(frequency_hz: float) -> float:
    """T of the two-DOF chain (module docstring)."""
    omega = 2 * math.pi * frequency_hz
    hinges = 4 * (STIFFNESS + 1j * omega * DAMPING)
    sensors = 4 * SENSOR_STIFFNESS
    ratio = hinges / (hinges + sensors - omega ** 2 * 4 * SENSOR_MASS)
    motion = 1.0 / (hinges - omega ** 2 * MASS - hinges * ratio)
    return abs(sensors * ratio * motion)


def rig_case(method: str, **changes):
    """The single-DOF case on the rig's transducers, run by *method*."""
    case = sdof_case([f / 10.0 for f in FREQUENCIES])
    return dataclasses.replace(case, test_rig=RIG, analysis=AnalysisSettings(steps_per_period=80, method=method),
                               **changes)


@pytest.fixture(scope="module")
def frequency_result():
    return run_case(rig_case("frequency"))


@pytest.mark.parametrize("method", ["time", "frequency"])
def test_two_dof_chain_matches_the_closed_form(method, frequency_result):
    result = frequency_result if method == "frequency" else run_case(rig_case("time"))
    for frequency in FREQUENCIES:
        run = result.run(f"r = {frequency / 10.0:g}")
        expected = chain_transmissibility(frequency)
        # the transducers change T by far more than the tolerance
        assert abs(expected / closed_form(frequency / 10.0) - 1) > 0.15
        rtol = 1e-6 if method == "frequency" else 0.005
        assert run.transmissibility[1:] == pytest.approx([expected, expected], rel=rtol)
        assert run.transmissibility[0] < 1e-6
        assert sorted(run.pylon_hinges) == [f"transducer hinge {i}" for i in range(4)]


def test_static_sag_adds_the_transducer_compliance():
    case = dataclasses.replace(rig_case("frequency"), static_loads=(Gravity(),))
    scene = build_scene(case)
    preload = solve_preload(scene)
    weight = MASS * 9.81
    sag = -scene.mbs.GetNodeOutput(scene.engine.node, exu.OutputVariableType.Displacement)[2]
    assert sag == pytest.approx(weight / (4 * STIFFNESS) + weight / (4 * SENSOR_STIFFNESS), rel=1e-6)
    np.testing.assert_allclose(preload.pylon_force, [0, 0, -weight], atol=1e-6 * weight)
    for name in scene.transducers:
        np.testing.assert_allclose(preload.hinge_forces[name], [0, 0, -weight / 4], atol=1e-6 * weight)


def _rig_entry(card) -> dict:
    return next(e for e in card.to_dict()["effects"] if e["name"] == "test-rig force-sensor compliance")


@pytest.mark.parametrize("case, reason", [
    (dataclasses.replace(rig_case("frequency"), effects=Effects(rig_sensors=False)), "switched off"),
    (dataclasses.replace(rig_case("frequency"), test_rig=None), "no transducers given")])
def test_what_is_off_is_not_built(case, reason, frequency_result):
    scene = build_scene(case)
    assert scene.transducers == {}
    assert scene.mbs.systemData.ODE2Size() == 6
    assert scene.pylon_channels == [f"hinge {i}" for i in range(4)]
    result = run_case(case)
    card = result.model_cards["r = 1.5"]
    assert not _rig_entry(card)["on"] and _rig_entry(card)["detail"].startswith(reason)
    assert card.total_dof == 6
    assert result.run("r = 1.5").transmissibility[2] == pytest.approx(closed_form(1.5), rel=1e-6)
    on = frequency_result.model_cards["r = 1.5"]
    assert _rig_entry(on)["on"] and _rig_entry(on)["detail"].startswith("4 transducers")
    assert on.total_dof == 6 + 4 * 3


def test_hinges_on_one_pin_share_one_transducer(frequency_result):
    """Hinge 0 split into two halves on the same pin: one transducer carries
    both, and the mount (hence T) is the same."""
    case = rig_case("frequency")
    half = dataclasses.replace(case.hinges[0], stiffness=STIFFNESS / 2, damping=DAMPING / 2)
    split = dataclasses.replace(case, hinges=(half, dataclasses.replace(half, name="hinge 0b")) + case.hinges[1:])
    scene = build_scene(split)
    assert scene.mbs.systemData.ODE2Size() == 6 + 4 * 3
    assert scene.transducers["transducer hinge 0 + hinge 0b"].hinges == ("hinge 0", "hinge 0b")
    run = run_case(split).run("r = 1.5")
    np.testing.assert_allclose(run.transmissibility, frequency_result.run("r = 1.5").transmissibility,
                               rtol=1e-8, atol=1e-12)


def test_very_stiff_transducers_reproduce_the_rigid_pylon_on_the_reference_mount():
    # the coarse link meshes of the other reference-mount tests (rigid links: mass properties only)
    reference = reference_case(element_size=0.03).with_rigid_links()
    reference = dataclasses.replace(reference, analysis=AnalysisSettings(method="frequency"))
    stiff = dataclasses.replace(reference, test_rig=ForceTransducers((1e12,) * 3))
    rigid_result, stiff_result = run_case(reference), run_case(stiff)
    for name in ("LP rotor", "HP rotor"):
        np.testing.assert_allclose(stiff_result.run(name).transmissibility,
                                   rigid_result.run(name).transmissibility, rtol=1e-3, err_msg=name)
    preload = stiff_result.preloads["LP rotor"]
    assert preload.solved
    assert preload.relative_mismatch < 1e-6
    np.testing.assert_allclose(preload.pylon_force, preload.applied_force,
                               atol=1e-6 * np.linalg.norm(preload.applied_force))
    # each transducer carries exactly the static force of its pin's hinges
    scene = build_scene(stiff)
    assert len(scene.transducers) == 6
    for name, items in scene.transducers.items():
        carried = sum(preload.hinge_forces[hinge] for hinge in items.hinges)
        np.testing.assert_allclose(preload.hinge_forces[name], carried,
                                   atol=1e-6 * np.linalg.norm(preload.applied_force))


def test_bad_transducers_name_the_field():
    with pytest.raises(CaseError, match=r"test-rig force transducers, field 'stiffness': found \(2.0, 0.0, 3.0\), "
                                        r"expected three numbers > 0"):
        ForceTransducers((2.0, 0.0, 3.0))
    with pytest.raises(CaseError, match="field 'mass'.*expected a number > 0"):
        ForceTransducers((1e8,) * 3, mass=0.0)
    with pytest.raises(CaseError, match="field 'damping'"):
        ForceTransducers((1e8,) * 3, damping=(0.0, -1.0, 0.0))
    with pytest.raises(CaseError, match="case, field 'test_rig'.*expected a ForceTransducers or None"):
        dataclasses.replace(sdof_case(()), test_rig=(1e8, 1e8, 1e8))


def test_an_item_named_like_a_transducer_is_refused_only_when_the_rig_is_built():
    case = reference_case()
    pin = case.pylon_pins()[0][1]
    clash = f"transducer {' + '.join(pin)}"
    link = case.links[0]
    renamed = tuple(dataclasses.replace(h, body_a=clash) if h.body_a == link.name else
                    dataclasses.replace(h, body_b=clash) if h.body_b == link.name else h for h in case.hinges)
    on_bench = dataclasses.replace(case, links=(dataclasses.replace(link, name=clash),) + case.links[1:],
                                   hinges=renamed)  # without the rig, the name is free
    with pytest.raises(CaseError, match=rf"link '{clash}', field 'name'.*not the test-rig transducer under the "
                                        rf"pylon pin of {pin[0]}"):
        dataclasses.replace(on_bench, test_rig=ForceTransducers((1e8,) * 3))


def test_transducers_survive_json_and_pickle():
    case = dataclasses.replace(rig_case("frequency"), test_rig=ForceTransducers((1e8, 2e8, 3e8), 0.5, (1.0, 2.0, 3.0)))
    assert from_json(to_json(case)) == case
    assert pickle.loads(pickle.dumps(case)) == case
