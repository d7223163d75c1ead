"""Per-hinge answers against frequency (workbook.answers.hinge_curves) and collected sweep warnings."""
import dataclasses
import json
from types import SimpleNamespace

import numpy as np
import pytest

from workbook.answers.hinge_curves import HingeCurves, hinge_curves, select_hinges
from workbook.answers.warning_groups import group_warnings, warning_lines
from workbook.cli.main import main
from workbook.errors import InputError
from workbook.model.case import RunUp, Sweep
from workbook.model.codec import to_json
from workbook.solve.pipeline import run_case
from workbook.solve.run_up import run_up


def test_warnings_are_grouped_by_text_with_count_and_frequency_range():
    runs = [SimpleNamespace(name=f"sweep @ {f:g} Hz", frequency_hz=f,
                            warnings=["mode near"] * 2 + (["gap closed"] if f > 30 else []))
            for f in np.linspace(10.0, 50.0, 25)]
    groups = group_warnings(runs)
    assert [(g.text, g.count) for g in groups] == [("mode near", 25), ("gap closed", 12)]
    lines = warning_lines(runs, "row 1")
    assert lines == ["WARNING row 1 / 25 points from 10 to 50 Hz: mode near",
                     f"WARNING row 1 / 12 points from {runs[13].frequency_hz:.6g} to 50 Hz: gap closed"]
    assert warning_lines(runs[:1]) == ["WARNING sweep @ 10 Hz: mode near"]
    assert warning_lines([SimpleNamespace(name="a", frequency_hz=5.0, warnings=[])]) == []


def test_selection_by_name_prefix_and_pylon():
    names = ["front-up-left", "front-down-left", "rear-up-left", "front"]
    assert select_hinges(names, "front-up-left") == ["front-up-left"]
    assert select_hinges(names, "front") == ["front"]                       # an exact name wins
    assert select_hinges(names, "front-") == ["front-up-left", "front-down-left"]
    assert select_hinges(names, "pylon", pylon=["rear-up-left", "front-up-left"]) == ["front-up-left", "rear-up-left"]
    with pytest.raises(InputError, match="^--hinges 'aft': expected a hinge name.*rear-up-left"):
        select_hinges(names, "aft", option="--hinges")



def test_the_force_of_hinges_together_needs_their_phases():
    curves = HingeCurves("front", ("run",), np.array([59.0]), ("front-up-left",), np.ones((1, 1, 3)), np.ones(1), None)
    with pytest.raises(InputError, match="^the force of hinges 'front' together: expected frequency-domain runs"):
        curves.group_force()

@pytest.fixture(scope="module")
def swept(coarse_reference):
    """The coarse reference mount under a 6-point sweep of its LP rotor, frequency domain."""
    sweep = Sweep.band("LP sweep", coarse_reference.excitations[0], 20.0, 300.0, 6)
    case = dataclasses.replace(coarse_reference, excitations=(sweep,))
    return case, run_case(case)


@pytest.mark.slow
def test_pylon_hinges_summed_as_vectors_are_the_pylon_curve(swept):
    _, result = swept
    curves = hinge_curves(result, "pylon")
    assert set(curves.hinges) == set(result.runs[0].pylon_hinges)
    pylon = np.array([run.pylon_amplitude for run in result.runs])
    np.testing.assert_allclose(np.abs(curves.group_force()), pylon, rtol=1e-12, atol=1e-9 * pylon.max())
    # each hinge alone is smaller than the sum of all, and T is |F| over the excitation
    front = hinge_curves(result, "front")
    assert front.hinges and all(h.startswith("front") for h in front.hinges)
    excitation = np.array([run.excitation_amplitude for run in result.runs])
    np.testing.assert_allclose(front.transmissibility(), front.amplitudes / excitation[:, None, None])
    table = front.to_pandas()
    assert table.shape == (6, 6 * len(front.hinges))
    np.testing.assert_allclose(table[(front.hinges[0], "T", "y")], front.transmissibility()[:, 0, 1])


@pytest.mark.slow
def test_run_command_prints_hinge_tables_a_plot_and_each_warning_once(swept, capsys, tmp_path):
    case, _ = swept
    path = tmp_path / "swept.json"
    path.write_text(to_json(case))
    plot = tmp_path / "front.png"
    assert main(["run", str(path), "--no-progress", "--hinges", "front-up", "--plot", str(plot)]) == 0
    out = capsys.readouterr().out
    assert "hinges 'front-up'" in out and "front-up-left:" in out and "front-up-right:" in out
    texts = [line.split(": ", 1)[1] for line in out.splitlines() if line.startswith("WARNING")]
    assert len(texts) == len(set(texts))                 # one line per distinct warning, never one per point
    assert plot.stat().st_size > 0
    assert main(["run", str(path), "--no-progress", "--json", "--hinges", "front-up-left"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert len(answer["hinges"]) == 6 and "front-up-left T x" in answer["hinges"][0]


@pytest.mark.parametrize("options, named", [(["--hinges", "aft"], "--hinges"),
                                            (["--plot", "t.png"], "--plot"),
                                            (["--compare", "complete"], "--compare"),
                                            (["--hinges", "front", "--plot", "t.pdf"], "--plot")])
def test_run_command_refuses_bad_hinge_options(options, named, capsys):
    assert main(["run", "--no-progress", *options]) == 2
    assert named in capsys.readouterr().err


@pytest.mark.slow
def test_run_up_command_gives_the_hinge_curves_of_its_speeds(coarse_reference, capsys, tmp_path):
    """mountwb run-up --hinges: a table per chosen hinge over the run-up's speeds, the same numbers as the
    hinge curves of the run-up's result, and their plot."""
    path = tmp_path / "coarse.json"
    path.write_text(to_json(coarse_reference))
    plot = tmp_path / "hinges.png"
    options = ["--excitation", "LP rotor", "--from", "2000", "--to", "4000", "--points", "3", "--unbalance", "0.01"]
    assert main(["run-up", str(path), *options, "--hinges", "front-up-left", "--hinges-plot", str(plot)]) == 0
    out = capsys.readouterr().out
    assert "hinges 'front-up-left'" in out and plot.stat().st_size > 0
    rows = out.split("front-up-left:\n", 1)[1].splitlines()[2:5]
    item = dataclasses.replace(coarse_reference.excitations[0], amplitude=None, unbalance=0.01)
    expected = hinge_curves(run_up(coarse_reference, RunUp.speeds("LP rotor run-up", item, 2000, 4000, 3, "rpm"))
                            .result, "front-up-left")
    for row, force in zip(rows, expected.amplitudes[:, 0, 2], strict=True):
        assert float(row.split()[-4]) == pytest.approx(force, rel=1e-3)       # |F| N z, printed to 4 digits
    assert main(["run-up", str(path), *options, "--hinges-plot", str(tmp_path / "x.png")]) == 2
    assert "--hinges-plot" in capsys.readouterr().err
