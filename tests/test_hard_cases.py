"""The catalogue of hard scenes (docs/hard-cases.md): each ends in finite
numbers that pass a physical check, or in a plain-words error.

Most scenes use the reference mount with rigid links: the hardness lies in
the hinges, the damping, the clearance or the excitation, and rigid links
keep each run to about a second. Where the links themselves are the subject
(the forced low-frequency approximation, a small excitation on the large
preload), they are flexible.
"""
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import skfem
from conftest import COARSE_ELEMENT_SIZE

from flexbodies.assembly import assemble
from flexbodies.eigen import natural_frequencies
from flexbodies.materials import Material
from flexbodies.meshing import BodyMesh
from workbook.errors import FourPoleError, MechanismError, RecordError, ResonanceError, RoundOffError, SimulationError, UsageError
from workbook.model.case import HarmonicForce, Rotor, Sweep
from workbook.model.reference import HINGE_DAMPING_TIME, HP_ROTOR, LP_ROTOR, reference_case
from workbook.rig.correlation import measure
from workbook.rig.records import read_record
from workbook.rig.updating import update_to_transmissibility
from workbook.solve.campbell import campbell
from workbook.solve.guards import singular_solve_guard
from workbook.solve.harmonic import excitation_phasor
from workbook.solve.method import TIME, MethodChoice, choose_method
from workbook.solve.modes import FREE_FREQUENCY_HZ, modes_of, mounted_modes
from workbook.solve.pipeline import four_pole, prepare, run_case, run_excitation, solve_frequencies


@pytest.fixture(scope="module")
def rigid(cache_dir):
    return reference_case(element_size=COARSE_ELEMENT_SIZE).with_rigid_links()


def _with(case, **analysis):
    return dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, **analysis))


def _hinges(case, **changes):
    return dataclasses.replace(case, hinges=tuple(dataclasses.replace(h, **changes) for h in case.hinges))


def _time(case, excitation=LP_ROTOR):
    return run_excitation(case, excitation)


def _frequency(case, excitation=LP_ROTOR):
    return run_case(_with(dataclasses.replace(case, excitations=(excitation,)), method="frequency")).runs[0]


# --- 1. very stiff hinges ---------------------------------------------------------------------------


def test_hinge_stiffness_1e10_converges_and_matches_the_frequency_domain(rigid):
    """k = 1e10 N/m puts the mounted modes at 105-577 Hz and local hinge
    modes far above the step's resolution; generalized-alpha damps those."""
    stiff = _hinges(rigid, stiffness=1e10, damping=HINGE_DAMPING_TIME * 1e10)
    coarse, fine = _time(stiff), _time(_with(stiff, steps_per_period=80))
    linear = _frequency(stiff)
    assert np.all(np.isfinite(coarse.transmissibility)) and coarse.steady
    assert fine.transmissibility == pytest.approx(coarse.transmissibility, rel=5e-3)
    assert fine.transmissibility == pytest.approx(linear.transmissibility, rel=5e-3)


REFERENCE_RECORD = Path(__file__).parents[1] / "cases" / "reference-lp-rig.csv"


def _one_hinge(case, stiffness):
    return dataclasses.replace(case, hinges=(dataclasses.replace(case.hinges[0], stiffness=stiffness),
                                             *case.hinges[1:]))


def test_one_hinge_far_stiffer_than_the_rest_is_refused_where_round_off_swamps_the_answer(rigid):
    """One hinge of 1e16 N/m beside 2e7: its force, known only to 3.8 N at
    these coordinates, enters the central differences of the linearisation
    over steps of 1e-7 and 1e-6; T was 0.028 instead of 0.055 (z, 59 Hz), at
    1e18 N/m 1.4 instead of 0.055, without a word. Up to 1e14 the answer
    agrees with 1e12 (an effectively rigid hinge) to 1 % (measured 0.6 %)."""
    rigidly = _frequency(_one_hinge(rigid, 1e12))
    stiff = _frequency(_one_hinge(rigid, 1e14))
    assert stiff.transmissibility == pytest.approx(rigidly.transmissibility, rel=0.01)
    with pytest.raises(RoundOffError, match=r"1e\+16 N/m.*round-off on forces whose largest pylon amplitude"):
        _frequency(_one_hinge(rigid, 1e16))
    # the four-pole set, condensed from the same linearisation, likewise (1e16 N/m: T_z 0.028 before)
    force = excitation_phasor(LP_ROTOR)
    poles = four_pole(_one_hinge(rigid, 1e14), [59.0]).transmissibility(force, LP_ROTOR.point)[0]
    assert poles == pytest.approx(stiff.transmissibility, rel=1e-6)
    with pytest.raises(RoundOffError, match=r"1e\+16 N/m"):
        four_pole(_one_hinge(rigid, 1e16), [59.0]).transmissibility(force, LP_ROTOR.point)


# --- 2. no damping ----------------------------------------------------------------------------------


def test_undamped_mount_at_a_mounted_resonance_stops_in_both_domains(rigid):
    undamped = dataclasses.replace(rigid, effects=dataclasses.replace(rigid.effects, hinge_damping=False))
    modes = mounted_modes(prepare(undamped, LP_ROTOR).modes)
    on_mode = dataclasses.replace(LP_ROTOR, frequency_hz=modes[1].frequency_hz)
    with pytest.raises(ResonanceError, match="undamped mounted mode .* grows without bound"):
        _frequency(undamped, on_mode)
    with pytest.raises(ResonanceError, match="never decays"):
        _time(undamped, on_mode)


def test_the_four_pole_set_of_an_undamped_mount_refuses_its_rigid_pylon_answer_on_a_mounted_mode(rigid):
    """Loss factor 0: on the 4.72 Hz mounted mode the engine on its mount on a rigid pylon has no steady
    state (before: T_y = 3.3e11 from a matrix singular but for round-off); at 59 Hz the set's T is the
    full solve's."""
    undamped = _hinges(rigid, loss_factor=0.0)
    modes = mounted_modes(prepare(undamped, LP_ROTOR).modes)
    poles = four_pole(undamped, [modes[0].frequency_hz, 59.0])
    force = excitation_phasor(LP_ROTOR)
    with pytest.raises(FourPoleError, match=r"singular at 4.72\d* Hz: the engine on its mount on a rigid pylon .*"
                                            r"the mode at 4.72\d* Hz \(engine roll"):
        poles.transmissibility(force, LP_ROTOR.point)
    off = four_pole(undamped, [59.0]).transmissibility(force, LP_ROTOR.point)[0]
    assert off == pytest.approx(_frequency(undamped).transmissibility, rel=1e-6)


def test_undamped_mount_off_resonance_warns_and_agrees_with_the_frequency_domain(rigid):
    undamped = dataclasses.replace(rigid, effects=dataclasses.replace(rigid.effects, hinge_damping=False))
    result, linear = _time(undamped), _frequency(undamped)
    assert any("undamped mounted modes" in w for w in result.warnings)
    # the free vibration left by the ramp leaks little into the 59 Hz bin
    # (measured: x 0.4 %, z 0.2 %; the nearly cancelled lateral force is 3 % off)
    assert result.transmissibility[[0, 2]] == pytest.approx(linear.transmissibility[[0, 2]], rel=0.01)


def test_a_time_domain_sweep_warns_where_its_grid_steps_over_a_mounted_mode(rigid):
    """3 points from 3 to 30 Hz step over all six mounted modes (4.7 to 25.8 Hz): the frequency domain
    warned, the time domain (a clearance scene, or asked for) said nothing. Now both warn alike."""
    sweep = Sweep.band("coarse", LP_ROTOR, 3.0, 30.0, 3)
    swept = dataclasses.replace(rigid, excitations=(sweep,))
    timed = run_case(swept, method=MethodChoice(TIME, "asked for")).runs
    linear = run_case(swept).runs
    # the same answers (measured: within 3 %, the integrator's period error next to the modes)
    assert np.array([r.transmissibility for r in timed]) == pytest.approx(
        np.array([r.transmissibility for r in linear]), rel=0.05)
    grid = [[w for w in run.warnings if "the grid steps over the peak" in w] for run in timed]
    assert grid == [[w for w in run.warnings if "the grid steps over the peak" in w] for run in linear]
    assert sum(len(warned) for warned in grid) == 6


# --- 3. clearance, closed by the preload; impacting without it ------------------------------------------


def test_clearance_closed_by_the_preload_agrees_with_the_linear_answer(rigid):
    """30 um gaps, the bearing's stiffness once closed, 100 N: the preload
    keeps every gap closed, so the scene stays on its linearisation.

    (With a contact 10x stiffer the mounted modes move next to 59 Hz, where
    the integrator's period error at 40 steps per period puts T 1.6 % off
    the linear answer, with or without clearance.)"""
    gapped = _hinges(rigid, radial_clearance=30e-6)
    small = dataclasses.replace(LP_ROTOR, amplitude=100.0)
    result, linear = _time(gapped, small), _frequency(gapped, small)
    # rigid links at 59 Hz are warned (the thrust rods' fundamental is 100 Hz); no gap is
    assert result.steady and all("is rigid although" in w for w in linear.warnings)
    # measured 0.42 %: the integrator's period error at 40 steps per period, as without clearance
    assert result.transmissibility == pytest.approx(linear.transmissibility, rel=0.01)


SHAKE = HarmonicForce("vertical shake", point=(-0.55, 0.0, -0.03), direction=(0, 0, 1), amplitude=60_000.0,
                      frequency_hz=59.0)


@pytest.mark.slow
def test_rattling_in_every_hinge_without_preload_is_periodic_and_bounded(rigid):
    """20 um gaps on all 16 hinges, no preload, 60 kN at 59 Hz: the engine
    (free inside the gaps) moves about 0.12 mm and impacts on every cycle.

    Inside the open gaps the mounted modes rest on the residual stiffness
    alone (0.05 Hz, damped only by its loss factor: a planned settle of
    340 s); the impacts settle the motion, within 2 s (measured: the two
    windows agree to 1e-3)."""
    rattling = _with(dataclasses.replace(_hinges(rigid, radial_clearance=20e-6, contact_stiffness=2e8),
                                         effects=dataclasses.replace(rigid.effects, preload=False)),
                     settle_time=2.0)
    coarse, fine = _time(rattling, SHAKE), _time(_with(rattling, steps_per_period=80), SHAKE)
    assert coarse.steady and fine.steady
    # the impacts make the pylon force large (free mass: T would be ~0.001)
    assert coarse.transmissibility[2] > 0.1
    # bounded: no pylon-force peak above twice the shaking force
    assert np.abs(coarse.pylon_history).max() < 2 * SHAKE.amplitude
    # step halving, measured: x 0.3 %, z 3 %
    assert fine.transmissibility[[0, 2]] == pytest.approx(coarse.transmissibility[[0, 2]], rel=0.05)
    # the frequency domain, frozen at open gaps, says it cannot answer this
    linear = _frequency(rattling, SHAKE)
    assert sum("open at the preload" in w for w in linear.warnings) == len(rattling.hinges)


# --- 4. a small excitation on the large preload ---------------------------------------------------------


def test_one_newton_on_the_58_kN_preload_gives_the_same_transmissibility(coarse_reference):
    """The answer of a linear(ised) mount does not depend on the amplitude;
    1 N is 2e-5 of the static loads (flexible links, nonlinear FFRF)."""
    case = coarse_reference
    one = _time(case, dataclasses.replace(LP_ROTOR, amplitude=1.0))
    full = _time(case, LP_ROTOR)
    assert one.steady and one.transmissibility == pytest.approx(full.transmissibility, rel=1e-3)


# --- 5. the low-frequency approximation forced where it does not hold ----------------------------------


@pytest.mark.slow
def test_forcing_static_modes_near_a_thrust_rod_fundamental_warns_and_auto_keeps_modes(cache_dir):
    case = reference_case()
    near = dataclasses.replace(LP_ROTOR, name="near the thrust rods", frequency_hz=90.0)
    forced = dataclasses.replace(case, links=tuple(
        dataclasses.replace(link, modes="static") if link.name.startswith("thrust") else link
        for link in case.links))
    auto_prepared = prepare(case, near)
    thrust = auto_prepared.scene.reduced["thrust-left"]
    assert thrust.decision.ratio > 0.25 and thrust.n_fixed_interface > 0
    auto, static = _frequency(case, near), _frequency(forced, near)
    assert not any("low-frequency" in w for w in auto.warnings)
    warned = [w for w in static.warnings if "low-frequency approximation" in w]
    assert {w.split("'")[1] for w in warned} == {"thrust-left", "thrust-right"}
    # the warning matters: the forced model misses the rods' own dynamics
    assert np.max(np.abs(static.transmissibility / auto.transmissibility - 1)) > 0.05


# --- 6. nearly incompressible link material --------------------------------------------------------------


def _free_bending_hz(poisson_ratio: float) -> np.ndarray:
    """First two free-free bending frequencies of a 0.5 m x 20 mm x 20 mm steel-like bar, Hz."""
    length, side = 0.5, 0.02
    solid = Material("bar", youngs_modulus=210e9, poisson_ratio=poisson_ratio, density=7850.0)
    x, yz = np.linspace(0, length, 51), np.linspace(-side / 2, side / 2, 3)
    bar = assemble(BodyMesh(skfem.MeshTet2.from_mesh(skfem.MeshTet1.init_tensor(x, yz, yz))), solid)
    frequencies, _ = natural_frequencies(bar.stiffness, bar.mass, 8, shift_hz=100.0)
    return frequencies[6:8]


def test_nearly_incompressible_material_does_not_lock():
    """nu = 0.49 (lambda = 25 mu): quadratic tetrahedra do not lock. The
    free-free bending frequency does not depend on nu (Euler-Bernoulli,
    4.730^2 / (2 pi L^2) sqrt(EI / rho A)); measured -0.56 % for both 0.3 and
    0.49 (shear and rotary inertia). A locking element would stiffen it
    with nu. (Clamped, the 3-D end constraint of the lateral contraction does
    stiffen it with nu: +0.16 % at 0.3, +1.0 % at 0.49.)"""
    c = math.sqrt(210e9 / 7850.0)
    euler = 4.7300 ** 2 / (2 * math.pi * 0.5 ** 2) * math.sqrt(0.02 ** 2 / 12) * c
    incompressible, ordinary = _free_bending_hz(0.49), _free_bending_hz(0.3)
    assert incompressible == pytest.approx([euler, euler], rel=0.01)
    assert incompressible == pytest.approx(ordinary, rel=1e-3)


# --- 7. a very long run -------------------------------------------------------------------------------


@pytest.mark.slow
def test_a_long_run_stores_the_measured_windows_only(rigid):
    """Memory does not grow with the run: 60 s of settling (142k steps) keeps
    the same number of stored samples as 1 s."""
    short = _time(_with(rigid, settle_time=1.0, start="rest"))
    long = _time(_with(rigid, settle_time=60.0, start="rest"))
    expected = 2 * rigid.analysis.measured_periods * rigid.analysis.steps_per_period + 1
    assert len(short.time) == len(long.time) == expected
    assert long.steady and long.transmissibility == pytest.approx(short.transmissibility, rel=1e-3)


# --- 8. an unrestrained mechanism -------------------------------------------------------------------------


@pytest.mark.parametrize("run", [_time, _frequency], ids=["time", "frequency"])
def test_an_unrestrained_mechanism_stops_before_any_integration(rigid, run):
    without = rigid.without_link("thrust-left").without_link("thrust-right")
    with pytest.raises(MechanismError, match=r"free motion.*heading translation \(x\)") as caught:
        run(without)
    assert isinstance(caught.value, SimulationError)


# --- 9. a very fast heavy rotor -----------------------------------------------------------------------------


def test_a_heavy_fast_rotor_is_no_mechanism_and_keeps_the_stiffness_determinant(rigid):
    """Ip = 1e5 kg m^2 at 248.5 Hz drives the backward whirl towards 0 Hz;
    nothing is free, so the mechanism check (on K and M alone) passes. The
    gyroscopic coupling cannot change det(K) / det(M), the product of the
    squared natural frequencies: it must be the same with and without it."""
    heavy = dataclasses.replace(rigid, rotors=(Rotor("heavy", polar_inertia=1e5, frequency_hz=248.5),),
                                effects=dataclasses.replace(rigid.effects, gyroscopics=True))
    prepared = prepare(heavy, HP_ROTOR)
    whirl = [m.omega_squared for m in prepared.modes]
    still = [m.omega_squared for m in modes_of(prepared.model.linearization, gyroscopic=False)]
    assert min(m.frequency_hz for m in prepared.modes) < FREE_FREQUENCY_HZ < still[0]
    # the slow backward whirl is a real mounted mode: listed, not dropped as if it were free
    assert mounted_modes(prepared.modes)[0].frequency_hz < FREE_FREQUENCY_HZ
    assert np.sum(np.log(whirl)) == pytest.approx(np.sum(np.log(still)), rel=1e-6)


def test_a_campbell_diagram_to_an_extreme_speed_says_which_branch_it_loses(cache_dir):
    """The reference rotors from 1e5 to 1e7 rpm: at 5e6 rpm the gyroscopic moment has slowed the
    backward whirl (1.4 Hz at 1e5 rpm) below the 0.05 Hz the diagram follows, so one branch has no
    continuation (before: an IndexError from an uninitialised index, or, when the garbage index
    happened to lie in range, a branch silently continued by another mode)."""
    case = reference_case(rotors=True, element_size=COARSE_ELEMENT_SIZE).with_rigid_links()
    with pytest.raises(SimulationError, match=r"cannot follow the branch of engine yaw.*at 1\.40\d Hz at 100000 "
                                              r"rpm\) to 5\.05e\+06 rpm"):
        campbell(case, start_rpm=1e5, stop_rpm=1e7, points=3)


@pytest.mark.parametrize("excitation", [0.0, 5.0, "noise"], ids=["zero", "constant", "noise only"])
def test_a_rig_record_without_an_excitation_to_divide_by_is_refused(excitation):
    """The reference rig record measures T_x 0.0351 (its simulation: 0.03511); with its excitation
    channels at zero, constant, or holding noise alone, T was NaN, infinite, 2.8e15 or noise, exit 0."""
    record = read_record(REFERENCE_RECORD)
    assert measure(record, 20).transmissibility[0] == pytest.approx(0.03511, rel=0.01)
    signal = (np.random.default_rng(0).normal(0.0, 10.0, record.excitation.shape) if excitation == "noise"
              else np.full(record.excitation.shape, excitation))
    with pytest.raises(RecordError, match="no excitation at the rotor frequency to divide by"):
        measure(dataclasses.replace(record, excitation=signal), 20)


def test_updating_to_a_measured_t_of_zero_or_nan_is_refused_naming_it(rigid):
    """The fit compares ln T: a record whose pylon channels are dead measures T = 0 (before: an internal
    error, "Residuals are not finite in the initial point")."""
    measured = [[0.035, 0.0004, 0.017], [0.0, 0.0016, math.nan]]
    with pytest.raises(UsageError, match=r"measured dead T x = 0, dead T z = nan: the fit compares ln T"):
        update_to_transmissibility(rigid, ["LP rotor", "HP rotor"], measured, {"hinge_stiffness": (1e6, 1e8)},
                                   labels=["good", "dead"])


# --- 10. an undamped link mode -------------------------------------------------------------------------------


@pytest.mark.slow
def test_an_excitation_on_an_undamped_link_mode_is_refused_naming_the_links(cache_dir):
    """Hinge and link damping off, flexible links: the thrust rods' own
    bending modes (engine still) are undamped. On one of them the harmonic
    matrix is singular to round-off (T of 1e8 was reported before);
    1 % beside it the answer is finite and bounded by the undamped modal
    amplification."""
    case = reference_case()
    bare = dataclasses.replace(case, effects=dataclasses.replace(case.effects, hinge_damping=False,
                                                                 link_damping=False))
    prepared = prepare(bare, LP_ROTOR, reduce_for=HP_ROTOR)
    rod = next(m for m in prepared.modes if m.engine_share < 0.01 and m.body_shares["thrust-left"] > 0.3)
    on_mode = dataclasses.replace(LP_ROTOR, frequency_hz=rod.frequency_hz)
    with pytest.raises(ResonanceError, match=r"undamped mode at [\d.]+ Hz \(motion of 'thrust-(left|right)'.*"
                                             r"with the engine still"):
        solve_frequencies(bare, prepared, (on_mode,), choose_method(bare))
    # the safety net behind that check: a solve singular to round-off is refused, naming the nearest mode
    with pytest.raises(ResonanceError, match=r"singular to round-off.*from the mode at [\d.]+ Hz \(motion of "
                                             r"'thrust-(left|right)'"):
        with singular_solve_guard("the rods", rod.frequency_hz, prepared.modes):
            prepared.model.result(on_mode, bare.analysis.steady_tolerance)
    beside = dataclasses.replace(LP_ROTOR, frequency_hz=1.01 * rod.frequency_hz)
    result = solve_frequencies(bare, prepared, (beside,), choose_method(bare))[0]
    assert np.all(np.isfinite(result.transmissibility)) and result.transmissibility.max() < 1e3
