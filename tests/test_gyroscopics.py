"""The rotors' gyroscopic moment against closed forms, and the two domains against each other.

The whirl case: a rigid engine of mass m and inertia diag(I_x, I_t, I_t) about
its centre of gravity, held by six identical isotropic hinges of stiffness k
at (+-L, 0, 0), (0, +-R, 0) and (0, 0, +-R) from the centre of gravity. The
hinge points sum to zero, so translations and rotations decouple; pitch and
yaw share the stiffness k_t = k (2 L^2 + 2 R^2) and, without spin, the
frequency w0 = sqrt(k_t / I_t). A rotor of spin angular momentum h = Ip Omega
along +x exerts the moment h x omega; for small angles (theta_y, theta_z)

    I_t theta_y'' + h theta_z' + k_t theta_y = 0,
    I_t theta_z'' - h theta_y' + k_t theta_z = 0,

so u = theta_y + i theta_z obeys I_t u'' - i h u' + k_t u = 0. u = exp(i w t)
is the forward whirl (turning with the spin), u = exp(-i w t) the backward
whirl:

    w^2 -+ (h / I_t) w - w0^2 = 0,   w_f,b = (sqrt(h^2 + 4 I_t k_t) +- h) / (2 I_t),

with w_f w_b = w0^2. Roll (k 4 R^2 / I_x) and the translations (6 k / m) do
not feel the rotor.
"""
import dataclasses
import math
import pickle

import numpy as np
import pytest

from workbook.errors import CaseError
from workbook.model.case import ENGINE, PYLON, AnalysisSettings, Case, Effects, Engine, Hinge, RotatingForce, Rotor
from workbook.model.codec import from_json, to_json
from workbook.scene.build import build_scene
from workbook.solve.modes import linearize, modes_of, mounted_modes
from workbook.solve.pipeline import run_case
from workbook.solve.preload import solve_preload

MASS, ROLL_INERTIA, TRANSVERSE_INERTIA = 1000.0, 200.0, 1000.0    # kg, kg m^2
STIFFNESS, LENGTH, RADIUS = 1.0e6, 1.0, 0.5                        # N/m per hinge, m
ROTOR = Rotor("rotor", polar_inertia=20.0, frequency_hz=100.0)     # h = 12566 kg m^2/s
CG = (0.3, -0.2, 0.1)


def whirl_case(*, hinge_centre=CG, damping=0.0, excitations=(), rotors=(ROTOR,), effects=Effects()) -> Case:
    """The whirl case; a *hinge_centre* apart from the centre of gravity couples the
    rotations into the pylon force."""
    offsets = [(LENGTH, 0, 0), (-LENGTH, 0, 0), (0, RADIUS, 0), (0, -RADIUS, 0), (0, 0, RADIUS), (0, 0, -RADIUS)]
    hinges = tuple(Hinge(f"hinge {i}", PYLON, ENGINE, tuple(np.add(hinge_centre, p)), STIFFNESS, damping)
                   for i, p in enumerate(offsets))
    inertia = np.diag([ROLL_INERTIA, TRANSVERSE_INERTIA, TRANSVERSE_INERTIA])
    return Case("whirl", Engine(MASS, CG, tuple(map(tuple, inertia))), (), hinges, excitations=excitations,
                rotors=rotors, effects=effects,
                analysis=AnalysisSettings(steps_per_period=80, settle_time_constants=3.0))


def mounted(case: Case):
    scene = build_scene(case, reduced={})
    solve_preload(scene)
    return scene, mounted_modes(modes_of(linearize(scene)))


def test_mounted_modes_split_into_forward_and_backward_whirl():
    scene, modes = mounted(whirl_case())
    tilt_stiffness = STIFFNESS * (2 * LENGTH ** 2 + 2 * RADIUS ** 2)
    h = ROTOR.polar_inertia * 2 * math.pi * ROTOR.frequency
    root = math.sqrt(h ** 2 + 4 * TRANSVERSE_INERTIA * tilt_stiffness)
    backward, forward = ((root + sign * h) / (2 * TRANSVERSE_INERTIA) / (2 * math.pi) for sign in (-1, 1))
    whirl = sorted(m.frequency_hz for m in modes if abs(m.engine_shape[4]) > 0.99 and abs(m.engine_shape[5]) > 0.99)
    np.testing.assert_allclose(whirl, [backward, forward], rtol=1e-6)
    # the split is real: 7.02 and 9.02 Hz about w0 = 7.96 Hz
    assert forward * backward == pytest.approx(tilt_stiffness / TRANSVERSE_INERTIA / (2 * math.pi) ** 2, rel=1e-6)
    assert forward / backward > 1.25
    others = sorted(m.frequency_hz for m in modes if m.frequency_hz not in whirl)
    roll = math.sqrt(4 * STIFFNESS * RADIUS ** 2 / ROLL_INERTIA) / (2 * math.pi)
    translation = math.sqrt(6 * STIFFNESS / MASS) / (2 * math.pi)
    np.testing.assert_allclose(others, [roll] + [translation] * 3, rtol=1e-6)
    assert scene.gyroscopics.rotors == ("rotor",)


@pytest.mark.parametrize("spin", [0.0, 300.0])
def test_eigenpairs_are_those_of_scipys_generalised_problem(spin):
    """The eigenpairs (whitened by the Cholesky factor of M) against SciPy's QZ of the pencil as
    given, and each pair's residual: ``(lambda^2 M + lambda G + K) x = 0`` with ``lambda = i w``.
    The masses span 1e-3 to 1e3 as a link's modal and a heavy engine's coordinates do; without spin
    K has an unsymmetric part, as the preload's geometric stiffness gives it (with spin it is kept
    symmetric, so that every ``lambda`` is imaginary)."""
    import scipy.linalg as sla

    from workbook.solve.modes import Linearization, eigenpairs

    generator = np.random.default_rng(7)
    size = 12
    shape = generator.normal(size=(size, size))
    scale = np.diag(np.logspace(-1.5, 1.5, size))
    mass = scale @ (shape @ shape.T + size * np.eye(size)) @ scale
    shape = generator.normal(size=(size, size))
    stiffness = 1e4 * (shape @ shape.T + size * np.eye(size)) + (spin == 0) * 10.0 * generator.normal(size=(size, size))
    gyroscopic = spin * np.triu(generator.normal(size=(size, size)), 1)
    gyroscopic = gyroscopic - gyroscopic.T
    lin = Linearization(mass, stiffness, gyroscopic, np.eye(size), mass, {}, gyroscopic if spin else None)
    squared, vectors = eigenpairs(lin)
    if spin:
        first_order = sla.eig(np.block([[np.zeros((size, size)), np.eye(size)], [-stiffness, -gyroscopic]]),
                              sla.block_diag(np.eye(size), mass), right=False)
        expected = np.sort(-(first_order[first_order.imag > 0] ** 2).real)
    else:
        expected = np.sort(sla.eig(stiffness, mass, right=False).real)
    np.testing.assert_allclose(squared, expected, rtol=1e-9)
    lam = 1j * np.sqrt(squared)
    residual = (lam ** 2 * (mass @ vectors) + lam * (gyroscopic @ vectors) + stiffness @ vectors)
    scale = np.abs(lam) ** 2 * np.linalg.norm(mass, 2) * np.linalg.norm(vectors, axis=0)
    assert np.all(np.linalg.norm(residual, axis=0) < 1e-10 * scale)


def test_a_motion_without_mass_is_named_not_solved():
    """A linearised M that is not positive definite (a coordinate without mass) is numerical trouble
    said in words, not a crash of the Cholesky factor or modes of noise."""
    from workbook.errors import SimulationError
    from workbook.solve.modes import Linearization, eigenpairs

    mass = np.diag([2.0, 1.0, 0.0])
    stiffness = np.diag([1e4, 2e4, 3e4])
    lin = Linearization(mass, stiffness, np.zeros((3, 3)), np.eye(3), mass, {}, None)
    with pytest.raises(SimulationError, match="motion without mass"):
        eigenpairs(lin)


def test_moment_is_exact_for_a_large_rotation():
    """M = -Ip Omega (omega x a), with a turned with the engine, as generalised
    force G^T M on the Tait-Bryan angles; omega, G and the rotation from Exudyn's node."""
    import exudyn as exu

    scene = build_scene(whirl_case(), reduced={})
    mbs, node, data = scene.mbs, scene.engine.node, scene.mbs.systemData
    first = mbs.GetNodeODE2Index(node)
    current = exu.ConfigurationType.Current
    angles, rates = np.array([0.3, -0.5, 0.8]), np.array([1.0, 2.0, -3.0])      # rad, rad/s
    coordinates = np.zeros(data.ODE2Size())
    coordinates[first + 3:first + 6] = angles
    data.SetODE2Coordinates(list(coordinates), configuration=current)

    def angular_velocity(angle_rates):
        velocities = np.zeros(data.ODE2Size())
        velocities[first + 3:first + 6] = angle_rates
        data.SetODE2Coordinates_t(list(velocities), configuration=current)
        return np.array(mbs.GetNodeOutput(node, exu.OutputVariableType.AngularVelocity))

    rate_matrix = np.column_stack([angular_velocity(unit) for unit in np.eye(3)])
    omega = angular_velocity(rates)
    rotation = np.array(mbs.GetNodeOutput(node, exu.OutputVariableType.RotationMatrix)).reshape(3, 3)
    moment = -ROTOR.polar_inertia * 2 * math.pi * ROTOR.frequency * np.cross(omega, rotation @ ROTOR.axis)
    force = scene.gyroscopics.function.Evaluate(mbs, 0.0, int(scene.gyroscopics.object),
                                                [0, 0, 0, *angles], [0, 0, 0, *rates])
    np.testing.assert_allclose(force, np.r_[0, 0, 0, rate_matrix.T @ moment], rtol=1e-12, atol=1e-9)
    # the rotation matters here: the moment with the axis left in place differs
    fixed_axis = -np.cross(omega, ROTOR.angular_momentum)
    assert np.linalg.norm(moment - fixed_axis) > 0.1 * np.linalg.norm(moment)


def test_time_domain_matches_frequency_domain_with_the_rotor():
    """A forward rotating force at the nose, between the whirl frequencies; the
    hinges' centre 0.3 m aft of the centre of gravity lets the tilt reach the pylon force."""
    force = RotatingForce("nose", point=tuple(np.add(CG, (1.0, 0, 0))), frequency_hz=8.0, amplitude=1000.0)
    case = whirl_case(hinge_centre=np.add(CG, (-0.3, 0, 0)), damping=2000.0, excitations=(force,))
    answers = {}
    for gyroscopics in (True, False):
        for method in ("time", "frequency"):
            variant = dataclasses.replace(case, effects=Effects(gyroscopics=gyroscopics),
                                          analysis=dataclasses.replace(case.analysis, method=method))
            answers[gyroscopics, method] = run_case(variant).run("nose")
    td, fd = answers[True, "time"], answers[True, "frequency"]
    assert td.steady
    np.testing.assert_allclose(fd.transmissibility[1:], td.transmissibility[1:], rtol=0.01)
    np.testing.assert_allclose(fd.hinge_amplitudes["hinge 0"][1:], td.hinge_amplitudes["hinge 0"][1:], rtol=0.01)
    # ... and the rotor changes the answer
    without = answers[False, "frequency"].transmissibility[1:]
    assert np.all(np.abs(fd.transmissibility[1:] / without - 1) > 0.05)


@pytest.mark.parametrize("rotors, effects, reason", [
    ((), Effects(), "no rotors given: rotor inertia lumped in the engine"),
    ((ROTOR,), Effects(gyroscopics=False), "switched off: rotor inertia lumped in the engine"),
])
def test_nothing_is_built_without_rotors_or_when_switched_off(rotors, effects, reason):
    force = RotatingForce("nose", point=tuple(np.add(CG, (1.0, 0, 0))), frequency_hz=8.0, amplitude=1000.0)
    case = whirl_case(rotors=rotors, effects=effects, excitations=(force,))
    scene, modes = mounted(case)
    assert scene.gyroscopics is None
    assert linearize(scene).gyroscopic is None
    assert {scene.mbs.GetObject(i)["objectType"] for i in range(scene.mbs.systemData.NumberOfObjects())} \
        == {"Ground", "RigidBody", "ConnectorCartesianSpringDamper"}
    # pitch and yaw stay together at w0
    w0 = math.sqrt(STIFFNESS * (2 * LENGTH ** 2 + 2 * RADIUS ** 2) / TRANSVERSE_INERTIA) / (2 * math.pi)
    assert sum(m.frequency_hz == pytest.approx(w0, rel=1e-6) for m in modes) == 2
    frequency = dataclasses.replace(case, analysis=AnalysisSettings(method="frequency"))
    effects = {e.name: e for e in run_case(frequency).model_cards["nose"].effects}
    assert not effects["gyroscopic rotor"].on
    assert effects["gyroscopic rotor"].detail == reason


def test_card_names_the_rotors():
    force = RotatingForce("nose", point=CG, frequency_hz=8.0, amplitude=1000.0)
    case = whirl_case(excitations=(force,), rotors=(ROTOR, Rotor("slow", 5.0, rpm=3000.0, axis=(2, 0, 0))))
    card = run_case(dataclasses.replace(case, analysis=AnalysisSettings(method="frequency"))).model_cards["nose"]
    entry = next(e for e in card.effects if e.name == "gyroscopic rotor")
    assert entry.on
    assert entry.detail.startswith("rotor Ip = 20 kg m^2 at 100 Hz, slow Ip = 5 kg m^2 at 50 Hz")


def test_rotor_input_is_checked():
    assert Rotor("r", 1.0, rpm=600.0, axis=(0, 0, -3)).axis == (0.0, 0.0, -1.0)
    with pytest.raises(CaseError, match="rotor 'r', field 'frequency_hz'.*either frequency_hz or rpm"):
        Rotor("r", 1.0, frequency_hz=10.0, rpm=600.0)
    with pytest.raises(CaseError, match="rotor 'r', field 'polar_inertia': found -1.0, expected a number > 0"):
        Rotor("r", -1.0, frequency_hz=10.0)
    with pytest.raises(CaseError, match="rotor 'r', field 'axis'.*non-zero direction"):
        Rotor("r", 1.0, frequency_hz=10.0, axis=(0, 0, 0))
    with pytest.raises(CaseError, match="rotor 'rotor', field 'name'.*not used before"):
        whirl_case(rotors=(ROTOR, ROTOR))
    with pytest.raises(CaseError, match="case, field 'rotors'.*expected Rotor"):
        whirl_case(rotors=("LP",))


def test_rotors_survive_json_and_pickle():
    case = whirl_case()
    assert from_json(to_json(case)) == case
    assert pickle.loads(pickle.dumps(case)) == case
