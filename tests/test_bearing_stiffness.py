"""Hinge stiffness, damping and loss factor per direction of a hinge frame.

Four hinges at (+-a, +-b, 0) about a rigid mass's centre of gravity, all
with the same frame, translate the mass without rotating it when forced at
its centre of gravity: the translational stiffness is 4 S with
S = R^T diag(k) R, R the frame's rows.
"""
import dataclasses
import math

import numpy as np
import pytest

from workbook.errors import CaseError
from workbook.model.case import ENGINE, PYLON, AnalysisSettings, Case, Engine, HarmonicForce, Hinge, PointForce, RotatingForce
from workbook.scene.build import build_scene
from workbook.scene.hinge_law_base import hinge_frame
from workbook.solve.harmonic import harmonic_model
from workbook.solve.pipeline import run_case
from workbook.solve.preload import solve_preload

MASS = 500.0                                    # kg
CG = (0.2, -0.1, 0.3)
STIFFNESS = (2.0e6, 5.0e6, 0.5e6)               # N/m: radial 1, radial 2, axial
#: A frame turned about all three axes (rows: radial 1, radial 2, axial).
FRAME = tuple(map(tuple, np.linalg.qr(np.array([[0.8, 0.3, -0.2], [0.1, 0.9, 0.4], [0.3, -0.2, 0.7]]))[0].T))


def mount(stiffness, damping=0.0, loss_factor=0.0, frame=None, **case_fields) -> Case:
    hinges = tuple(Hinge(f"hinge {i}", PYLON, ENGINE, (CG[0] + sx * 0.4, CG[1] + sy * 0.3, CG[2]), stiffness,
                         damping, loss_factor=loss_factor, frame=frame)
                   for i, (sx, sy) in enumerate([(1, 1), (1, -1), (-1, 1), (-1, -1)]))
    return Case("bearing", Engine(MASS, CG, ((20.0, 0, 0), (0, 30.0, 0), (0, 0, 40.0))), links=(), hinges=hinges,
                **case_fields)


def _frequency(case: Case) -> Case:
    return dataclasses.replace(case, analysis=AnalysisSettings(method="frequency"))


def test_equal_values_reproduce_the_isotropic_hinge():
    excitations = tuple(RotatingForce(f"f = {f:g}", point=(0.3, 0.0, 0.1), frequency_hz=f, amplitude=1000.0)
                        for f in (5.0, 12.0, 40.0))
    k, d, eta = 2.0e6, 800.0, 0.05
    isotropic = run_case(_frequency(mount(k, d, eta, excitations=excitations)))
    for frame in (None, FRAME):
        three = run_case(_frequency(mount((k, k, k), (d, d, d), (eta, eta, eta), frame, excitations=excitations)))
        for run in isotropic.runs:
            np.testing.assert_allclose(three.run(run.name).transmissibility, run.transmissibility, rtol=1e-9)


def test_rotated_frame_gives_the_rotated_stiffness():
    case = mount(STIFFNESS, frame=FRAME)
    with build_scene(case) as scene:
        model = harmonic_model(scene)
        translations = model.linearization.body_coordinates[ENGINE][:3]
        rows = model.stiffness_output[:3][:, translations]      # hinge 0's force per engine translation
    frame = np.array(FRAME)
    np.testing.assert_allclose(rows, frame.T @ np.diag(STIFFNESS) @ frame, rtol=1e-6, atol=1e-6 * max(STIFFNESS))


@pytest.mark.parametrize("direction", range(3))
def test_static_stiffness_per_direction(direction):
    """A static force along frame direction i moves the mass along it by F / (4 k_i)."""
    force = 1000.0 * np.array(FRAME[direction])
    case = mount(STIFFNESS, frame=FRAME, static_loads=(PointForce("push", tuple(force), CG),))
    import exudyn as exu

    with build_scene(case) as scene:
        solve_preload(scene)
        moved = np.array(scene.mbs.GetNodeOutput(scene.engine.node, exu.OutputVariableType.Displacement))
    np.testing.assert_allclose(moved, force / (4 * STIFFNESS[direction]), rtol=1e-6, atol=1e-12)


@pytest.mark.parametrize("direction", range(3))
def test_loss_factor_per_direction_against_the_single_dof_closed_form(direction):
    """Forced along frame direction i at r = 1.5: T = sqrt(1 + eta_i^2) / sqrt((1 - r^2)^2 + eta_i^2)."""
    loss = (0.02, 0.05, 0.1)
    natural = math.sqrt(4 * STIFFNESS[direction] / MASS) / (2 * math.pi)
    push = HarmonicForce("push", point=CG, direction=FRAME[direction], amplitude=1000.0, frequency_hz=1.5 * natural)
    run = run_case(_frequency(mount(STIFFNESS, loss_factor=loss, frame=FRAME, excitations=(push,)))).run()
    expected = math.sqrt((1 + loss[direction] ** 2) / ((1 - 1.5 ** 2) ** 2 + loss[direction] ** 2))
    # the pylon force is parallel to the push: its magnitude over the push's
    assert np.linalg.norm(run.pylon_amplitude) / push.amplitude == pytest.approx(expected, rel=1e-6)
    np.testing.assert_allclose(run.pylon_amplitude, expected * push.amplitude * np.abs(FRAME[direction]), rtol=1e-6)


def test_time_domain_builds_the_rotated_viscous_equivalent():
    """The anisotropic hinge in the time domain (symbolic law with the loss factors' viscous
    equivalent at the run's frequency) agrees with the exact frequency domain at that frequency."""
    loss = (0.02, 0.05, 0.1)
    push = RotatingForce("spin", point=CG, frequency_hz=14.0, amplitude=1000.0, axis=(1.0, 0.0, 0.0))
    case = mount(STIFFNESS, damping=(50.0, 80.0, 20.0), loss_factor=loss, frame=FRAME, excitations=(push,))
    exact = run_case(_frequency(case)).run()
    timed = run_case(dataclasses.replace(case, analysis=AnalysisSettings(method="time", steps_per_period=80))).run()
    np.testing.assert_allclose(timed.transmissibility[1:], exact.transmissibility[1:], rtol=0.005)


def test_default_frame_of_a_hinge_on_a_link_is_the_links(coarse_reference):
    hinge = next(h for h in coarse_reference.hinges if h.body_a not in (PYLON, ENGINE))
    link = coarse_reference.link_map[hinge.body_a]
    frame = hinge_frame(coarse_reference, hinge)
    axis = np.subtract(link.end_b, link.end_a) / link.length
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(frame[0], axis, atol=1e-12)
    if link.bore_axis is not None:
        assert abs(frame[2] @ np.asarray(link.bore_axis)) == pytest.approx(np.linalg.norm(
            np.asarray(link.bore_axis) - axis * (axis @ link.bore_axis)), rel=1e-9)


@pytest.mark.parametrize("fields, name", [
    ({"stiffness": (1e6, 2e6)}, "stiffness"),
    ({"stiffness": (1e6, 2e6, 3e6, 4e6)}, "stiffness"),
    ({"stiffness": 1e6, "damping": (1.0, 2.0)}, "damping"),
    ({"stiffness": 1e6, "loss_factor": (0.1, -0.1, 0.1)}, "loss_factor[radial 2]"),
    ({"stiffness": (1e6, 2e6, -3e6)}, "stiffness[axial]"),
    ({"stiffness": 1e6, "frame": ((1, 0, 0), (0, 1, 0), (0, 1, 1))}, "frame"),
    ({"stiffness": 1e6, "frame": ((2, 0, 0), (0, 1, 0), (0, 0, 1))}, "frame"),
    ({"stiffness": 1e6, "frame": ((1, 0, 0), (0, 1, 0))}, "frame"),
    ({"stiffness": (1e6, 2e6, 3e6), "radial_clearance": 1e-5}, "stiffness"),
])
def test_bad_per_direction_values_are_named(fields, name):
    with pytest.raises(CaseError) as error:
        Hinge("h", PYLON, ENGINE, (0, 0, 0), **fields)
    assert error.value.item == "hinge 'h'" and error.value.field == name


def test_four_pole_set_of_anisotropic_lossy_hinges_gives_the_rig_run():
    """The four-pole set of hinges with per-direction stiffness, damping and
    loss factor in a turned frame, with the test rig's transducers as the
    pylon impedance, gives the rig run's pylon force (the identity of
    tests/test_four_pole.py, now through the hinges' own 3x3 terminal terms)."""
    from workbook.model.case import ForceTransducers
    from workbook.solve.harmonic import excitation_phasor
    from workbook.solve.pipeline import four_pole

    rig = ForceTransducers(stiffness=(2e6, 3e6, 4e6), mass=2.5, damping=(50.0, 80.0, 20.0))
    frequencies = (4.0, 11.0, 30.0)
    excitations = tuple(RotatingForce(f"f = {f:g}", point=(0.3, 0.0, 0.1), frequency_hz=f, amplitude=1000.0)
                        for f in frequencies)
    case = mount(STIFFNESS, (50.0, 80.0, 20.0), (0.02, 0.05, 0.1), FRAME, excitations=excitations, test_rig=rig)
    pole = four_pole(case, frequencies)
    w = 2 * np.pi * np.array(frequencies)
    transducer = np.array(rig.stiffness) + 1j * w[:, None] * np.array(rig.damping)
    pylon = np.stack([np.diag(row) for row in transducer]) - (w ** 2 * rig.mass)[:, None, None] * np.eye(3)
    result = run_case(_frequency(case))
    for j, excitation in enumerate(excitations):
        response = pole.respond(excitation_phasor(excitation), excitation.point, pylon)[j]
        measured = np.abs((transducer[j] * response.pin_motions).sum(axis=0)) / excitation.force_amplitude
        np.testing.assert_allclose(measured, result.run(excitation.name).transmissibility, rtol=1e-6, atol=1e-12)


def test_per_direction_hinges_and_loss_factors_round_trip_through_json():
    from workbook.model.codec import from_json, to_json

    case = mount(STIFFNESS, (50.0, 80.0, 20.0), (0.02, 0.05, 0.1), FRAME)
    again = from_json(to_json(case))
    assert again == case
    assert again.hinges[0].frame == case.hinges[0].frame and not again.hinges[0].isotropic
