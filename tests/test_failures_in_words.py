"""Every failure in the user's words: a failed static solve says why and
what to change, Exudyn's console output never reaches stdout (so
``mountwb run --json`` always prints JSON), and a JSON file that is not a
case is bad input (exit 2), not a traceback. Real Exudyn runs on the
reference mount with rigid links."""
import dataclasses
import json

import pytest

from workbook.cli.main import main
from workbook.errors import EquilibriumError
from workbook.model.case import PointForce
from workbook.model.codec import to_dict, to_json
from workbook.model.reference import LP_ROTOR, reference_case
from workbook.solve.pipeline import run_case


@pytest.fixture(scope="module")
def rigid(coarse_reference):
    return dataclasses.replace(coarse_reference.with_rigid_links(), excitations=(LP_ROTOR,))


def _pushed(case, newtons):
    return dataclasses.replace(case, static_loads=case.static_loads + (
        PointForce("push", point=case.engine.center_of_mass, force=(0.0, 0.0, newtons)),))


@pytest.mark.slow
def test_a_push_beyond_the_limit_load_names_the_share_carried(rigid, capsys):
    """2 MN upward: in load steps the solve stops at the limit load, which
    must lie where the preloaded stiffness changes sign (between 1.8 and
    1.9 MN, tests/test_preload_stability.py)."""
    with pytest.raises(EquilibriumError, match=r"could be carried up to [\d.]+ % of their value and no further.*"
                                               r"buckles a compressed link or tips the mount") as caught:
        run_case(_pushed(rigid, 2e6))
    share = float(str(caught.value).split("carried up to ")[1].split(" %")[0]) / 100
    assert 1.8e6 < share * 2e6 < 1.9e6
    assert "STATIC SOLVER FAILED" in caught.value.detail
    assert "SOLVER" not in capsys.readouterr().out


def test_hinges_too_stiff_for_double_precision_are_named_with_advice(rigid, capsys):
    stiff = dataclasses.replace(rigid, hinges=tuple(dataclasses.replace(h, stiffness=1e13) for h in rigid.hinges))
    with pytest.raises(EquilibriumError, match=r"did not converge even on [\d.]+ % of the static loads.*stiffest "
                                               r"hinge has 1e\+13 N/m.*Lower the stiffest hinge stiffnesses"):
        run_case(stiff)
    assert capsys.readouterr().out == ""


def test_json_output_parses_and_failures_keep_stdout_clean(rigid, tmp_path, capsys):
    good = tmp_path / "good.json"
    good.write_text(to_json(rigid))
    assert main(["run", str(good), "--json", "--no-progress"]) == 0
    assert json.loads(capsys.readouterr().out)["case"] == rigid.name
    bad = tmp_path / "pushed.json"
    bad.write_text(to_json(_pushed(rigid, 2e6)))
    assert main(["run", str(bad), "--json", "--no-progress"]) == 1
    out, err = capsys.readouterr()
    assert out == "" and "numerical trouble" in err and "limit load" in err


@pytest.mark.parametrize("content, expected", [
    (lambda: to_json(reference_case().engine), "expected a JSON case (type 'Case')"),
    (lambda: json.dumps({"type": "Case", "name": "half"}), "fields ['engine', 'hinges', 'links'] missing"),
    (lambda: json.dumps(dict(to_dict(reference_case()), engine=[1, 2, 3])), "engine"),
])
def test_a_json_file_that_is_not_a_case_is_bad_input(tmp_path, capsys, content, expected):
    path = tmp_path / "not-a-case.json"
    path.write_text(content())
    assert main(["run", str(path), "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and expected in err and "Traceback" not in err
