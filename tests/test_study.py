"""``mountwb study accuracy``: the ladder on the reference mount (HP rotor, coarse link meshes)."""
import dataclasses

import numpy as np
import pandas as pd
import pytest
from openpyxl import load_workbook

from workbook.cli.main import main
from workbook.model.codec import to_json
from workbook.studies.accuracy import REFERENCE_RUNG, SEED_RUNG

# every test reads the study the module's fixture runs once (a ladder of runs)
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def study(coarse_reference, tmp_path_factory):
    """Run the CLI once into a folder that already holds a user's accuracy-study.md."""
    folder = tmp_path_factory.mktemp("study")
    case = dataclasses.replace(coarse_reference, excitations=(coarse_reference.excitations[1],))
    path = folder / "hp.json"
    path.write_text(to_json(case))
    (folder / "accuracy-study.md").write_text("a user's notes\n")
    assert main(["study", "accuracy", str(path), "--repeats", "1", "--output", str(folder)]) == 0
    return folder


@pytest.fixture(scope="module")
def table(study):
    return pd.read_excel(study / "accuracy-study-2.xlsx", index_col=0)


def _t(table, rung, axis):
    """T of a rung from its error against the reference, relative to the reference's T."""
    return 1 + table.loc[rung, f"HP rotor T_{axis} error %"] / 100


def test_files_are_written_without_overwriting(study):
    assert (study / "accuracy-study.md").read_text() == "a user's notes\n"
    for suffix in (".md", ".png", ".xlsx"):
        assert (study / f"accuracy-study-2{suffix}").stat().st_size > 0
    assert load_workbook(study / "accuracy-study-2.xlsx").sheetnames == ["accuracy study"]
    markdown = (study / "accuracy-study-2.md").read_text()
    assert markdown.count("\n|") == 1 + 12
    assert SEED_RUNG in markdown and f"'{REFERENCE_RUNG}'" in markdown
    assert markdown.count("Low-frequency approximation (") == 2


def test_ladder_rungs_and_their_dof(table):
    assert len(table) == 12
    reference = f"{REFERENCE_RUNG} (reference)"
    assert table.loc[reference, "worst |error| %"] == 0
    fidelity = ["rigid links", "static modes only"] + [f"Craig-Bampton, {n} modes" for n in (2, 6, 12)] + [reference]
    dof = table.loc[fidelity, "DOF"].to_numpy()
    assert dof[0] == 6 + 8 * 6
    # eight flexible links, each 6 rigid-frame DOF plus 6 static modes, plus n fixed-interface modes
    np.testing.assert_array_equal(dof[1:], 6 + 8 * (12 + np.array([0, 2, 6, 12, 20])))
    # the seed study's complete-MNF model is the reference's link model, integrated in time
    assert table.loc[SEED_RUNG, "DOF"] == dof[-1]
    # the low-frequency approximation drops the fixed-interface modes of the links that meet the rule
    assert table.loc["frequency domain", "DOF"] < table.loc[SEED_RUNG, "DOF"] / 2


def test_errors_converge(table):
    # mode count: 12 fixed-interface modes are within 0.05 % of 20 in the lateral and vertical answers
    for axis in "yz":
        assert abs(_t(table, "Craig-Bampton, 12 modes", axis) - 1) < 5e-4
    # rigid links miss the thrust rods' bending (100 Hz) and overstate the heading force at 248.5 Hz
    assert table.loc["rigid links", "HP rotor T_x error %"] > 10
    # time step: the time domain converges to the frequency domain of the same model
    gaps = []
    for steps in (20, 40, 80):
        rung = f"time domain, {steps} steps/period"
        gaps.append(max(abs(_t(table, rung, a) / _t(table, "frequency domain", a) - 1) for a in "yz"))
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 0.003
    # the complete-MNF model in the time domain is the reference model up to the time-step error
    assert table.loc[SEED_RUNG, "worst |error| %"] < 1.0
    assert (table["wall time s"] > 0).all()


def test_a_workbook_run_row_is_the_studied_case():
    from pathlib import Path

    from workbook.cli.loading import load_case
    from workbook.errors import WorkbookError

    book = Path(__file__).parents[1] / "cases" / "reference.xlsx"
    case = load_case(str(book), run="HP rotor")
    assert [e.frequency for e in case.excitations] == [248.5]
    with pytest.raises(WorkbookError):
        load_case(str(book), run="no such run")
    with pytest.raises(ValueError):
        load_case(None, run="HP rotor")
