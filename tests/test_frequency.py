"""The frequency-domain answer against the time domain, a closed form and a free-vibration run."""
import dataclasses

import numpy as np
import pytest
import scipy.linalg as sla
from test_sdof import NATURAL_HZ, closed_form, sdof_case

from workbook.answers.results import PYLON_SUM
from workbook.model.case import AnalysisSettings, Effects, Sweep
from workbook.scene.build import build_scene, reduce_links
from workbook.solve.method import choose_method
from workbook.solve.modes import mounted_modes
from workbook.solve.pipeline import prepare, run_case
from workbook.solve.preload import solve_preload
from workbook.solve.sweep import run_sweep
from workbook.solve.time_domain import TimePlan, integrate

# the coarse reference mount of conftest: coarse link meshes, short but steady time runs


@pytest.fixture(scope="module")
def reference(coarse_reference):
    return coarse_reference


def _with_method(case, method):
    return dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method=method))


@pytest.mark.slow
def test_frequency_domain_matches_time_domain_on_the_reference_mount(reference):
    time_result = run_case(_with_method(reference, "time"))
    frequency_result = run_case(_with_method(reference, "frequency"))
    for name in ("LP rotor", "HP rotor"):
        td, fd = time_result.run(name), frequency_result.run(name)
        assert td.steady
        np.testing.assert_allclose(fd.transmissibility, td.transmissibility, rtol=0.01, err_msg=name)
        # the pylon-side hinges carrying most of the force agree too
        for hinge in td.pylon_hinges:
            large = td.hinge_amplitudes[hinge] > 0.05 * td.pylon_amplitude.max()
            np.testing.assert_allclose(fd.hinge_amplitudes[hinge][large], td.hinge_amplitudes[hinge][large],
                                       rtol=0.02, err_msg=f"{name} {hinge}")
    card = frequency_result.model_cards["HP rotor"].to_dict()
    effects = {e["name"]: e for e in card["effects"]}
    assert effects["frequency domain"]["on"] and not effects["time domain"]["on"]
    assert "exact" in effects["frequency domain"]["detail"]
    assert card["total_dof"] == time_result.model_cards["HP rotor"].total_dof


def test_single_dof_sweep_matches_the_closed_form(cache_dir):
    case = sdof_case(())
    sweep = Sweep.band("sweep", sdof_case((1.0,)).excitations[0], 0.1 * NATURAL_HZ, 20 * NATURAL_HZ, 60)
    case = dataclasses.replace(case, excitations=(sweep,), analysis=AnalysisSettings(method="auto"))
    assert choose_method(case).method == "frequency"
    result = run_case(case)
    assert len(result.runs) == 60
    for run in result.runs:
        expected = closed_form(run.frequency_hz / NATURAL_HZ)
        assert run.transmissibility[1] == pytest.approx(expected, rel=0.005), run.name
        assert run.transmissibility[2] == pytest.approx(expected, rel=0.005), run.name
        assert run.transmissibility[0] < 1e-9
    # the three translations of the mass are its mounted modes at the natural frequency
    card = result.model_cards[result.runs[0].name]
    translations = sorted(f for f, _, motion in card.mounted_modes if "translation" in motion)
    np.testing.assert_allclose(translations, [NATURAL_HZ] * 3, rtol=1e-6)


def test_auto_takes_the_time_domain_when_clearance_makes_the_scene_nonlinear():
    case = sdof_case((1.0,))
    gapped = dataclasses.replace(case, analysis=AnalysisSettings(method="auto"),
                                 hinges=tuple(dataclasses.replace(h, radial_clearance=1e-4) for h in case.hinges))
    choice = choose_method(gapped)
    assert choice.method == "time" and "clearance" in choice.reason
    no_gaps = dataclasses.replace(gapped, effects=Effects(clearance=False))
    assert choose_method(no_gaps).method == "frequency"
    forced = dataclasses.replace(gapped, analysis=AnalysisSettings(method="frequency"))
    assert choose_method(forced).method == "frequency" and "approximation" in choose_method(forced).reason


def test_auto_is_the_default_and_a_linear_sweep_takes_one_linearisation_whatever_is_asked():
    """The default answers a linear scene in the frequency domain and says so on the card and in the JSON; a
    sweep asked for in the time domain on a linear scene still takes one linearisation (its T is the closed
    form, which a time run per point would give only to the time-step error)."""
    import json

    case = sdof_case((3.0,))
    assert AnalysisSettings().method == "auto"
    result = run_case(dataclasses.replace(case, analysis=AnalysisSettings()))
    card = result.model_cards["r = 3"]
    assert card.method == "frequency" and card.method_reason.startswith("auto: the scene is linear")
    assert f"Method: frequency domain ({card.method_reason})" in card.to_text()
    answer = json.loads(result.to_json())["runs"][0]["model_card"]["method"]
    assert answer == {"analysis": "frequency domain", "reason": card.method_reason}
    assert result.run("r = 3").transmissibility[2] == pytest.approx(closed_form(3.0), rel=1e-6)
    sweep = Sweep.band("sweep", case.excitations[0], 0.5 * NATURAL_HZ, 3 * NATURAL_HZ, 5)
    timed = dataclasses.replace(case, excitations=(sweep,), analysis=AnalysisSettings(method="time"))
    swept = run_case(timed)
    assert {c.method for c in swept.model_cards.values()} == {"frequency"}
    assert all("a sweep on a linear scene" in c.method_reason for c in swept.model_cards.values())
    for run in swept.runs:
        assert run.transmissibility[2] == pytest.approx(closed_form(run.frequency_hz / NATURAL_HZ), rel=1e-6)
    gapped = dataclasses.replace(timed, hinges=tuple(dataclasses.replace(h, radial_clearance=1e-4) for h in case.hinges))
    assert choose_method(gapped, sweep=True).method == "time"


def _spectral_peak(time, signal):
    """Frequency of the largest peak: Hann window, zero padding, parabolic refinement, Hz."""
    values = (signal - signal.mean()) * np.hanning(len(signal))
    size = 64 * len(values)
    spectrum = np.abs(np.fft.rfft(values, size))
    k = int(np.argmax(spectrum[1:])) + 1
    a, b, c = np.log(spectrum[k - 1:k + 2])
    shift = 0.5 * (a - c) / (a - 2 * b + c)
    return (k + shift) / (size * (time[1] - time[0]))


@pytest.mark.slow
def test_mounted_modes_match_a_free_vibration_run(reference):
    """Undamped scene, preloaded; started with the velocity of one mounted mode,
    it vibrates at that mode's frequency (spectral peak of a hinge force)."""
    import exudyn as exu

    undamped = dataclasses.replace(reference, effects=Effects(hinge_damping=False, link_damping=False),
                                   excitations=())
    reduced = reduce_links(undamped, reference.excitations[0])
    prepared = prepare(undamped, reference.excitations[0], reduced=reduced)
    lin = prepared.model.linearization
    mounted = mounted_modes(prepared.modes)
    assert len(mounted) == 6
    eigenvalues, vectors = sla.eig(lin.stiffness, lin.mass)
    frequencies = np.sqrt(np.abs(eigenvalues.real)) / (2 * np.pi)
    for mode in mounted:
        index = int(np.argmin(np.abs(frequencies - mode.frequency_hz)))
        shape = np.real(vectors[:, index])
        # hinge force component that this mode loads most
        output = int(np.argmax(np.abs(prepared.model.stiffness_output @ shape)))
        hinge, axis = prepared.model.hinge_names[output // 3], output % 3
        scene = build_scene(undamped, reference.excitations[0], reduced=reduced)
        solve_preload(scene)
        velocity = lin.basis @ shape
        velocity *= 1e-3 / np.abs(velocity[lin.body_coordinates["engine"][:3]]).max(initial=1e-12)
        scene.mbs.systemData.SetODE2Coordinates_t(list(velocity), configuration=exu.ConfigurationType.Initial)
        steps_per_period, periods = 100, 40
        plan = TimePlan(mode.frequency_hz, 1 / (mode.frequency_hz * steps_per_period), steps_per_period,
                        0, 0, periods // 2, "free vibration")
        histories = integrate(scene, plan)
        peak = _spectral_peak(histories.time, histories.hinge_forces[hinge][:, axis])
        assert peak == pytest.approx(mode.frequency_hz, rel=0.01), (mode.description, hinge, axis)


@pytest.mark.slow
def test_sweep_tabulates_modes_and_plots(reference, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sweep = Sweep.band("sweep", reference.excitations[1], 2.0, 300.0, 200)
    answer = run_sweep(reference, sweep)
    modes = answer.modes.to_pandas()
    mounted = modes[modes.kind == "mounted"]
    assert len(mounted) == 6
    assert (mounted["damping ratio %"] > 0).all()
    # the thrust rods' first bending modes (about 100 Hz) are link modes in band
    assert (modes.kind == "link").any()
    curves = answer.to_pandas(locations=(PYLON_SUM, "front-up-left"))
    assert curves.shape == (200, 6)
    # isolation above the mounted modes: T falls well below 1 at the top of the band
    assert curves.iloc[-1][["T pylon sum y", "T pylon sum z"]].max() < 0.1
    # resonance: T exceeds 1 near a mounted mode
    assert curves[["T pylon sum y", "T pylon sum z"]].to_numpy().max() > 1.0
    figure = answer.plot(locations=(PYLON_SUM, "front-up-left"))
    figure.savefig(tmp_path / "sweep.png")
    assert len(figure.axes) == 3
    plt.close(figure)
