"""Uncertainty studies: sampling of the distributions, Monte Carlo percentiles through a monotone T,
Sobol' indices of a parameter without effect, Dask = local processes on the linear mount."""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pandas as pd
import pytest
from conftest import COARSE_ELEMENT_SIZE
from scipy.stats import norm

from workbook.cli.main import main
from workbook.cli.uq import parse_params
from workbook.errors import EXIT_FAILED_ROWS, InputError, UsageError
from workbook.model.codec import to_json
from workbook.model.reference import LP_ROTOR, reference_case
from workbook.studies.parallel import NUMPY_PATH, prepare_design_model, run_rows
from workbook.studies.parametric import row_case, study_cases
from workbook.studies.sensitivity import study_frame
from workbook.studies.uncertainty import Distribution, parse_distribution, run_uncertainty, sample_rows

STIFFNESS = "lognormal:2e7:0.1"


@pytest.fixture(scope="module")
def base():
    """The reference mount on rigid links, LP rotor, hinge damping switched off: its loss factor has no effect."""
    case = reference_case(element_size=COARSE_ELEMENT_SIZE).with_rigid_links()
    return dataclasses.replace(case, excitations=(LP_ROTOR,),
                               effects=dataclasses.replace(case.effects, hinge_damping=False))


@pytest.fixture(scope="module")
def model(base, cache_dir):
    return prepare_design_model(base)


def test_distributions_are_sampled_as_defined():
    rows = sample_rows({"hinge_stiffness": parse_distribution(STIFFNESS),
                        "engine_mass": parse_distribution("tol:2300:3%:3"),
                        "hinge_loss_factor": parse_distribution("uniform:0.02:0.08")}, 20_000, seed=4)
    log_k = np.log([row["hinge_stiffness"] for row in rows])
    assert np.exp(np.median(log_k)) == pytest.approx(2e7, rel=3e-3)       # median recovered
    assert log_k.std() == pytest.approx(0.1, rel=0.02)                      # sigma of ln recovered
    mass = np.array([row["engine_mass"] for row in rows])
    assert mass.mean() == pytest.approx(2300, abs=0.1) and mass.std() == pytest.approx(69 / 3, rel=0.02)
    eta = np.array([row["hinge_loss_factor"] for row in rows])
    assert 0.02 <= eta.min() and eta.max() <= 0.08 and eta.mean() == pytest.approx(0.05, rel=0.01)
    assert parse_distribution("tol:2e7:1e6") == Distribution("normal", 2e7, 1e6 / 3)
    assert len(sample_rows({"hinge_stiffness": parse_distribution(STIFFNESS)}, 8, sobol=True)) == 8 * 3
    for text in ("normal:1", "beta:1:2", "uniform:2:1", "lognormal:-1:0.1", "tol:1:0", "normal:a:1"):
        with pytest.raises(InputError, match="distribution"):
            parse_distribution(text)
    with pytest.raises(InputError, match="power of two"):
        sample_rows({"hinge_stiffness": parse_distribution(STIFFNESS)}, 10, sobol=True)
    with pytest.raises(UsageError, match="--param 'stiff=normal:1:1': unknown study parameter"):
        parse_params(["stiff=normal:1:1"])
    with pytest.raises(InputError, match="material takes a list"):
        sample_rows({"material": parse_distribution("uniform:1:2")}, 4)


def test_monte_carlo_percentiles_follow_t_through_the_parameter_quantiles(base, model):
    """T x rises with the hinge stiffness, so its P-th percentile is T at the stiffness's: at 400 samples the
    sample quantile lies within 0.35 standard deviations (about 3 standard errors) of the distribution's."""
    stiffness = parse_distribution(STIFFNESS)
    result = run_uncertainty(base, {"hinge_stiffness": stiffness}, 400, seed=2, design_model=model)
    assert set(result.frame["path"]) == {NUMPY_PATH} and result.failed == 0
    statistics = result.to_pandas().set_index("quantity")

    def t_x(z):
        case = row_case(base, {"hinge_stiffness": float(stiffness.ppf(norm.cdf(z)))}, 0)
        return model.evaluate(case).result.runs[0].transmissibility[0]

    for p in (5, 50, 95):
        z = norm.ppf(p / 100)
        low, high = sorted((t_x(z - 0.35), t_x(z + 0.35)))
        assert low < statistics.loc["T x", f"P{p}"] < high, p
        assert statistics.loc["eta % x", f"P{100 - p}"] == pytest.approx(100 * (1 - statistics.loc["T x", f"P{p}"]))
    t = result.frame["T x"].to_numpy()
    assert statistics.loc["T x", "mean"] == pytest.approx(t.mean()) and statistics.loc["T x", "std"] == pytest.approx(t.std(ddof=1))


@pytest.mark.slow
def test_sobol_indices_of_a_parameter_without_effect_through_the_command(base, tmp_path):
    """With hinge damping off the loss factor leaves T as it is: total index 0; the first-order indices sum to
    at most 1 within their confidence; the files as documented."""
    case_file = tmp_path / "case.json"
    case_file.write_text(to_json(base))
    argv = ["study", "uq", str(case_file), "--param", f"hinge_stiffness={STIFFNESS}",
            "--param", "hinge_loss_factor=uniform:0.02:0.08", "--samples", "64", "--sobol", "--workers", "1",
            "--output", str(tmp_path / "out"), "--json"]
    assert main(argv) == 0
    sheets = pd.read_excel(tmp_path / "out" / "uncertainty.xlsx", sheet_name=None)
    assert list(sheets) == ["Uncertainty samples", "Statistics", "Sobol indices"]
    assert len(pd.read_csv(tmp_path / "out" / "uncertainty.csv")) == 64 * 4
    assert (tmp_path / "out" / "uncertainty.png").stat().st_size > 10_000
    indices = sheets["Sobol indices"]
    lossy = indices[indices["parameter"] == "hinge_loss_factor"]
    assert np.all(np.abs(lossy["ST"]) < 1e-9) and np.all(np.abs(lossy["S1"]) < 1e-9)
    for _, group in indices.groupby("quantity"):
        assert group["S1"].sum() <= 1 + np.hypot.reduce(group["S1 conf"])
    stiff = indices[indices["parameter"] == "hinge_stiffness"]
    assert np.all(stiff["ST"] + stiff["ST conf"] > 0.9)


def test_the_command_prints_json(base, tmp_path, capsys):
    case_file = tmp_path / "case.json"
    case_file.write_text(to_json(base))
    assert main(["study", "uq", str(case_file), "--param", "engine_mass=tol:2300:5%", "--samples", "20",
                 "--workers", "1", "--output", str(tmp_path), "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["rows"] == 20 and document["failed"] == 0 and document["sobol"] is None
    assert document["distributions"] == {"engine_mass": "normal:2300:38.3333"}
    assert [r["quantity"] for r in document["statistics"]][:3] == ["T x", "T y", "T z"]
    assert document["files"][0].endswith("uncertainty.csv")
    assert main(["study", "uq", str(case_file), "--param", "engine_mass=tol:2300", "--samples", "20"]) == UsageError.exit_code
    assert "--param 'engine_mass=tol:2300': distribution" in capsys.readouterr().err


@pytest.mark.slow
def test_dask_workers_use_the_linear_mount_and_equal_local_processes(base, model):
    from distributed import LocalCluster

    rows = sample_rows({"hinge_stiffness": parse_distribution(STIFFNESS),
                        "engine_mass": parse_distribution("normal:2300:50")}, 40, seed=5)
    cases = study_cases(base, rows)
    local = study_frame(rows, run_rows(cases, workers=2, design_model=model))
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        on_dask = study_frame(rows, run_rows(cases, dask=cluster.scheduler_address, design_model=model))
    assert set(on_dask["path"]) == {NUMPY_PATH}
    pd.testing.assert_frame_equal(local.drop(columns="wall time s"), on_dask.drop(columns="wall time s"))


def test_a_study_whose_every_row_fails_says_why(tmp_path, capsys):
    """It printed pandas' "Empty DataFrame" and its columns; now the first row's error."""
    argv = ["study", "uq", "--rigid", "--param", "hinge_stiffness=uniform:-2e7:-1e7", "--samples", "4", "--workers",
            "1", "--output", str(tmp_path)]
    assert main(argv) == EXIT_FAILED_ROWS
    out = capsys.readouterr().out
    assert "Empty DataFrame" not in out
    assert out.splitlines()[0].startswith("no statistics: every row failed (row 0: CaseError: hinge ")
    assert out.splitlines()[-1] == f"4 of 4 rows failed (their errors in {tmp_path / 'uncertainty.csv'})"
