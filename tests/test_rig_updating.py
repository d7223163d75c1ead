"""Model updating: parameters put into a case come back from its rig records; what the data cannot tell is said."""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from workbook import run_case
from workbook.cli.main import main
from workbook.design.linear_mount import LinearMount
from workbook.errors import CaseError, UsageError
from workbook.model.case import ForceTransducers
from workbook.model.codec import from_json, to_json
from workbook.model.reference import reference_case
from workbook.rig.correlation import measure
from workbook.rig.records import write_record
from workbook.rig.synthetic import REFERENCE_TRANSDUCERS, default_sample_rate, synthetic_record
from workbook.rig.updating import update_model
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
    rate = default_sample_rate(e.frequency_hz for e in truth.excitations)
    records = [synthetic_record(run, REFERENCE_TRANSDUCERS, excitation=excitation, sample_rate_hz=rate,
                                duration=2.0, noise=NOISE, seed=seed)
               for seed in (3, 4) for run, excitation in zip(result.runs, truth.excitations, strict=True)]
    return result, records


def test_a_clean_record_of_a_rig_case_measures_its_transducers_t(nominal, rig):
    result, _ = rig
    run, excitation = result.runs[1], nominal.excitations[1]      # HP: the transducers' mass counts most
    record = synthetic_record(run, REFERENCE_TRANSDUCERS, excitation=excitation, sample_rate_hz=4096.0,
                              duration=2.0, noise=0.0, drift=0.0)
    np.testing.assert_allclose(measure(record, 100).transmissibility, run.transmissibility, rtol=1e-3)


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
    assert main(["update", str(folder / "nominal.json"), *[a for p in paths for a in ("--record", p)],
                 "--vary", "hinge_stiffness/front=5e6:1e8", "--vary", "transducer_stiffness=1e7:1e9",
                 "--output", str(output), "--json"]) == 0
    out = capsys.readouterr().out
    fitted = json.loads(out[out.index("\n{") + 1:])       # after the lines saying what was written
    case = from_json((output / "updated-case.json").read_text())
    assert case.test_rig.stiffness[0] == pytest.approx(fitted["parameters"]["transducer_stiffness"]["fitted"])
    assert {p.name for p in output.iterdir()} >= {"updated-case.json", "update-errors.csv", "update.png"}
