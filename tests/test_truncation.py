"""The truncation-error estimate (workbook.solve.truncation) against explicit modes and more modes."""
import dataclasses
import json

import numpy as np
import pytest

from flexbodies import STEEL, LinkGeometry, LinkModel, build_fe_model, decide_modes
from flexbodies.interfaces import rigid_motion_rows
from flexbodies.interior import InteriorSolver
from flexbodies.reduction import couple, reduce_for_decisions
from workbook.model.case import HarmonicForce
from workbook.solve.pipeline import prepare
from workbook.solve.truncation import truncation_error

LINK = LinkGeometry(length=0.30, eye_outer_radius=0.030, bore_radius=0.015, thickness=0.025,
                    shank_width=0.040, shank_thickness=0.025)


def test_residual_mass_is_the_omitted_modes_sum_and_vanishes_as_they_are_kept():
    fe, _ = build_fe_model(LinkModel(geometry=LINK, material=STEEL, element_size=0.012))
    coupled = couple(fe, "RBE2")
    solver = InteriorSolver(coupled.stiffness, coupled.mass, coupled.coupling)
    frequencies = solver.reference_frequencies()
    none, four = reduce_for_decisions(coupled, solver, [decide_modes(0, 1.0), decide_modes(4, 1.0)],
                                      frequencies, [{}, {}])
    # independent rigid motion of every FE node about the link frame's origin, in coupled coordinates
    rigid = rigid_motion_rows(fe.nodes).reshape(-1, 6)
    force = (coupled.coupling.transform.T @ (fe.mass @ rigid))[solver.interior]
    hz, modes = solver.fixed_interface_modes(4)
    participation = modes[solver.interior].T @ force
    explicit = participation.T @ (participation / (2 * np.pi * hz[:, None]) ** 2)
    # the four modes kept leave their own share out of the rigid block, and nothing else changes
    np.testing.assert_allclose(none.residual_mass[:6, :6] - four.residual_mass[:6, :6], explicit,
                               rtol=1e-6, atol=1e-9 * np.abs(explicit).max())
    for link in (none, four):
        assert link.residual_mass.shape == (6 + link.n_modes,) * 2
        assert np.linalg.eigvalsh(link.residual_mass).min() > -1e-9 * np.abs(link.residual_mass).max()
    assert np.trace(four.residual_mass[:6, :6]) < np.trace(none.residual_mass[:6, :6])


@pytest.fixture(scope="module")
def answers(coarse_reference):
    """T and its estimate of the HP rotor with static modes only and with 20 modes per link."""
    excitation = coarse_reference.excitations[1]
    found = {}
    for modes in (0, 20):
        case = dataclasses.replace(coarse_reference, links=tuple(
            dataclasses.replace(link, modes=modes) for link in coarse_reference.links))
        prepared = prepare(case, excitation)
        with prepared.scene:
            result = prepared.model.result(excitation, 0.01)
            found[modes] = result.transmissibility, truncation_error(prepared.model, excitation), prepared.model
    return excitation, found


def test_estimate_is_the_error_against_twenty_modes_and_goes_to_zero(answers):
    _, found = answers
    (t_static, estimate_static, _), (t_20, estimate_20, _) = found[0], found[20]
    true = np.abs(t_static - t_20) / t_20
    large = true > 1e-3
    assert large.any()
    ratio = estimate_static[large] / true[large]
    assert np.all((ratio > 0.5) & (ratio < 2.0)), (estimate_static, true)
    assert np.all(estimate_20 < 0.1 * np.maximum(estimate_static, 1e-4))


def test_estimate_grows_as_the_fourth_power_of_frequency(answers):
    excitation, found = answers
    model = found[0][2]
    low = [truncation_error(model, HarmonicForce("probe", excitation.point, (0.0, 1.0, 1.0), 1000.0, f))
           for f in (0.5, 1.0)]
    # quasi-static, the correction -w^4 R changes the loaded directions' T (y, z) as f^4: a factor 16
    # per octave (x, loaded only through inertia coupling, has a T of its own growing as f^2)
    np.testing.assert_allclose(low[1][1:] / low[0][1:], 16.0, rtol=0.05)


def test_compare_complete_gives_the_complete_models_curves_next_to_the_cases(answers, coarse_reference, capsys,
                                                                           tmp_path):
    from workbook.cli.main import main
    from workbook.model.codec import to_json

    excitation, found = answers
    case = dataclasses.replace(coarse_reference, excitations=(excitation,), links=tuple(
        dataclasses.replace(link, modes=0) for link in coarse_reference.links))
    path = tmp_path / "hp.json"
    path.write_text(to_json(case))
    plot = tmp_path / "fig9.png"
    assert main(["run", str(path), "--no-progress", "--json", "--hinges", "pylon", "--compare", "complete",
                 "--plot", str(plot)]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert plot.stat().st_size > 0
    for rows, (t, _, _) in ((answer["hinges"], found[0]), (answer["hinges_complete"], found[20])):
        (row,) = rows
        pylon = np.abs(sum(row[key] for key in row if key.endswith(" T x")))
        assert pylon >= t[0] * (1 - 1e-9)          # the hinges' |T| summed bound the pylon's |sum|
    assert answer["runs"][0]["truncation_error"]["x"] == pytest.approx(found[0][1][0], rel=1e-6)


def test_accuracy_target_adds_modes_until_the_estimate_is_within_it(coarse_reference, answers):
    """--accuracy: a loose target stops at the case's own modes; a tight one goes on to 20 modes per link
    (reduced for the fixture already), each step's estimate being the largest of its runs."""
    from workbook.solve.truncation import run_to_accuracy

    case = dataclasses.replace(coarse_reference, excitations=coarse_reference.excitations[1:])  # HP only
    result, steps = run_to_accuracy(case, 0.5, ladder=(20,))
    assert [s.modes for s in steps] == ["as the case says"]
    assert steps[0].estimate == pytest.approx(float(np.nanmax(result.runs[0].truncation_error)))
    result, steps = run_to_accuracy(case, steps[0].estimate / 10, ladder=(20,))
    assert [s.modes for s in steps] == ["as the case says", "20 per link"]
    assert steps[1].estimate < steps[0].estimate / 10
    assert not any("stays above" in warning for warning in result.runs[0].warnings)
    result, steps = run_to_accuracy(case, steps[1].estimate / 10, ladder=(20,))
    assert "stays above" in result.runs[0].warnings[-1]
