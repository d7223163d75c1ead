"""Counts on the command line (processes, starts, periods, iterations, generations) are whole numbers >= 1:
anything else is a usage error, exit 2, before any work, naming the option and what was found."""
from pathlib import Path

import pytest

from workbook.cli.main import main

RECORD = str(Path(__file__).resolve().parents[1] / "cases" / "reference-lp-rig.csv")


@pytest.mark.parametrize("args, found", [
    (["optimise", "--vary", "hinge_stiffness/all=1e7:5e7", "--workers", "0"], "found 0"),
    (["optimise", "--vary", "hinge_stiffness/all=1e7:5e7", "--starts", "-1"], "found -1"),
    (["study", "params", "--vary", "hinge_stiffness=1e7,2e7", "--workers", "two"], "found 'two'"),
    (["study", "uq", "--param", "hinge_stiffness=uniform:1e7:2e7", "--workers", "0"], "found 0"),
    (["rig", "measure", RECORD, "--periods", "0"], "found 0"),
    (["rig", "compare", RECORD, "--periods", "-3"], "found -3"),
    (["update", "--record", RECORD, "--vary", "hinge_stiffness/front=1e7:5e7", "--periods", "0"], "found 0"),
    (["optimise", "--vary", "hinge_stiffness/all=1e7:5e7", "--iterations", "-1"], "found -1"),
    (["optimise", "--vary", "hinge_stiffness/all=1e7:5e7", "--pareto", "--population", "0"], "found 0"),
    (["optimise", "--vary", "hinge_stiffness/all=1e7:5e7", "--pareto", "--generations", "0"], "found 0"),
])
def test_a_count_below_one_is_refused_before_any_work(args, found, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as stopped:
        main(args)
    assert stopped.value.code == 2
    error = capsys.readouterr().err
    option = args[-2]
    assert f"argument {option}: expected a whole number >= 1, {found}" in error
    assert list(tmp_path.iterdir()) == []
