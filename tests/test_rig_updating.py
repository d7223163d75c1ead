"""Model updating: parameters put into a case come back from its rig records; what the data cannot tell is said."""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from workbook import run_case
from workbook.cli.main import main
from workbook.design.linear_mount import LinearMount
from workbook.design.sensitivity import design_case
from workbook.errors import CaseError, UsageError
from workbook.model.case import ForceTransducers
from workbook.model.codec import from_json, to_json
from workbook.model.reference import reference_case
from workbook.rig.correlation import measure
from workbook.rig.records import write_record
from workbook.rig.synthetic import REFERENCE_TRANSDUCERS, synthetic_record, synthetic_records
from workbook.rig.updating import Uncertainty, update_model, update_to_transmissibility
from workbook.studies.parametric import parameter, parameter_value

#: What the rig has that the nominal model lacks: one hinge group 30 % stiffer, soft transducers (N/m).
TRUTH = {"hinge_stiffness/front": 1.3 * 2e7, "transducer_stiffness": 4e7}
BOUNDS = {"hinge_stiffness/front": (5e6, 1e8), "hinge_stiffness/rear": (5e6, 1e8),
          "transducer_stiffness": (1e7, 1e9)}
NOISE = 0.005


@pytest.fixture(scope="module")
def nominal(cache_dir):
    # rigid links: the fast path prepares in a second; the transducers as the rig's datasheet says
    return dataclasses.replace(reference_case().with_rigid_links(), test_rig=ForceTransducers((1e8,) * 3))


@pytest.fixture(scope="module")
def mount(nominal):
    return LinearMount.prepare(nominal)


@pytest.fixture(scope="module")
def rig(nominal):
    """The true case's answers (by the Exudyn pipeline, not the linear model fitted) and two noisy records
    of each rotor."""
    truth = nominal
    for name, value in TRUTH.items():
        truth = parameter(name).apply(truth, value)
    result = run_case(truth)
    records = synthetic_records(truth, result, (3, 4), noise=NOISE)
    return result, records


def test_a_clean_record_of_a_rig_case_measures_its_transducers_t(nominal, rig):
    result, _ = rig
    run, excitation = result.runs[1], nominal.excitations[1]      # HP: the transducers' mass counts most
    record = synthetic_record(run, REFERENCE_TRANSDUCERS, excitation=excitation, sample_rate_hz=4096.0,
                              duration=2.0, noise=0.0, drift=0.0)
    # the amplitudes fitted at the (searched) frequency, not read off a DFT of a window of whole samples, whose
    # image leakage reached 0.2 % in records of the reference mount
    np.testing.assert_allclose(measure(record, 100).transmissibility, run.transmissibility, rtol=1e-5)
    np.testing.assert_allclose(measure(record, 7).transmissibility, run.transmissibility, rtol=1e-5)


def test_updating_recovers_the_perturbed_parameters_within_two_standard_errors(nominal, mount, rig):
    result, records = rig
    update = update_model(nominal, records, BOUNDS, mount=mount)
    truth = {**TRUTH, "hinge_stiffness/rear": 2e7}
    expected = np.array([truth[name] for name in update.parameters])
    assert np.all(np.abs(update.values - expected) < 2 * update.standard_errors), \
        (update.values, expected, update.standard_errors)
    assert np.all(update.standard_errors < 0.05 * update.values)
    assert update.warnings == [] and update.seconds < 20
    # the noise level: each record's measured T against the true T it was made from
    true_t = np.array([run.transmissibility for run in result.runs] * 2)
    noise = np.abs(update.measured / true_t - 1).max()
    errors = update.error_frame()
    assert errors["error before %"].abs().max() > 30
    assert errors["error after %"].abs().max() < 100 * 2 * noise
    # the updated case answers the true T
    updated = run_case(update.case)
    np.testing.assert_allclose([run.transmissibility for run in updated.runs], true_t[:2], rtol=2 * noise)


def test_parameters_that_act_alike_are_named(nominal, mount, rig):
    _, records = rig
    lp = [record for record in records if record.run == "LP rotor"]
    # the front links' two hinges in series: at the LP rotor only their combined spring acts
    update = update_model(nominal, lp, {"hinge_stiffness/front-up": (5e6, 1e8),
                                        "hinge_stiffness/front-down": (5e6, 1e8)},
                          mount=mount, screening=0, starts=1, max_evaluations=8)
    assert any("front-up and hinge_stiffness/front-down are not determined apart" in w for w in update.warnings)
    assert abs(update.correlation[0, 1]) > 0.999


def test_parameter_value_reads_what_apply_wrote(nominal):
    for name, value in (("hinge_stiffness/thrust/axial", 3.3e7), ("hinge_loss_factor/front", 0.08),
                        ("transducer_stiffness", 5e7), ("engine_mass", 3000.0)):
        assert parameter_value(parameter(name).apply(nominal, value), name) == value
    changed = parameter("hinge_stiffness/front/axial").apply(nominal, 3e7)
    with pytest.raises(CaseError, match="one value over its hinges and directions"):
        parameter_value(changed, "hinge_stiffness/front")


#: Two parameters fitted to exact T of the fast model at TRUTH: four measurements, the last one noisy.
RUNS = ["LP rotor", "HP rotor", "LP rotor", "HP rotor"]
SIGMA = np.array([0.005, 0.005, 0.005, 0.05])
TWO = {"hinge_stiffness/front": BOUNDS["hinge_stiffness/front"], "transducer_stiffness": BOUNDS["transducer_stiffness"]}


@pytest.fixture(scope="module")
def exact(mount):
    """The case at TRUTH and its T of each of RUNS (the linear model's, so that only the noise is in the data)."""
    truth = design_case(mount, TRUTH)
    by_run = {run.name: run.transmissibility for run in mount.evaluate(truth).result.runs}
    return truth, np.array([by_run[run] for run in RUNS])


def test_a_record_with_a_larger_uncertainty_weighs_less(mount, exact):
    truth, t = exact
    measured = t.copy()
    measured[3] *= 1.05                  # the noisy record off by its own sigma, the others exact
    fits = {weighted: update_to_transmissibility(
        truth, RUNS, measured, TWO, mount=mount, screening=0, starts=1,
        uncertainty=[Uncertainty(s) for s in SIGMA] if weighted else None) for weighted in (False, True)}
    shift = {k: np.abs(np.log(fit.values / [TRUTH[n] for n in fit.parameters])) for k, fit in fits.items()}
    # weights 1/sigma^2: the noisy record pulls 100 times less than unweighted
    assert np.all(shift[True] < 0.05 * shift[False]), shift
    assert fits[True].uncertainty is not None and fits[False].uncertainty is None
    assert "sigma %" in fits[True].error_frame()


@pytest.mark.slow
def test_standard_errors_from_the_weights_match_a_monte_carlo_over_the_noise(mount, exact):
    """20 noise realisations (ln T normal with each record's sigma) fitted: the scatter of the fitted
    values is the reported standard error within 50 % (the sample SD of 20 normal draws has a relative
    standard error of 1/sqrt(38) = 16 %: 3 of it), and their mean is the truth within 3 SE/sqrt(20)."""
    truth, t = exact
    rng = np.random.default_rng(7)
    fits = [update_to_transmissibility(truth, RUNS, t * np.exp(SIGMA[:, None] * rng.standard_normal(t.shape)), TWO,
                                       uncertainty=[Uncertainty(s) for s in SIGMA], mount=mount, screening=0, starts=1)
            for _ in range(20)]
    logs = np.log([fit.values for fit in fits])
    predicted = np.median([fit.standard_errors / fit.values for fit in fits], axis=0)
    np.testing.assert_allclose(np.std(logs, axis=0, ddof=1), predicted, rtol=0.5)
    assert np.all(np.abs(logs.mean(axis=0) - np.log([TRUTH[n] for n in fits[0].parameters]))
                  < 3 * predicted / np.sqrt(len(fits)))
    # from the weights, not the residual: the same for every realisation (up to the Jacobian's change)
    np.testing.assert_allclose([fit.standard_errors / fit.values for fit in fits], [predicted] * len(fits), rtol=0.02)
    # an unweighted fit of the same data takes them from its residual instead
    plain = update_to_transmissibility(truth, RUNS, t * np.exp(SIGMA[:, None] * rng.standard_normal(t.shape)), TWO,
                                       mount=mount, screening=0, starts=1)
    assert plain.uncertainty is None and not np.allclose(plain.standard_errors / plain.values, predicted, rtol=0.1)


@pytest.mark.parametrize("text, value, relative", [("0.5%", 0.005, True), ("2 %", 0.02, True),
                                                    ("4e-4", 4e-4, False)])
def test_an_uncertainty_reads_relative_or_absolute(text, value, relative):
    parsed = Uncertainty.parse(text)
    assert parsed.value == pytest.approx(value) and parsed.relative is relative
    assert parsed.of_log(np.array([0.5]))[0] == pytest.approx(value if relative else value / 0.5)


@pytest.mark.parametrize("text", ["0%", "abc", "1e-3%%", ""])
def test_a_bad_uncertainty_is_refused_naming_it(text):
    with pytest.raises(UsageError, match="measurement uncertainty"):
        Uncertainty.parse(text)


@pytest.mark.parametrize("option", ["lp.csv:-3%", "lp.csv:0%"])
def test_a_record_option_with_a_bad_uncertainty_names_the_uncertainty(option):
    """A tail that reads as a number is the uncertainty, refused when not positive (not taken for the path)."""
    from workbook.cli.update import _record_option

    with pytest.raises(UsageError, match="measurement uncertainty"):
        _record_option(option)
    assert _record_option("C:lp.csv") == ("C:lp.csv", None)
    assert _record_option("lp.csv:0.5%")[1].value == pytest.approx(0.005)


def test_uncertainties_for_some_records_only_are_refused(mount, exact):
    truth, t = exact
    with pytest.raises(UsageError, match="for every record or none"):
        update_to_transmissibility(truth, RUNS, t, TWO, mount=mount, uncertainty=[Uncertainty(0.01), None, None, None])


def test_the_casing_modulus_is_a_parameter_of_a_flexible_casing_only(nominal):
    """(tests/test_linear_mount_casing.py fits it.)"""
    from workbook.model.reference import reference_casing

    with pytest.raises(CaseError, match="flexible engine casing"):
        parameter("casing_modulus").apply(nominal, 1e11)
    flexible = dataclasses.replace(nominal, engine=dataclasses.replace(nominal.engine,
                                                                       casing=reference_casing(element_size=0.12)))
    changed = parameter("casing_modulus").apply(flexible, 1.3e11)
    assert parameter_value(changed, "casing_modulus") == 1.3e11
    assert changed.engine.casing.material.density == flexible.engine.casing.material.density


def test_fewer_values_than_parameters_are_refused(nominal, rig):
    _, records = rig
    with pytest.raises(UsageError, match="1 record.* give 3 values of T for 3 parameters"):
        update_model(nominal, records[:1], BOUNDS)


@pytest.fixture(scope="module")
def files(nominal, rig, tmp_path_factory):
    folder = tmp_path_factory.mktemp("update")
    (folder / "nominal.json").write_text(to_json(nominal))
    _, records = rig
    paths = [str(write_record(folder / f"record-{i}.csv", record)) for i, record in enumerate(records)]
    other = dataclasses.replace(records[0], run="CR rotor")
    return folder, paths, str(write_record(folder / "other-run.csv", other))


@pytest.mark.parametrize("vary, message", [
    ("hinge_stifness/front=1e7:5e7", "unknown study parameter 'hinge_stifness/front'"),
    ("hinge_stiffness/front=5e7:1e7", "expected NAME=low:high with numbers low < high"),
    ("section_scale=0.5:2", "'section_scale' has no single value in a case"),
])
def test_bad_parameters_exit_2_naming_them(files, capsys, vary, message):
    folder, paths, _ = files
    assert main(["update", str(folder / "nominal.json"), "--record", paths[0], "--vary", vary]) == 2
    assert message in capsys.readouterr().err


def test_a_record_of_another_run_exits_2_naming_it(files, capsys):
    folder, paths, other = files
    assert main(["update", str(folder / "nominal.json"), "--record", paths[0], "--record", other,
                 "--vary", "transducer_stiffness=1e7:1e9"]) == 2
    err = capsys.readouterr().err
    assert "other-run.csv" in err and "'CR rotor'" in err


@pytest.mark.slow
def test_update_command_writes_the_updated_case(files, capsys):
    folder, paths, _ = files
    output = folder / "out"
    assert main(["update", str(folder / "nominal.json"), *[a for p in paths for a in ("--record", p + ":0.5%")],
                 "--vary", "hinge_stiffness/front=5e6:1e8", "--vary", "transducer_stiffness=1e7:1e9",
                 "--output", str(output), "--json"]) == 0
    out = capsys.readouterr().out
    fitted = json.loads(out[out.index("\n{") + 1:])       # after the lines saying what was written
    assert fitted["weighted"] is True
    case = from_json((output / "updated-case.json").read_text())
    assert case.test_rig.stiffness[0] == pytest.approx(fitted["parameters"]["transducer_stiffness"]["fitted"])
    assert {p.name for p in output.iterdir()} >= {"updated-case.json", "update-errors.csv", "update.png"}
