"""Time-domain runs of the reference mount at the LP (59 Hz) and HP (248.5 Hz) rotor speeds."""
import dataclasses
import json

import matplotlib
import numpy as np
import pytest

from workbook.answers.results import PYLON_SUM
from workbook.scene.build import reduce_links
from workbook.solve.pipeline import run_case

matplotlib.use("Agg")

# The coarse reference mount of conftest (coarse link meshes, short runs):
# the checks compare runs with each other.


@pytest.fixture(scope="module")
def reference(coarse_reference):
    return dataclasses.replace(coarse_reference, analysis=dataclasses.replace(coarse_reference.analysis, method="time"))


@pytest.fixture(scope="module")
def result(reference):
    return run_case(reference)


def test_mount_isolates_both_rotors(result):
    table = result.to_pandas("efficiency")
    assert list(table.index) == ["LP rotor", "HP rotor"]
    for run in result.runs:
        assert run.steady, run.warnings
        assert not run.warnings
        # mounted modes at 4.7-26 Hz: both rotors run far above them
        assert np.all(run.transmissibility < 0.1), run.name
        assert np.all(run.transmissibility > 1e-5), run.name
    # the vertical pylon force is the largest share at both speeds
    assert np.argmax(result.run("LP rotor").pylon_amplitude[1:]) == 1


def test_pylon_sum_is_the_vector_sum_of_pylon_side_hinges(result):
    run = result.run("HP rotor")
    assert set(run.pylon_hinges) == {"front-up-left", "front-up-right", "rear-up-left", "rear-up-right",
                                     "rear-up-middle", "rear-up-lateral"}
    total = sum(run.hinge_histories[name] for name in run.pylon_hinges)
    np.testing.assert_allclose(run.pylon_history, total)
    # amplitudes of a sum are at most the sum of the amplitudes
    assert np.all(run.pylon_amplitude <= sum(run.hinge_amplitudes[n] for n in run.pylon_hinges) + 1e-9)


@pytest.mark.slow
def test_halving_the_time_step_changes_transmissibility_by_less_than_half_a_percent(reference, result):
    finer = dataclasses.replace(reference, analysis=dataclasses.replace(reference.analysis, steps_per_period=80))
    fine = run_case(finer)
    for coarse_run, fine_run in zip(result.runs, fine.runs, strict=True):
        change = fine_run.transmissibility / coarse_run.transmissibility - 1
        assert np.all(np.abs(change) < 0.005), (coarse_run.name, change)


def _short_links_with(case, modes):
    """Front and rear links with *modes*; the thrust rods (below the
    low-frequency rule) rigid in both variants."""
    links = tuple(dataclasses.replace(link, flexible=False) if link.name.startswith("thrust")
                  else dataclasses.replace(link, modes=modes) for link in case.links)
    return dataclasses.replace(case, links=links)


@pytest.mark.slow
def test_static_modes_match_twenty_fixed_interface_modes_where_the_rule_holds(reference):
    static_case = _short_links_with(reference, "static")
    modal_case = _short_links_with(reference, 20)
    for excitation in static_case.excitations:
        reduced = reduce_links(static_case, excitation)
        for name, link in reduced.items():
            if not name.startswith("thrust"):
                assert excitation.frequency < link.decision.fundamental_hz / 4, name
    static = run_case(static_case)
    modal = run_case(modal_case)
    assert modal.model_cards["HP rotor"].total_dof == static.model_cards["HP rotor"].total_dof + 6 * 20
    for static_run, modal_run in zip(static.runs, modal.runs, strict=True):
        change = static_run.transmissibility / modal_run.transmissibility - 1
        assert np.all(np.abs(change) < 0.01), (static_run.name, change)


def test_result_tabulates_and_serialises(result):
    frame = result.to_pandas("all")
    assert len(frame) == 2 * (16 + 1) * 3
    pylon = frame[(frame.location == PYLON_SUM) & (frame.run == "HP rotor")].set_index("direction")
    run = result.run("HP rotor")
    np.testing.assert_allclose(pylon["T"].to_numpy(), run.transmissibility)
    np.testing.assert_allclose(pylon["eta %"].to_numpy(), 100 * (1 - run.transmissibility))
    data = json.loads(result.to_json())
    assert data["runs"][1]["pylon"]["z"]["efficiency_pct"] == pytest.approx(run.efficiency[2])
    card = data["runs"][1]["model_card"]
    assert card["total_dof"] == sum(body["dof"] for body in card["bodies"])
    assert {e["name"]: e["on"] for e in card["effects"]}["hinge clearance"] is False
    assert result.preloads[result.run().name].to_pandas().loc[PYLON_SUM, "Fx N"] == pytest.approx(23_000.0, rel=1e-6)


def test_result_plots_itself(result):
    figures = [result.plot_time_histories("LP rotor", locations=(PYLON_SUM, "front-up-left")),
               result.plot_spectra("HP rotor"), result.plot_efficiency()]
    assert [len(f.axes) for f in figures] == [4, 3, 1]
    import matplotlib.pyplot as plt

    for figure in figures:
        plt.close(figure)
