"""Guards of the solver path (workbook.solve.guards): a Newton failure is retried
with a smaller step and then reported with its time and cause; a run-away
engine, an exhausted time budget and an absurdly long plan stop the run in
plain words. Real Exudyn runs of the single-DOF mass of test_sdof."""
import dataclasses

import numpy as np
import pytest
from test_sdof import sdof_case

from workbook.errors import CaseError, DivergenceError, NewtonFailure, RunTooLong, SimulationError, TimeBudgetExceeded
from workbook.model.case import AnalysisSettings, HarmonicForce
from workbook.solve.guards import RoundOffWarning, checked_solve
from workbook.solve.pipeline import run_excitation

SDOF = sdof_case((1.0,))
SHAKE = HarmonicForce("shake", point=SDOF.engine.center_of_mass, direction=(0, 0, 1), amplitude=1e4,
                      frequency_hz=20.0)


def _impacting(**analysis):
    """The mass inside 20 um gaps with a 1e12 N/m contact: the first impact
    at 0.3 s defeats Newton at 40 steps per period, half the step does not."""
    hinges = tuple(dataclasses.replace(h, radial_clearance=20e-6, contact_stiffness=1e12) for h in SDOF.hinges)
    return dataclasses.replace(SDOF, hinges=hinges, analysis=AnalysisSettings(**analysis))


def test_a_newton_failure_is_retried_with_half_the_step():
    result = run_excitation(_impacting(), SHAKE)
    card = result.model_card
    retries = card.solver["step retries"]
    assert retries.startswith("0.3 to 0.35 s: step halved 1 time(s) to 0.000625 s after: ")
    assert np.all(np.isfinite(result.transmissibility))
    # sampling stays at the planned step through the retried segments
    assert np.allclose(np.diff(result.time), 1 / (40 * 20.0))


def test_without_retries_the_failure_names_the_time_and_the_cause():
    with pytest.raises(NewtonFailure, match=r"between t = 0\.3 s and t = 0\.35 s: Newton's method did not "
                                            r"converge .* halved 0 time\(s\), to 0\.00125 s\. Likely cause: "
                                            r".*(stiff|impact)") as caught:
        run_excitation(_impacting(step_halvings=0), SHAKE)
    assert caught.value.time == pytest.approx(0.3) and isinstance(caught.value, SimulationError)


def test_a_run_away_engine_stops_the_run():
    """The shaken mass moves about 0.13 mm at resonance; a limit of 1 um is exceeded."""
    case = dataclasses.replace(SDOF, analysis=AnalysisSettings(divergence_displacement=1e-6))
    with pytest.raises(DivergenceError, match=r"at t = [\d.]+ s the engine's centre of gravity is [\d.]+ mm from "
                                              r"its preloaded position \(limit 0.001 mm"):
        run_excitation(case, SHAKE)


def test_the_time_budget_stops_a_long_run_with_an_estimate():
    case = dataclasses.replace(SDOF, analysis=AnalysisSettings(settle_time=2000.0, time_budget=0.5, start="rest"))
    with pytest.raises(TimeBudgetExceeded, match=r"time budget 0.5 s\) at t = [\d.]+ s of 2\d{3}(\.\d+)? s "
                                                 r"simulated; the whole run would need about [\d.e+]+ s") as caught:
        run_excitation(case, SHAKE)
    assert 0 < caught.value.simulated < 2000.0 and caught.value.estimated_wall_time > 0.5


def test_an_absurd_plan_is_refused_before_integrating():
    case = dataclasses.replace(SDOF, analysis=AnalysisSettings(settle_time=1e7, start="rest"))
    with pytest.raises(RunTooLong, match="time steps .* Add damping, set a fixed settle time"):
        run_excitation(case, SHAKE)


@pytest.mark.parametrize("field, value", [("step_halvings", -1), ("step_halvings", 1.5),
                                          ("time_budget", 0.0), ("divergence_displacement", -1.0)])
def test_guard_settings_are_validated(field, value):
    with pytest.raises(CaseError, match=field):
        AnalysisSettings(**{field: value})


def test_the_command_line_reports_an_exhausted_time_budget_as_numerical_trouble(coarse_reference, tmp_path, capsys):
    from workbook.cli.main import main
    from workbook.model.codec import to_json

    path = tmp_path / "coarse.json"
    # from rest: a run of many segments (a steady start integrates two windows in one)
    path.write_text(to_json(dataclasses.replace(coarse_reference, analysis=dataclasses.replace(
        coarse_reference.analysis, start="rest"))))
    assert main(["run", str(path), "--rigid", "--method", "time", "--no-progress", "--time-budget", "0.01"]) == 1
    error = capsys.readouterr().err
    assert "mountwb run: numerical trouble: case 'reference mount', run 'LP rotor': stopped after" in error
    assert "time budget 0.01 s" in error


def test_a_long_measured_window_is_sampled_once_per_step():
    """4000 measured periods at 248.5 Hz: 320 000 stored steps. A sensor
    write period of exactly one step once skipped a sample there (t = 24.17 s)
    and the run failed with 'time must be uniformly sampled'."""
    shake = dataclasses.replace(SHAKE, frequency_hz=248.5, amplitude=1e3)
    case = dataclasses.replace(SDOF, analysis=AnalysisSettings(measured_periods=4000, settle_time=0.1))
    result = run_excitation(case, shake)
    step = 1 / (40 * 248.5)
    assert len(result.time) == 2 * 4000 * 40 + 1
    assert np.abs(np.diff(result.time) - step).max() < 1e-9 * step
    assert np.all(np.isfinite(result.transmissibility))


@pytest.mark.parametrize("condition", [1e2, 1e10, 1e19, 1e22])
def test_a_solve_singular_to_round_off_warns_as_scipys_does(condition):
    """:func:`checked_solve` against SciPy's ``solve``: the same answer, and a warning on the same
    complex matrices (dynamic stiffnesses of a given condition number)."""
    import warnings

    import scipy.linalg as sla

    generator = np.random.default_rng(3)
    size = 40
    left, _ = np.linalg.qr(generator.normal(size=(size, size)) + 1j * generator.normal(size=(size, size)))
    right, _ = np.linalg.qr(generator.normal(size=(size, size)) + 1j * generator.normal(size=(size, size)))
    matrix = left @ np.diag(np.logspace(0, -np.log10(condition), size)) @ right
    load = generator.normal(size=size) + 1j * generator.normal(size=size)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        expected = sla.solve(matrix, load)
        answer = checked_solve(matrix, load)
    scipy_warned = any(issubclass(w.category, sla.LinAlgWarning) for w in caught)
    warned = any(issubclass(w.category, RoundOffWarning) for w in caught)
    assert warned == scipy_warned == (condition > 1e16)
    if not warned:
        np.testing.assert_allclose(answer, expected, rtol=1e-15 * condition * 100)
    with pytest.raises(np.linalg.LinAlgError):
        checked_solve(np.zeros((3, 3)), np.ones(3))
