"""Run-ups: an unbalance over a speed range, force U w^2, against closed forms and single runs."""
import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest
from test_sdof import NATURAL_HZ, ZETA, closed_form, sdof_case

from workbook.answers.warning_groups import warning_lines
from workbook.model.case import RotatingForce, RunUp
from workbook.model.reference import HP_ROTOR, LP_ROTOR
from workbook.solve.pipeline import run_case
from workbook.solve.run_up import run_up

UNBALANCE = 4e-3       # kg m


@pytest.fixture(scope="module")
def sdof_run_up():
    case = sdof_case(())
    rotor = RotatingForce("rotor", case.engine.center_of_mass, rpm=600.0, unbalance=UNBALANCE)
    item = RunUp.speeds("run-up", rotor, 120.0, 1800.0, 41, unit="rpm")
    return run_up(dataclasses.replace(case, excitations=(item,)), item)


def test_single_dof_run_up_follows_u_omega_squared_times_the_closed_form(sdof_run_up):
    frame = sdof_run_up.to_pandas()
    speeds = frame.index.to_numpy()
    omega = 2 * math.pi * speeds / 60
    ratio = speeds / 60 / NATURAL_HZ
    expected = UNBALANCE * omega ** 2 * np.array([closed_form(r) for r in ratio])
    # the rotating force drives y and z alike, x not at all
    np.testing.assert_allclose(frame["F y N"], expected, rtol=1e-6)
    np.testing.assert_allclose(frame["F z N"], expected, rtol=1e-6)
    assert frame["F x N"].max() < 1e-9 * expected.max()
    np.testing.assert_allclose(frame["excitation N"], UNBALANCE * omega ** 2, rtol=1e-12)
    np.testing.assert_allclose(frame["T z"], frame["F z N"] / frame["excitation N"], rtol=1e-12)
    np.testing.assert_allclose(frame["frequency Hz"], speeds / 60, rtol=1e-12)



def test_run_up_points_are_named_and_their_warnings_placed_in_its_speed_unit():
    rotor = RotatingForce("rotor", (0.0, 0.0, 0.0), rpm=600.0, unbalance=UNBALANCE)
    points = RunUp.speeds("run-up", rotor, 600.0, 1200.0, 3, unit="rpm").expand()
    assert [point.name for point in points] == ["run-up @ 600 rpm", "run-up @ 900 rpm", "run-up @ 1200 rpm"]
    np.testing.assert_allclose([point.frequency_hz for point in points], [10.0, 15.0, 20.0], rtol=1e-15)
    runs = [SimpleNamespace(name=point.name, frequency_hz=point.frequency_hz, warnings=["all", "one"][: i + 1])
            for i, point in enumerate(points[:2])]
    assert warning_lines(runs, unit="rpm") == ["WARNING 2 points from 600 to 900 rpm: all",
                                               "WARNING run-up @ 900 rpm: one"]
    assert warning_lines(runs)[0] == "WARNING 2 points from 10 to 15 Hz: all"

def test_former_run_up_table_names_warn_and_give_the_same_tables(sdof_run_up):
    with pytest.warns(DeprecationWarning, match=r"RunUpAnswer.frame\(\) is now to_pandas"):
        assert sdof_run_up.frame().equals(sdof_run_up.to_pandas())
    with pytest.warns(DeprecationWarning, match="modes_frame"):
        assert sdof_run_up.modes_frame().equals(sdof_run_up.modes.to_pandas())


def test_the_mounted_modes_are_marked_at_their_speed(sdof_run_up, tmp_path):
    marked = sdof_run_up.mode_speeds()
    # the translations in y and z at f_n = 10 Hz = 600 rpm lie in the range
    translations = [speed for _, kind, speed in marked if abs(speed - 60 * NATURAL_HZ) < 1e-3 * 60 * NATURAL_HZ]
    assert len(translations) >= 2 and all(kind == "mounted" for _, kind, _ in marked)
    damping = sdof_run_up.modes.to_pandas()["damping ratio %"]
    assert np.isclose(damping, 100 * ZETA, rtol=1e-3).sum() >= 2
    figure = sdof_run_up.plot()
    path = tmp_path / "run-up.png"
    figure.savefig(path)
    assert path.stat().st_size > 10_000


@pytest.mark.slow
def test_run_up_gives_the_single_runs_at_the_rotor_speeds(coarse_reference):
    """A run-up from the LP to the HP speed gives at those two speeds the T
    of single-frequency runs of the same imbalance plane (force given in N)."""
    template = dataclasses.replace(LP_ROTOR, name="run-up rotor", amplitude=None, unbalance=2e-3)
    item = RunUp.speeds("run-up", template, LP_ROTOR.frequency, HP_ROTOR.frequency, 6, unit="Hz")
    case = dataclasses.replace(coarse_reference, excitations=(item,))
    answer = run_up(case, item)
    singles = (dataclasses.replace(LP_ROTOR, name="at LP"),
               dataclasses.replace(LP_ROTOR, name="at HP", frequency_hz=HP_ROTOR.frequency))
    single_case = dataclasses.replace(coarse_reference, excitations=singles,
                                      analysis=dataclasses.replace(coarse_reference.analysis, method="frequency"))
    result = run_case(single_case)
    frame = answer.to_pandas()
    for name, row in (("at LP", 0), ("at HP", -1)):
        expected = result.run(name).transmissibility
        got = frame[["T x", "T y", "T z"]].to_numpy()[row]
        np.testing.assert_allclose(got, expected, rtol=2e-3, atol=1e-4 * expected.max(), err_msg=name)


def _sdof_json(tmp_path, *excitations):
    from workbook.model.codec import to_json

    case = dataclasses.replace(sdof_case(()), excitations=excitations)
    path = tmp_path / "sdof.json"
    path.write_text(to_json(case), encoding="utf-8")
    return case, path


def test_command_line_runs_an_imbalance_up_and_writes_table_and_plot(tmp_path, capsys):
    import pandas as pd

    from workbook.cli.main import main

    case, path = _sdof_json(tmp_path, RotatingForce("rotor", (0.2, -0.1, 0.3), rpm=600.0, amplitude=50.0))
    csv, png = tmp_path / "run-up.csv", tmp_path / "run-up.png"
    code = main(["run-up", str(path), "--excitation", "rotor", "--unbalance", str(UNBALANCE), "--from", "5",
                 "--to", "25", "--points", "5", "--unit", "Hz", "--csv", str(csv), "--plot", str(png)])
    assert code == 0
    table = pd.read_csv(csv, index_col=0)
    omega = 2 * math.pi * table.index.to_numpy()
    expected = UNBALANCE * omega ** 2 * np.array([closed_form(f / NATURAL_HZ) for f in table.index])
    np.testing.assert_allclose(table["F z N"], expected, rtol=1e-6)
    assert png.stat().st_size > 10_000
    assert "run-up rotor run-up" in capsys.readouterr().out


@pytest.mark.parametrize("extra, words", [
    (["--from", "25", "--to", "5"], ["--to 5: expected a speed above the start (25 rpm)"]),
    (["--from", "0", "--to", "5"], ["--from 0: expected"]),
    (["--from", "5", "--to", "25", "--points", "1"], ["--points 1: expected"]),
    (["--from", "5", "--to", "25"], ["--excitation 'rotor': found no unbalance", "--unbalance KG_M"]),
    ([], ["the case has no run-up"]),
])
def test_command_line_bad_run_up_exits_2_and_writes_nothing(tmp_path, capsys, extra, words):
    from workbook.cli.main import main

    _, path = _sdof_json(tmp_path, RotatingForce("rotor", (0.2, -0.1, 0.3), rpm=600.0, amplitude=50.0))
    csv = tmp_path / "run-up.csv"
    args = ["run-up", str(path), "--csv", str(csv)] + (["--excitation", "rotor"] if extra else []) + extra
    assert main(args) == 2
    message = capsys.readouterr().err
    assert all(word in message for word in words) and "field '" not in message, message
    assert not csv.exists()


@pytest.mark.slow
def test_a_workbook_run_up_row_runs_from_the_command_line(coarse_reference, tmp_path, capsys):
    """An Excitations row with a run-up speed unit, run by ``mountwb run-up``,
    gives the run-up of the same case built in Python."""
    import pandas as pd

    from workbook.cli.main import main
    from workbook.excel.runs import RunSpec
    from workbook.excel.template import case_workbook, write_workbook
    case = coarse_reference.with_rigid_links()
    rotor = dataclasses.replace(LP_ROTOR, amplitude=None, unbalance=3e-3)
    item = RunUp.speeds("LP run-up", rotor, 600.0, 6000.0, 4, unit="rpm")
    case = dataclasses.replace(case, excitations=(item,))
    path, _ = write_workbook(case_workbook(case, (RunSpec("LP run-up", "LP run-up"),)), tmp_path / "case.xlsx")
    csv = tmp_path / "run-up.csv"
    assert main(["run-up", str(path), "--csv", str(csv)]) == 0
    table = pd.read_csv(csv, index_col=0)
    expected = run_up(case, item).to_pandas()
    np.testing.assert_allclose(table.index, [600.0, 2400.0, 4200.0, 6000.0])
    np.testing.assert_allclose(table.to_numpy(), expected.to_numpy(), rtol=1e-9)
    assert "LP run-up" in capsys.readouterr().out
