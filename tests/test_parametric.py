"""Parameter studies: rows, row cases, and runs serial = processes = Dask, failures per row."""
from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest
from conftest import COARSE_ELEMENT_SIZE

from workbook.cli.main import main
from workbook.cli.params import parse_vary
from workbook.errors import EXIT_FAILED_ROWS, CaseError, UsageError
from workbook.model.case import AnalysisSettings
from workbook.model.codec import to_json
from workbook.model.reference import HINGE_STIFFNESS, LP_ROTOR, reference_case
from workbook.solve.pipeline import run_case
from workbook.studies.parallel import run_rows
from workbook.studies.parametric import grid, latin_hypercube, linear_range, row_case, study_cases
from workbook.studies.sensitivity import study_frame

#: Short, steady runs on rigid links, LP rotor only.
SHORT = AnalysisSettings(settle_time=0.2, measured_periods=10)
STIFFNESS = [1e7, HINGE_STIFFNESS, 4e7, 0.0]
REMOVED = ["none", "rear-left"]


@pytest.fixture(scope="module")
def base():
    case = reference_case(analysis=SHORT, element_size=COARSE_ELEMENT_SIZE).with_rigid_links()
    return dataclasses.replace(case, excitations=(LP_ROTOR,))


@pytest.fixture(scope="module")
def rows():
    return grid({"hinge_stiffness": STIFFNESS, "removed_link": REMOVED})


@pytest.fixture(scope="module")
def serial(base, rows, cache_dir):
    return study_frame(rows, run_rows(study_cases(base, rows), workers=1))


def _answers(frame):
    return frame.drop(columns="wall time s").reset_index(drop=True)


def test_grid_range_and_latin_hypercube_rows():
    assert grid({"hinge_stiffness": [1, 2], "material": ["steel", "titanium"]}) == (
        {"hinge_stiffness": 1, "material": "steel"}, {"hinge_stiffness": 1, "material": "titanium"},
        {"hinge_stiffness": 2, "material": "steel"}, {"hinge_stiffness": 2, "material": "titanium"})
    assert linear_range(1e7, 4e7, 4) == [1e7, 2e7, 3e7, 4e7]
    samples = latin_hypercube({"hinge_stiffness": (1e7, 3e7), "frequency": (50.0, 70.0)}, 10, seed=3)
    for name, (low, high) in (("hinge_stiffness", (1e7, 3e7)), ("frequency", (50.0, 70.0))):
        strata = sorted(int((row[name] - low) / (high - low) * 10) for row in samples)
        assert strata == list(range(10))  # one sample in each tenth of every range
    assert parse_vary(["hinge_damping=1e3:3e3:3", "material=steel,titanium"], None) == grid(
        {"hinge_damping": [1e3, 2e3, 3e3], "material": ["steel", "titanium"]})
    with pytest.raises(ValueError, match="with --lhs give bounds"):
        parse_vary(["frequency=50,60"], lhs=5)
    with pytest.raises(ValueError, match="unknown study parameter"):
        grid({"stiffness": [1.0]})



@pytest.mark.parametrize("spec, lhs, words", [
    ("hinge_stiffness=a,b", None, "found 'a', expected a finite number"),
    ("hinge_stiffness=inf,2e7", None, "found 'inf', expected a finite number"),
    ("hinge_stiffness=1e7:nan:3", None, "found 'nan', expected a finite number"),
    ("hinge_stiffness=1e7:2e7:2.5", None, "found '2.5' points, expected a whole number"),
    ("hinge_stiffness=1e7:2e7:0", None, "a range needs at least one point, got 0"),
    ("hinge_stiffness=x:2e7", 5, "found 'x', expected a finite number"),
])
def test_a_malformed_vary_option_is_named_with_what_was_found(spec, lhs, words):
    with pytest.raises(UsageError) as raised:
        parse_vary([spec], lhs)
    assert str(raised.value) == f"--vary {spec!r}: {words}"

def test_row_case_sets_every_parameter(base):
    row = {"hinge_stiffness": 3e7, "hinge_damping": 500.0, "clearance": 1e-4, "section_scale": 1.2,
           "material": "titanium", "frequency": 61.0, "removed_link": "rear-lateral"}
    case = row_case(base, row, 7)
    assert case.name.endswith("/ row 7") and "rear-lateral" not in case.link_map
    assert {(h.stiffness, h.damping, h.radial_clearance) for h in case.hinges} == {(3e7, 500.0, 1e-4)}
    front = case.link_map["front-left"].model
    assert front.material.name == "titanium"
    assert front.geometry.shank_width == pytest.approx(1.2 * base.link_map["front-left"].model.geometry.shank_width)
    assert [e.frequency for e in case.excitations] == [61.0]
    with pytest.raises(CaseError, match="stiffness"):
        row_case(base, {"hinge_stiffness": 0.0}, 0)


def test_hinge_parameters_by_group_and_direction(base):
    case = row_case(base, {"hinge_stiffness/front/axial": 1e8, "hinge_loss_factor/all/radial": 0.05,
                           "engine_mass": 2500.0}, 1)
    for hinge, before in zip(case.hinges, base.hinges, strict=True):
        axial = 1e8 if hinge.name.startswith("front") else before.values("stiffness")[2]
        np.testing.assert_array_equal(hinge.values("stiffness"), [*before.values("stiffness")[:2], axial])
        np.testing.assert_array_equal(hinge.values("loss_factor"), [0.05, 0.05, before.values("loss_factor")[2]])
    assert case.engine.mass == 2500.0 and case.engine.inertia == base.engine.inertia
    with pytest.raises(ValueError, match="DIRECTION: radial1"):
        row_case(base, {"hinge_stiffness/front/up": 1e8}, 0)
    with pytest.raises(CaseError, match="start of hinge names"):
        row_case(base, {"hinge_damping/middle": 1.0}, 0)
    with pytest.raises(CaseError, match="test-rig force transducers"):
        row_case(base, {"transducer_stiffness": 1e8}, 0)


def test_a_row_sets_its_parameters_in_its_order(base):
    """A row's changes of every hinge are made together, yet a later value wins as if each parameter were
    applied in turn: a group's value before the value of every hinge is overwritten, after it is kept."""
    from workbook.studies.parametric import parameter

    for row in ({"hinge_stiffness/front": 1e8, "hinge_stiffness": 2e7, "hinge_loss_factor": 0.03},
                {"hinge_stiffness": 2e7, "hinge_loss_factor": 0.03, "hinge_stiffness/front": 1e8, "clearance": 1e-4},
                {"hinge_damping": 300.0, "engine_mass": 2500.0, "hinge_damping/rear": 700.0}):
        expected = base
        for name, value in row.items():
            expected = parameter(name).apply(expected, value)
        got = row_case(base, row, 3)
        assert got.hinges == expected.hinges and got.engine == expected.engine
    assert {h.values("stiffness")[0] for h in row_case(base, {"hinge_stiffness/front": 1e8, "hinge_stiffness": 2e7},
                                                       0).hinges} == {2e7}


def test_processes_equal_serial_and_failing_rows_are_reported(base, rows, serial):
    processes = study_frame(rows, run_rows(study_cases(base, rows), workers=2))
    # the same to round-off, not bit for bit: NumPy's reductions round by the memory alignment of their data,
    # which differs between a fresh worker process and one that has run before
    pd.testing.assert_frame_equal(_answers(processes), _answers(serial), check_exact=False, rtol=1e-10, atol=1e-14)
    by_row = serial.set_index("row")
    for index, row in enumerate(rows):
        status, error = by_row.loc[index, "status"], by_row.loc[index, "error"]
        if row["hinge_stiffness"] == 0.0:
            assert status == "failed" and error.startswith("CaseError: hinge") and "stiffness" in error
        elif row["removed_link"] == "rear-left":
            assert status == "failed" and error.startswith("MechanismError:") and "thrust-left" in error
        else:
            assert status == "ok" and error == "" and by_row.loc[index, "steady"]
    ok = serial[serial["status"] == "ok"]
    assert list(ok["hinge_stiffness"]) == [1e7, HINGE_STIFFNESS, 4e7]
    # the row with the reference values is the reference case's own answer
    direct = run_case(base).runs[0].transmissibility
    reference_row = ok[ok["hinge_stiffness"] == HINGE_STIFFNESS]
    np.testing.assert_allclose(reference_row[["T x", "T y", "T z"]].to_numpy()[0], direct, rtol=0.0,
                               atol=1e-12 * np.abs(direct).max())
    # stiffer hinges pass more heading force to the pylon at 59 Hz
    assert np.all(np.diff(ok["T x"].to_numpy()) > 0)


@pytest.mark.slow
def test_dask_cluster_equals_local(base, rows, serial, tmp_path):
    from distributed import LocalCluster

    case_file = tmp_path / "case.json"
    case_file.write_text(to_json(base))
    argv = ["study", "params", str(case_file), "--output", str(tmp_path / "out"), "--exudyn"]  # as the serial rows
    argv += [f"--vary=hinge_stiffness={','.join(map(str, STIFFNESS))}", f"--vary=removed_link={','.join(REMOVED)}"]
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        assert main(argv + ["--dask", cluster.scheduler_address]) == EXIT_FAILED_ROWS  # stiffness 0, link removed
    table = pd.read_csv(tmp_path / "out" / "parameter-study.csv")
    expected = _answers(serial)
    for column in expected:
        if expected[column].dtype.kind == "f":     # to round-off, as local processes
            np.testing.assert_allclose(table[column].to_numpy(float), expected[column].to_numpy(float), rtol=1e-10,
                                       atol=1e-14)
        else:
            assert list(table[column].fillna("").astype(str)) == list(expected[column].fillna("").astype(str))
    assert (tmp_path / "out" / "parameter-study.png").stat().st_size > 10_000
    assert pd.read_excel(tmp_path / "out" / "parameter-study.xlsx").shape[0] == len(serial)


@pytest.mark.parametrize(("address", "message"), [
    ("tcp://127.0.0.1:{port}", "no Dask scheduler answers there ("),
    ("nonsense", "--dask 'nonsense': missing port number in address 'nonsense'; expected tcp://HOST:PORT"),
])
@pytest.mark.parametrize("kind", ["params", "uq"])
def test_a_dask_address_where_no_scheduler_answers_is_refused_at_once(base, tmp_path, capsys, address, message, kind):
    """Dask's client tried a refused address for 30 s (a malformed one was an internal error) after the linear
    mount was prepared; now either is bad input before anything runs."""
    import socket
    import time

    with socket.socket() as free:                 # a port nothing listens on
        free.bind(("127.0.0.1", 0))
        port = free.getsockname()[1]
    case_file = tmp_path / "case.json"
    case_file.write_text(to_json(base))
    option = "--vary=hinge_stiffness=1e7,2e7" if kind == "params" else "--param=hinge_stiffness=uniform:1e7:2e7"
    argv = ["study", kind, str(case_file), "--output", str(tmp_path / "out"), option, "--dask",
            address.format(port=port)]
    start = time.monotonic()
    assert main(argv) == 2
    assert time.monotonic() - start < 15         # importing distributed takes seconds; its client took 30 s
    assert message.format(port=port) in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_section_too_wide_for_the_eyes_is_a_case_error_of_its_row(base):
    cases = study_cases(base, ({"section_scale": 1.0}, {"section_scale": 2.0}))
    assert cases[0].links[0].model == base.links[0].model
    assert isinstance(cases[1], CaseError) and "shank width" in str(cases[1])


@pytest.mark.parametrize(("option", "message"), [
    ("--vary=hinge_damping/middle=1,2", "field 'hinge_damping/middle': found 'middle', expected the start of hinge names"),
    ("--vary=transducer_stiffness=1e8,2e8", "field 'transducer_stiffness': found 'reference mount', expected a case "
                                            "with test-rig force transducers"),
    ("--vary=casing_modulus=1e11,2e11", "expected a case with a flexible engine casing"),
    ("--param=transducer_stiffness=uniform:1e8:2e8", "expected a case with test-rig force transducers"),
])
def test_a_parameter_no_row_of_the_case_can_take_is_refused_before_any_row(base, tmp_path, capsys, option, message):
    case_file = tmp_path / "case.json"
    case_file.write_text(to_json(base))
    kind = "params" if option.startswith("--vary") else "uq"
    argv = ["study", kind, str(case_file), "--output", str(tmp_path / "out"), "--workers", "1", option]
    assert main(argv) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_long_study_prints_the_ends_of_its_table_and_writes_every_row(base, tmp_path, capsys):
    """70 rows on the fast path: the table printed is its first and last 30 rows with a line saying where the
    rest is; the table file holds every row, and the rows answered in NumPy equal the batch's own answers."""
    from workbook.cli.params import PRINTED_ROWS
    from workbook.design.linear_mount import LinearMount

    case_file = tmp_path / "case.json"
    case_file.write_text(to_json(base))
    argv = ["study", "params", str(case_file), "--output", str(tmp_path / "out"), "--workers", "1",
            "--vary=hinge_stiffness=1e7:4e7", "--vary=hinge_loss_factor=0.02:0.08", "--lhs", "70"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert f"(the first and last {PRINTED_ROWS // 2} of 70 table rows; all of them in" in out
    assert len(out.splitlines()) < PRINTED_ROWS + 15
    table = pd.read_csv(tmp_path / "out" / "parameter-study.csv")
    assert list(table["row"]) == list(range(70)) and set(table["path"]) == {"NumPy"}
    rows = latin_hypercube({"hinge_stiffness": (1e7, 4e7), "hinge_loss_factor": (0.02, 0.08)}, 70, seed=0)
    answers = LinearMount.prepare(base).evaluate_many(study_cases(base, rows))
    np.testing.assert_allclose(table["T z"], [a.result.runs[0].transmissibility[2] for a in answers], rtol=1e-9)
