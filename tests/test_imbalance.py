"""Imbalance planes: several eccentric masses of one rotor at one speed.

The scene is the single-DOF mount of test_sdof (a rigid mass on four equal
spring-dampers at (+-a, +-b, 0) about its centre of gravity, diagonal
inertia). Two planes of equal force on the spin axis x at +-L about the
centre of gravity with opposite phases have no resultant force: they form a
rotating couple of magnitude 2 L F about y and z. On this mount pitch and
yaw are single-DOF oscillators of their own,

    theta_y = M / (k_ty - I_yy w^2 + i w c_ty),   k_ty = 4 k a^2,
    theta_z = M / (k_tz - I_zz w^2 + i w c_tz),   k_tz = 4 k (a^2 + b^2),

(c likewise with the hinge damping d), and each hinge carries
|k + i w d| a |theta_y| vertically and |k + i w d| a |theta_z| laterally.
"""
import dataclasses
import math

import numpy as np
import pytest
from test_sdof import DAMPING, STIFFNESS, sdof_case

from workbook.errors import CaseError
from workbook.model.case import Imbalance, ImbalancePlane, RotatingForce, RunUp
from workbook.solve.pipeline import prepare, run_case

HALF_SPAN = 0.4        # a: hinge offset along x, m (test_sdof)
HALF_WIDTH = 0.3       # b: hinge offset along y, m
FREQUENCY = 14.0       # Hz
FORCE = 800.0          # N per plane
ARM = 0.6              # L: plane offset from the centre of gravity, m


def _case(excitation, method="frequency"):
    case = sdof_case(())
    return dataclasses.replace(case, excitations=(excitation,),
                               analysis=dataclasses.replace(case.analysis, method=method))


def _couple(arm=ARM, force=FORCE, centre_offset=0.0):
    cg = np.array(sdof_case(()).engine.center_of_mass)
    planes = (ImbalancePlane(tuple(cg + (centre_offset + arm, 0, 0)), amplitude=force, phase_deg=0.0),
              ImbalancePlane(tuple(cg + (centre_offset - arm, 0, 0)), amplitude=force, phase_deg=180.0))
    return Imbalance("couple", planes, frequency_hz=FREQUENCY)


def _closed_form_hinge_amplitudes():
    """Hinge force amplitudes (x, y, z) of the rotating couple 2 L F, N."""
    omega = 2 * math.pi * FREQUENCY
    moment = 2 * ARM * FORCE
    inertia = np.diag(sdof_case(()).engine.inertia_matrix)
    spring = abs(STIFFNESS + 1j * omega * DAMPING)
    arms = {"y": HALF_SPAN ** 2, "z": HALF_SPAN ** 2 + HALF_WIDTH ** 2}
    theta = {axis: moment / abs(4 * r2 * STIFFNESS - inertia[i] * omega ** 2 + 1j * omega * 4 * r2 * DAMPING)
             for axis, r2, i in (("y", arms["y"], 1), ("z", arms["z"], 2))}
    return np.array([spring * HALF_WIDTH * theta["z"], spring * HALF_SPAN * theta["z"], spring * HALF_SPAN * theta["y"]])


@pytest.fixture(scope="module")
def couple_answers():
    return {method: run_case(_case(_couple(), method)) for method in ("frequency", "time")}


@pytest.mark.parametrize("method", ["frequency", "time"])
def test_opposite_planes_give_the_closed_form_couple(couple_answers, method):
    run = couple_answers[method].runs[0]
    expected = _closed_form_hinge_amplitudes()
    tolerance = 1e-6 if method == "frequency" else 5e-3
    for name, amplitude in run.hinge_amplitudes.items():
        np.testing.assert_allclose(amplitude, expected, rtol=tolerance, err_msg=name)
    # no resultant force: the pylon sum cancels to round-off
    assert run.pylon_amplitude.max() < 1e-6 * expected.max() * (1 if method == "frequency" else 1e3)
    assert run.excitation_amplitude == pytest.approx(2 * FORCE)


@pytest.mark.parametrize("method", ["frequency", "time"])
def test_model_card_lists_the_planes_only_when_given(couple_answers, method):
    card = next(iter(couple_answers[method].model_cards.values()))
    entry = next(e for e in card.effects if e.name == "imbalance planes")
    assert entry.on and "2 planes" in entry.detail and "1600 N" in entry.detail
    single = run_case(_case(RotatingForce("one", (0.2, -0.1, 0.3), frequency_hz=FREQUENCY, amplitude=FORCE)))
    entry = next(e for e in next(iter(single.model_cards.values())).effects if e.name == "imbalance planes")
    assert not entry.on


def test_any_equal_couple_gives_the_same_answer():
    """A rigid engine feels the resultant and the moment only: a couple of the
    same moment from planes elsewhere on the axis, with another arm and force."""
    moved = run_case(_case(_couple(arm=1.5 * ARM, force=FORCE / 1.5, centre_offset=-0.9))).runs[0]
    np.testing.assert_allclose(moved.hinge_amplitudes["hinge 0"], _closed_form_hinge_amplitudes(), rtol=1e-6)


def test_planes_superpose_and_unbalance_grows_with_the_speed_squared():
    """Two planes in one solve equal the sum of two single rotating forces
    (phasors), and an unbalance U gives the force U w^2."""
    cg = np.array(sdof_case(()).engine.center_of_mass)
    unbalance, rpm = 2.5e-3, 840.0
    planes = (ImbalancePlane(tuple(cg + (0.3, 0, 0)), unbalance=unbalance, phase_deg=30.0),
              ImbalancePlane(tuple(cg - (0.5, 0, 0)), amplitude=300.0, phase_deg=-75.0))
    both = Imbalance("two planes", planes, rpm=rpm)
    omega = 2 * math.pi * rpm / 60
    assert both.plane_forces()[0].force_amplitude == pytest.approx(unbalance * omega ** 2, rel=1e-12)
    assert both.force_amplitude == pytest.approx(unbalance * omega ** 2 + 300.0, rel=1e-12)
    case = _case(both)
    prepared = prepare(case, both)
    with prepared.scene:
        model = prepared.model
        together = model.respond_generalised(both.frequency, model.excitation_input(both))
        single = [RotatingForce("one", planes[0].point, rpm=rpm, amplitude=unbalance * omega ** 2, phase_deg=30.0),
                  RotatingForce("two", planes[1].point, rpm=rpm, amplitude=300.0, phase_deg=-75.0)]
        parts = [model.respond(f.frequency, np.asarray(f.force_coefficients()[0]) - 1j * f.force_coefficients()[1],
                               f.point) for f in single]
    for name in together.hinge_forces:
        np.testing.assert_allclose(together.hinge_forces[name], parts[0].hinge_forces[name] + parts[1].hinge_forces[name],
                                   rtol=1e-10, atol=1e-9 * FORCE)


@pytest.mark.parametrize("planes, field", [
    ((ImbalancePlane((0, 0, 0), unbalance=-1e-3),), "unbalance"),
    ((ImbalancePlane((0, 0, 0), amplitude=10.0, phase_deg="north"),), "phase_deg"),
    ((ImbalancePlane((0, 0, 0)),), "unbalance"),
    ((), "planes"),
])
def test_bad_planes_are_named(planes, field):
    with pytest.raises(CaseError, match=f"field '{field}'"):
        Imbalance("bad", planes, frequency_hz=10.0)


def test_run_up_needs_an_unbalance_and_a_rising_speed():
    force = RotatingForce("r", (0, 0, 0), rpm=1000.0, amplitude=10.0)
    with pytest.raises(CaseError, match="field 'unbalance'"):
        RunUp.speeds("up", force, 1000.0, 2000.0, 5)
    rotor = dataclasses.replace(force, amplitude=None, unbalance=1e-3)
    with pytest.raises(CaseError, match="field 'stop'"):
        RunUp.speeds("up", rotor, 2000.0, 1000.0, 5)
    with pytest.raises(CaseError, match="field 'speed_unit'"):
        RunUp.speeds("up", rotor, 1000.0, 2000.0, 5, unit="rad/s")
    up = RunUp.speeds("up", rotor, 1200.0, 3000.0, 4)
    np.testing.assert_allclose(up.frequencies_hz, [20.0, 30.0, 40.0, 50.0])
    np.testing.assert_allclose(up.speed_values, [1200.0, 1800.0, 2400.0, 3000.0])


# -- the Excitations sheet ----------------------------------------------------------------------------------


def _rig_case():
    """The reference mount excited as the rig does: three planes (front support,
    centre of gravity, rear support), and a run-up of the same planes."""
    from workbook.model.reference import reference_case

    case = reference_case()
    planes = (ImbalancePlane((0.35, 0.0, 0.0), unbalance=2.0e-3, phase_deg=0.0),
              ImbalancePlane(case.engine.center_of_mass, unbalance=1.5e-3, phase_deg=120.0),
              ImbalancePlane((-0.7, 0.0, 0.0), amplitude=900.0, phase_deg=240.0))
    rig = Imbalance("rig exciter", planes, frequency_hz=100.0)
    unbalanced = dataclasses.replace(rig, name="rig run-up", planes=planes[:2])
    run_up = RunUp.speeds("rig run-up", unbalanced, 1000.0, 20000.0, 20, unit="rpm")
    return dataclasses.replace(case, excitations=(rig, run_up))


@pytest.fixture
def rig_book(tmp_path):
    from workbook.excel.runs import RunSpec
    from workbook.excel.template import case_workbook, write_workbook

    runs = (RunSpec("rig exciter", "rig exciter"), RunSpec("rig run-up", "rig run-up"))
    path, _ = write_workbook(case_workbook(_rig_case(), runs), tmp_path / "rig.xlsx")
    return path


def _plane_rows(path):
    from openpyxl import load_workbook

    ws = load_workbook(path)["Excitations"]
    return [r for r in range(3, ws.max_row + 1) if ws.cell(r, 2).value == "imbalance plane"]


def _same_excitations(read, expected):
    assert read[0] == expected[0]
    assert read[1].template.planes == expected[1].template.planes and read[1].speed_unit == expected[1].speed_unit
    np.testing.assert_allclose(read[1].frequencies_hz, expected[1].frequencies_hz, rtol=1e-12)


def test_planes_and_run_up_round_trip_through_a_workbook(rig_book):
    from workbook.excel.reader import read_workbook

    _same_excitations(read_workbook(rig_book).case.excitations, _rig_case().excitations)
    assert len(_plane_rows(rig_book)) == 5        # three planes, and two of the run-up


def test_unbalance_in_g_mm_reads_as_kg_m(rig_book):
    from excel_helpers import set_cells

    from workbook.excel.reader import read_workbook

    first = _plane_rows(rig_book)[0]
    set_cells(rig_book, {("Excitations", "unbalance", 2): "g*mm", **{("Excitations", "unbalance", r): None
                                                                    for r in _plane_rows(rig_book)}})
    set_cells(rig_book, {("Excitations", "unbalance", first): 2000.0, ("Excitations", "unbalance", first + 1): 1500.0,
                         ("Excitations", "unbalance", first + 3): 2000.0,
                         ("Excitations", "unbalance", first + 4): 1500.0})
    case = read_workbook(rig_book).case
    _same_excitations(case.excitations, _rig_case().excitations)
    rig = case.excitations[0]
    assert rig.plane_forces()[0].force_amplitude == pytest.approx(2.0e-3 * (2 * math.pi * 100.0) ** 2, rel=1e-12)


@pytest.mark.parametrize("column, row, value, words", [
    ("phase", 1, "north", ["'north'", "a number"]),
    ("unbalance", 0, -2.0e-3, ["unbalance", "-0.002", "> 0"]),
    ("unbalance", "unit", "g*mmm", ["'g*mmm'", "a known unit"]),
    ("sweep to", 3, 5.0, ["sweep to", "a speed above the start"]),
    ("run-up", 3, "rad/s", ["run-up", "'rad/s'"]),
    ("frequency", 4, 50.0, ["frequency", "an empty cell", "first plane"]),
])
def test_bad_excitation_cells_are_named_and_exit_2(rig_book, capsys, column, row, value, words):
    from excel_helpers import column_of, set_cells, sha256
    from openpyxl import load_workbook
    from openpyxl.utils import get_column_letter

    from workbook.cli.main import main

    rows = _plane_rows(rig_book)
    sheet_row = 2 if row == "unit" else rows[row]
    set_cells(rig_book, {("Excitations", column, sheet_row): value})
    letter = get_column_letter(column_of(load_workbook(rig_book)["Excitations"], column))
    before = sha256(rig_book)
    assert main(["check", str(rig_book)]) == 2
    message = capsys.readouterr().err
    for text in ["sheet 'Excitations'", f"cell {letter}{sheet_row}", *words]:
        assert text in message, f"{text!r} not in\n{message}"
    assert sha256(rig_book) == before


# -- two rotors at once ------------------------------------------------------------------------------------


def _together_answers(case, item):
    return {method: run_case(dataclasses.replace(case, excitations=(item,), analysis=dataclasses.replace(
        case.analysis, method=method))) for method in ("frequency", "time")}


def test_two_rotors_in_one_run_match_superposition_and_the_closed_forms():
    """Two unequal planes at 14 Hz and a rotating force at the centre of gravity
    at 23 Hz in one time run: the amplitude at each frequency equals the
    frequency domain's part by part, and the closed form at 23 Hz (test_sdof's T)."""
    from test_sdof import NATURAL_HZ, closed_form

    from workbook.model.case import Simultaneous

    cg = sdof_case(()).engine.center_of_mass
    slow = dataclasses.replace(_couple(), name="slow", planes=(
        _couple().planes[0], dataclasses.replace(_couple().planes[1], amplitude=0.6 * FORCE)))
    item = Simultaneous("both", (slow, RotatingForce("fast", cg, frequency_hz=23.0, amplitude=FORCE)))
    answers = _together_answers(sdof_case(()), item)
    frequency, time = (answers[m] for m in ("frequency", "time"))
    assert [r.name for r in time.runs] == ["both / slow", "both / fast"] == [r.name for r in frequency.runs]
    np.testing.assert_allclose(time.runs[1].transmissibility[1:], closed_form(23.0 / NATURAL_HZ), rtol=5e-3)
    for run, reference in zip(time.runs, frequency.runs, strict=True):
        assert run.steady and run.frequency_hz == reference.frequency_hz
        for name, amplitude in reference.hinge_amplitudes.items():
            np.testing.assert_allclose(run.hinge_amplitudes[name], amplitude, rtol=5e-3, atol=5e-3 * amplitude.max())
    card = time.model_cards["both / fast"]
    entries = {e.name: e for e in card.effects}
    assert entries["simultaneous excitations"].on and entries["imbalance planes"].on
    assert "superposition" in frequency.model_cards["both / fast"].method_reason


@pytest.mark.slow
def test_lp_and_hp_together_in_one_time_run_match_the_superposed_frequency_domain(coarse_reference):
    from workbook.model.case import Simultaneous
    from workbook.model.reference import HP_ROTOR, LP_ROTOR

    item = Simultaneous("LP and HP", (LP_ROTOR, HP_ROTOR))
    answers = _together_answers(coarse_reference, item)
    for run, reference in zip(answers["time"].runs, answers["frequency"].runs, strict=True):
        assert run.steady, run.name
        # the nearly cancelled lateral pylon force compares against the largest direction
        np.testing.assert_allclose(run.transmissibility, reference.transmissibility, rtol=0.01,
                                   atol=0.01 * reference.transmissibility.max(), err_msg=run.name)


def test_least_squares_separates_two_frequencies_over_any_window():
    from workbook.answers.amplitude import harmonic_amplitudes

    time = np.arange(0.0, 0.137, 1e-4) + 1.234          # not whole periods of either frequency
    signal = 5.0 + 2.0 * np.cos(2 * np.pi * 59.0 * time + 0.3) + 0.5 * np.sin(2 * np.pi * 248.5 * time - 1.0)
    amplitudes = harmonic_amplitudes(time, signal, [59.0, 248.5])
    np.testing.assert_allclose(amplitudes, [2.0 * np.exp(0.3j), 0.5 * np.exp(1j * (-1.0 - np.pi / 2))], rtol=1e-9)


def test_simultaneous_parts_need_their_own_frequencies():
    from workbook.model.case import Simultaneous

    one = RotatingForce("one", (0, 0, 0), frequency_hz=10.0, amplitude=1.0)
    with pytest.raises(CaseError, match="field 'parts'"):
        Simultaneous("both", (one, dataclasses.replace(one, name="two")))
    with pytest.raises(CaseError, match="field 'parts'"):
        Simultaneous("both", (one,))
    both = Simultaneous("both", (one, dataclasses.replace(one, name="two", frequency_hz=30.0)))
    assert both.frequency == 30.0 and [e.name for e in both.expand()] == ["both / one", "both / two"]


def test_a_run_cannot_override_the_force_of_an_imbalance(rig_book, capsys):
    from excel_helpers import set_cells

    from workbook.cli.main import main

    set_cells(rig_book, {("Runs", "amplitude", 3): 1000.0})
    assert main(["check", str(rig_book)]) == 2
    message = capsys.readouterr().err
    assert "sheet 'Runs'" in message and "is an imbalance" in message, message
