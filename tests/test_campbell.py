"""The Campbell diagram against closed forms: the gyroscopic split of a tilting engine, its critical
speeds, and flat lines without rotors."""
from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from test_gyroscopics import LENGTH, RADIUS, ROTOR, STIFFNESS, TRANSVERSE_INERTIA, mounted, whirl_case

from workbook.cli.main import main
from workbook.errors import EXIT_BAD_INPUT, CaseError
from workbook.model.case import RotatingForce
from workbook.model.codec import to_json
from workbook.solve.campbell import campbell

TILT_STIFFNESS = STIFFNESS * (2 * LENGTH ** 2 + 2 * RADIUS ** 2)


def _whirl_hz(speed_hz: float) -> tuple[float, float]:
    """Backward and forward tilt whirl frequencies at rotor speed *speed_hz*, Hz (see test_gyroscopics)."""
    h = ROTOR.polar_inertia * 2 * math.pi * speed_hz
    root = math.sqrt(h ** 2 + 4 * TRANSVERSE_INERTIA * TILT_STIFFNESS)
    return tuple((root + sign * h) / (2 * TRANSVERSE_INERTIA) / (2 * math.pi) for sign in (-1, 1))


@pytest.fixture(scope="module")
def diagram():
    return campbell(whirl_case(), stop_rpm=12000, points=41, orders=(1.0, 2.0))


def test_the_tilt_modes_split_into_forward_and_backward_whirl_at_every_speed(diagram):
    whirls = [diagram.branch_whirl(b) for b in range(len(diagram.descriptions))]
    forward, backward = whirls.index("forward"), whirls.index("backward")
    assert whirls.count("forward") == whirls.count("backward") == 1      # roll and translations do not whirl
    expected = np.array([_whirl_hz(rpm / 60) for rpm in diagram.speeds_rpm])
    np.testing.assert_allclose(diagram.frequencies_hz[backward], expected[:, 0], rtol=1e-6)
    np.testing.assert_allclose(diagram.frequencies_hz[forward], expected[:, 1], rtol=1e-6)
    others = [b for b in range(len(whirls)) if b not in (forward, backward)]
    assert np.ptp(diagram.frequencies_hz[others], axis=1).max() < 1e-9 * diagram.frequencies_hz.max()


def test_critical_speeds_are_the_closed_form_crossings(diagram):
    """A forward whirl at w = Omega: (I_t - I_p) Omega^2 = k_t; backward: (I_t + I_p) Omega^2 = k_t;
    2x: the same with w = 2 Omega."""
    ip, it = ROTOR.polar_inertia, TRANSVERSE_INERTIA
    for order in (1.0, 2.0):
        found = {c.whirl: c for c in diagram.crossings if c.order == order and c.whirl != "-"}
        forward = math.sqrt(TILT_STIFFNESS / (order ** 2 * it - order * ip)) / (2 * math.pi) * 60
        backward = math.sqrt(TILT_STIFFNESS / (order ** 2 * it + order * ip)) / (2 * math.pi) * 60
        assert found["forward"].speed_rpm == pytest.approx(forward, rel=1e-7)
        assert found["backward"].speed_rpm == pytest.approx(backward, rel=1e-7)
        assert found["forward"].frequency_hz == pytest.approx(order * forward / 60, rel=1e-7)
    frame = diagram.crossings_frame()
    assert list(frame["speed rpm"]) == sorted(frame["speed rpm"]) and len(frame) == len(diagram.crossings)


def test_without_rotors_the_lines_are_flat_at_the_mounted_modes_and_cross_at_60_f(tmp_path):
    imbalance = RotatingForce("fan", point=(0.3, -0.2, 0.1), amplitude=100.0, frequency_hz=20.0)
    case = dataclasses.replace(whirl_case(rotors=()), excitations=(imbalance,))
    diagram = campbell(case, stop_rpm=3000, points=7, orders=(1.0, 2.0))
    _, modes = mounted(case)
    np.testing.assert_allclose(diagram.frequencies_hz[:, 0], sorted(m.frequency_hz for m in modes), rtol=1e-9)
    assert np.ptp(diagram.frequencies_hz, axis=1).max() == 0.0
    for crossing in diagram.crossings:
        assert crossing.speed_rpm == pytest.approx(60 * crossing.frequency_hz / crossing.order, rel=1e-9)
    below = [f for f in diagram.frequencies_hz[:, 0] if f < 50.0]    # 1x reaches 50 Hz at 3000 rpm
    assert len([c for c in diagram.crossings if c.order == 1.0]) == len(below)


def test_the_command_writes_its_files_and_refuses_bad_options(tmp_path, capsys):
    path = tmp_path / "whirl.json"
    path.write_text(to_json(whirl_case()))
    plot, table = tmp_path / "campbell.png", tmp_path / "campbell.csv"
    assert main(["campbell", str(path), "--to", "1000", "--points", "11", "--json", "--plot", str(plot),
                 "--csv", str(table), "--operating", "300:900"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["reference rotor"] == "rotor" and len(answer["speeds rpm"]) == 11
    assert {c["whirl"] for c in answer["critical speeds"]} >= {"forward", "backward"}
    assert plot.stat().st_size > 0 and table.read_text().startswith("branch,speed rpm,frequency Hz")
    for bad, words in ((["--rotor", "HP"], "one of rotor"), (["--operating", "900:300"], "--operating"),
                       (["--orders", "1,x"], "--orders"), (["--plot", str(tmp_path / "c.pdf")], "expected a file ending in .png")):
        assert main(["campbell", str(path), "--points", "3", *bad]) == EXIT_BAD_INPUT
        assert words in capsys.readouterr().err
    assert not (tmp_path / "c.pdf").exists()
    with pytest.raises(SystemExit) as stopped:
        main(["campbell", str(path), "--up-to", "-3"])
    assert stopped.value.code == EXIT_BAD_INPUT
    assert "argument --up-to: expected a number > 0, found '-3'" in capsys.readouterr().err
    table.write_text("a table of the user's")              # an existing file of the output's name is kept
    assert main(["campbell", str(path), "--to", "1000", "--points", "3", "--csv", str(table)]) == 0
    assert table.read_text() == "a table of the user's"
    beside = [p for p in tmp_path.glob("campbell-campbell-*.csv")]
    assert len(beside) == 1 and beside[0].read_text().startswith("branch,speed rpm,frequency Hz")
    with pytest.raises(CaseError, match="a rotor or a rotating excitation"):
        campbell(whirl_case(rotors=()))
