"""Limit load cases (workbook.solve.load_cases): equilibrium, fail-safe, stresses, bad input, the command."""
import dataclasses
import json

import numpy as np
import pytest

from workbook.cli.main import main
from workbook.errors import EXIT_BAD_INPUT, CaseError
from workbook.model.case import PointForce
from workbook.model.codec import from_json, to_json
from workbook.model.load_cases import STANDARD_GRAVITY, LoadCase
from workbook.scene.build import reduce_links
from workbook.solve.load_cases import solve_load_cases

MANOEUVRE = LoadCase("manoeuvre", thrust=60e3, load_factors=(0.5, 1.0, -2.5), torque=20e3,
                     forces=(PointForce("inlet", (0.0, 0.0, -5e3), (1.2, 0.0, 0.0)),), factor_of_safety=1.5)
FAIL_SAFE = LoadCase("fail-safe", thrust=60e3, without_link="rear-middle")


@pytest.fixture(scope="module")
def solved(coarse_reference):
    case = dataclasses.replace(coarse_reference, load_cases=(MANOEUVRE, FAIL_SAFE))
    reduced = reduce_links(case)
    return case, reduced, solve_load_cases(case)


@pytest.mark.slow
def test_load_case_forces_sum_to_the_applied_load(solved):
    case, reduced, (manoeuvre, fail_safe) = solved
    mass = case.engine.mass + sum(link.mass for link in reduced.values())
    applied = np.array([60e3, 0.0, -5e3]) + mass * STANDARD_GRAVITY * np.array([0.5, 1.0, -2.5])
    np.testing.assert_allclose(manoeuvre.applied_force, applied, rtol=1e-9)
    np.testing.assert_allclose(manoeuvre.pylon_force, applied, rtol=1e-6)
    pylon = sum(force for name, force in manoeuvre.hinge_forces.items() if name.startswith(("front-up", "rear-up")))
    np.testing.assert_allclose(pylon, applied, rtol=1e-6)
    # fail-safe: the link and its hinges are gone, the rest carries the load
    assert "rear-middle" not in fail_safe.links and not any("middle" in name for name in fail_safe.hinge_forces)
    np.testing.assert_allclose(fail_safe.pylon_force, fail_safe.applied_force, atol=1e-6 * np.linalg.norm(fail_safe.applied_force))
    assert np.linalg.norm(manoeuvre.engine_displacement) > 0


@pytest.mark.slow
def test_link_stresses_and_margins(solved):
    case, _, (manoeuvre, _) = solved
    for name, stress in manoeuvre.links.items():
        geometry = case.link_map[name].model.geometry
        area = geometry.shank_width * geometry.shank_thickness
        assert stress.nominal_stress == pytest.approx(stress.axial_force / area, rel=1e-6)    # two-force member
        assert stress.von_mises >= abs(stress.nominal_stress) * 0.99
        assert stress.von_mises_region in ("eye A", "shank", "eye B")
        material = case.link_map[name].model.material
        assert stress.yield_margin == pytest.approx(material.yield_strength / stress.von_mises - 1)
        assert stress.ultimate_margin == pytest.approx(material.ultimate_strength / (1.5 * stress.von_mises) - 1)
        # the peak's point lies on the link, between its eyes (within an eye radius)
        a, b = np.array(case.link_map[name].end_a), np.array(case.link_map[name].end_b)
        t = (np.array(stress.von_mises_point) - a) @ (b - a) / np.linalg.norm(b - a) ** 2
        assert -0.5 < t < 1.5
    assert manoeuvre.stress_seconds < 1.0
    assert json.loads(json.dumps(manoeuvre.to_dict()))["links"]


def test_bad_load_cases_name_the_item(coarse_reference):
    with pytest.raises(CaseError, match="factor_of_safety"):
        LoadCase("limit", factor_of_safety=-1.5)
    with pytest.raises(CaseError, match="load case 'limit'.*factor_of_safety"):
        LoadCase("limit", factor_of_safety=0.9)
    with pytest.raises(CaseError, match="load case 'gone'.*without_link.*'no-such-link'"):
        dataclasses.replace(coarse_reference, load_cases=(LoadCase("gone", without_link="no-such-link"),))
    with pytest.raises(CaseError, match="load_factors"):
        LoadCase("limit", load_factors=(0.0, 1.0))
    with pytest.raises(CaseError, match="forces"):
        LoadCase("limit", forces=((1.0, 2.0, 3.0),))


def test_load_cases_survive_json(coarse_reference):
    case = dataclasses.replace(coarse_reference, load_cases=(MANOEUVRE, FAIL_SAFE))
    assert from_json(to_json(case)).load_cases == case.load_cases
    assert case.without_link("rear-middle").load_cases == (MANOEUVRE,)


@pytest.mark.slow
def test_the_command_prints_the_tables_and_refuses_bad_input(coarse_reference, tmp_path, capsys):
    path = tmp_path / "case.json"
    path.write_text(to_json(dataclasses.replace(coarse_reference, load_cases=(FAIL_SAFE,))))
    assert main(["loads", str(path)]) == 0
    out = capsys.readouterr().out
    assert "fail-safe: rear-middle removed" in out and "thrust-left" in out and "MS_u" in out
    assert main(["loads", str(path), "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["load_cases"][0]["without_link"] == "rear-middle"
    assert main(["loads", str(path), "--load-case", "nothing"]) == EXIT_BAD_INPUT
    bad = json.loads(path.read_text())
    bad["load_cases"][0]["factor_of_safety"] = -1
    path.write_text(json.dumps(bad))
    assert main(["loads", str(path)]) == EXIT_BAD_INPUT
    assert "factor_of_safety" in capsys.readouterr().err
