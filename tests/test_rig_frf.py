"""FRFs of rig records: H1 against closed-form FRFs, order tracking against a simulated run-up,
modal correlation (MAC, UFF 55, pairing) against the case's own modes."""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from test_sdof import NATURAL_HZ, sdof_case

from workbook.cli.main import main
from workbook.errors import RecordError
from workbook.model.case import RotatingForce, RunUp
from workbook.rig.frf import order_track, record_frf
from workbook.rig.modal import MeasuredModes, case_modes, identify_peaks, mac, pair_modes, read_uff_modes, shapes_at_points, write_uff_modes
from workbook.rig.records import write_record
from workbook.rig.synthetic import broadband_record, run_up_record
from workbook.solve.run_up import run_up

#: SDOF mount: natural frequency, damping ratio.
FN, ZETA = 60.0, 0.05
#: 2-DOF chain ground - k1 - m1 - k2 - m2, the force on m2, the force in k1 (and its damper) to ground.
M1, M2, K1, K2 = 1.0, 2.0, 4e5, 2e5
C1, C2 = 2 * 0.1 * math.sqrt(K1 * M1), 2 * 0.1 * math.sqrt(K2 * M2)


def sdof(frequencies):
    """Force transmissibility of a mass on a spring-damper, (k + i c w) / (k - m w^2 + i c w)."""
    ratio = np.asarray(frequencies) / FN
    return (1 + 2j * ZETA * ratio) / (1 - ratio ** 2 + 2j * ZETA * ratio)


def two_dof(frequencies):
    """Ground force per unit force on m2 of the 2-DOF chain, by Cramer's rule on the 2x2 dynamic stiffness."""
    w = 2 * np.pi * np.asarray(frequencies)
    k1, k2 = K1 + 1j * w * C1, K2 + 1j * w * C2
    a, b, d = k1 + k2 - M1 * w ** 2, -k2, k2 - M2 * w ** 2
    x1 = -b / (a * d - b * b)         # motion of m1 under a unit force on m2
    return k1 * x1


def closed_form_peaks(function, low=5.0, high=400.0):
    """Frequencies of the local maxima of ``|function(f)|`` on a 1 mHz grid, Hz."""
    grid = np.arange(low, high, 1e-3)
    values = np.abs(function(grid))
    inner = (values[1:-1] > values[:-2]) & (values[1:-1] > values[2:])
    return grid[1:-1][inner]


def frf(frequencies):
    return np.column_stack([sdof(frequencies), two_dof(frequencies), 2 * sdof(frequencies)])


@pytest.fixture(scope="module")
def clean():
    return record_frf(broadband_record(frf, duration=128.0), segment_s=2.0)


@pytest.fixture(scope="module")
def noisy():
    return record_frf(broadband_record(frf, duration=128.0, noise=0.3, seed=1), segment_s=2.0)


def test_h1_of_a_noise_free_record_is_the_closed_form_frf_with_unit_coherence(clean):
    band = clean.band(5.0, 400.0)
    exact = frf(clean.frequencies_hz[band])
    # the Hann window's leakage over a 2 s segment biases the resonance peaks by about 1.5 %
    np.testing.assert_allclose(clean.h1[band], exact, rtol=0.025)
    assert clean.coherence[band].min() > 0.98
    assert np.median(clean.coherence[band]) > 0.999
    assert clean.averages == 127


def test_h1_with_response_noise_scatters_as_its_random_error_without_bias(noisy):
    band = noisy.band(5.0, 400.0)[:, None] & (noisy.coherence > 0.5)
    exact = np.abs(frf(noisy.frequencies_hz))
    z = ((noisy.transmissibility / exact - 1) / noisy.random_error)[band]
    # eps = sqrt(1 - g2) / sqrt(2 n_d g2) is the standard deviation of |H1| / |H| - 1
    assert 0.8 < np.quantile(np.abs(z), 0.68) < 1.25
    assert np.quantile(np.abs(z), 0.95) < 2.6
    assert abs(z.mean()) < 0.2          # H1 is unbiased by noise on the response
    assert np.median(noisy.coherence[noisy.band(5.0, 400.0)]) < 0.9


def test_peak_picking_finds_the_closed_form_modes(clean):
    sdof_only = dataclasses.replace(clean, h1=clean.h1.copy())
    sdof_only.h1[:, 1] = np.nan                # x and z: the SDOF
    peaks = identify_peaks(sdof_only, 5.0, 400.0)
    # |T| peaks at r = sqrt(sqrt(1 + 8 zeta^2) - 1) / (2 zeta), 0.25 % below the natural frequency
    ratio = math.sqrt(math.sqrt(1 + 8 * ZETA ** 2) - 1) / (2 * ZETA)
    assert closed_form_peaks(sdof) == pytest.approx([FN * ratio], abs=2e-3)
    assert peaks.frequencies_hz == pytest.approx([FN * ratio], abs=0.05)
    assert peaks.damping_ratios == pytest.approx([ZETA], rel=0.1)
    chain = dataclasses.replace(clean, h1=clean.h1 * np.array([np.nan, 1, np.nan]))
    found = identify_peaks(chain, 5.0, 400.0).frequencies_hz
    assert found == pytest.approx(closed_form_peaks(two_dof), abs=0.1)


def test_an_unexcited_direction_has_no_frf_and_a_silent_excitation_is_refused():
    record = broadband_record(frf, duration=16.0)
    record.excitation[:, 1] = 0.0
    answer = record_frf(record)
    assert np.isnan(answer.h1[:, 1]).all() and not np.isnan(answer.h1[:, 0]).any()
    record.excitation[:] = 3.0
    with pytest.raises(RecordError, match="excitation x.*constant in every direction"):
        record_frf(record)
    with pytest.raises(RecordError, match="at least 4"):
        record_frf(record, segment_s=8.0)


@pytest.fixture(scope="module")
def sdof_run_up():
    case = sdof_case(())
    rotor = RotatingForce("rotor", case.engine.center_of_mass, rpm=600.0, unbalance=4e-3)
    item = RunUp.speeds("run-up", rotor, 4.0, 30.0, 105, unit="Hz")
    return run_up(dataclasses.replace(case, excitations=(item,)), item)


def test_order_track_of_a_synthetic_run_up_gives_the_simulated_run_up(sdof_run_up):
    duration = 130.0
    record = run_up_record(sdof_run_up, {f"hinge {i}": (f"hinge {i}",) for i in range(4)}, sample_rate_hz=512.0,
                           duration=duration)
    track = order_track(record, frame_s=2.0)
    speeds = sdof_run_up.frequencies
    # the rotor frequency rises linearly from 4 to 30 Hz
    np.testing.assert_allclose(track.frequency_hz, 4.0 + 26.0 * track.time_s / duration, atol=0.005)
    excitation = np.interp(track.frequency_hz, speeds, [r.excitation_amplitude for r in sdof_run_up.result.runs])
    np.testing.assert_allclose(track.excitation_amplitude, excitation, rtol=0.005)   # U w^2
    simulated = sdof_run_up.transmissibility()
    expected = np.column_stack([np.interp(track.frequency_hz, speeds, simulated[:, a]) for a in (1, 2)])
    error = np.abs(track.transmissibility[:, 1:] / expected - 1).max(axis=1)
    away = np.abs(track.frequency_hz - NATURAL_HZ) > 3.0
    assert error[away].max() < 0.005
    # at resonance a 2 s frame averages the response over 0.4 Hz of speed (half-power band 1 Hz)
    assert error.max() < 0.06
    peak = track.frequency_hz[np.argmax(track.pylon_amplitude[:, 2])]
    assert peak == pytest.approx(speeds[np.argmax(sdof_run_up.pylon_amplitudes()[:, 2])], abs=0.15)
    assert track.pylon_amplitude[:, 0].max() < 1e-6 * track.pylon_amplitude[:, 2].max()


def test_mac_is_one_for_proportional_shapes_and_zero_for_orthogonal_ones():
    rng = np.random.default_rng(0)
    shape = rng.normal(size=9)
    other = rng.normal(size=9)
    other -= shape * (shape @ other) / (shape @ shape)
    assert mac(shape, (2 - 3j) * shape)[0, 0] == pytest.approx(1.0, abs=1e-12)
    assert mac(shape, other)[0, 0] == pytest.approx(0.0, abs=1e-12)
    assert mac(np.eye(3), np.eye(3)) == pytest.approx(np.eye(3))


def test_rigid_shapes_at_points_move_a_point_as_the_rotation_turns_it():
    center = np.array([1.0, 0.0, 0.0])
    roll = np.array([[0, 0, 0, 1e-3, 0, 0]])        # 1 mrad about x
    shapes = shapes_at_points(roll, center, {7: np.array([1.0, 0.0, 2.0])}, [(7, 0), (7, 1), (7, 2), (7, 3)])
    np.testing.assert_allclose(shapes, [[0.0, -2e-3, 0.0, 1e-3]], atol=1e-15)


def test_uff_modes_written_by_pyuff_read_back(tmp_path):
    rng = np.random.default_rng(2)
    points = {3: np.array([0.0, 0.1, 0.6]), 8: np.array([-1.6, -0.3, 0.4])}
    dofs = [(node, dof) for node in points for dof in range(6)]
    modes = MeasuredModes(np.array([4.7, 8.4]), np.array([0.02, 0.03]), rng.normal(size=(2, 12)), dofs, points, "t")
    back = read_uff_modes(write_uff_modes(tmp_path / "modes.uff", modes))
    np.testing.assert_allclose(back.frequencies_hz, modes.frequencies_hz, rtol=1e-5)
    np.testing.assert_allclose(back.damping_ratios, modes.damping_ratios, rtol=1e-5)
    np.testing.assert_allclose(back.shapes, modes.shapes, rtol=1e-5, atol=1e-5)
    assert back.dofs == dofs and back.points.keys() == points.keys()


def test_complex_uff_modes_give_frequency_and_damping_from_the_eigenvalue(tmp_path):
    import pyuff

    zeta, f = 0.05, 12.0
    eigenvalue = 2 * np.pi * f * (-zeta + 1j * math.sqrt(1 - zeta ** 2))
    shape = np.array([1 + 0.1j, 0.5, -0.2j])
    sets = [pyuff.prepare_15(node_nums=[1], def_cs=[0], disp_cs=[0], color=[1], x=[0.0], y=[0.0], z=[1.0]),
            pyuff.prepare_55(id1="complex mode", model_type=1, analysis_type=3, data_ch=2, spec_data_type=8,
                             data_type=5, n_data_per_node=3, load_case=1, mode_n=1, eig=eigenvalue, modal_a=1 + 0j,
                             modal_b=0j, node_nums=np.array([1]), r1=shape[:1], r2=shape[1:2], r3=shape[2:])]
    path = tmp_path / "complex.uff"
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
    modes = read_uff_modes(path)
    assert modes.frequencies_hz == pytest.approx([f], rel=1e-5)
    assert modes.damping_ratios == pytest.approx([zeta], rel=1e-4)
    assert mac(modes.shapes, shape)[0, 0] == pytest.approx(1.0, abs=1e-9)


def test_a_node_without_coordinates_is_refused_naming_it(tmp_path):
    import pyuff

    sets = [pyuff.prepare_55(id1="m", model_type=1, analysis_type=2, data_ch=2, spec_data_type=8, data_type=2,
                             n_data_per_node=3, load_case=1, mode_n=1, freq=5.0, modal_m=1.0, modal_damp_vis=0.0,
                             modal_damp_his=0.0, node_nums=np.array([4]), r1=[1.0], r2=[0.0], r3=[0.0])]
    path = tmp_path / "bare.uff"
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
    with pytest.raises(RecordError, match="node 4 has no coordinates"):
        read_uff_modes(path)


@pytest.fixture(scope="module")
def reference_modes(coarse_reference):
    case = coarse_reference.with_rigid_links()
    return case, case_modes(case, 40.0)


def test_pairing_recovers_the_case_modes_from_a_perturbed_shuffled_test_set(reference_modes, tmp_path):
    case, modes = reference_modes
    assert len(modes) == 6
    points = {k: np.array(p) for k, (p, _) in enumerate(case.engine_eyes(), start=1)}
    dofs = [(node, dof) for node in points for dof in range(3)]
    simulated = shapes_at_points(np.array([m.engine_shape for m in modes]), np.array(case.engine.center_of_mass),
                                 points, dofs)
    rng = np.random.default_rng(3)
    order = rng.permutation(6)
    factors = 1 + rng.uniform(-0.05, 0.05, 6)
    frequencies = np.array([m.frequency_hz for m in modes])
    noise = 0.03 * rng.normal(size=simulated.shape) * np.abs(simulated).max(axis=1, keepdims=True)
    test = MeasuredModes(frequencies[order] * factors, np.full(6, 0.02), (simulated + noise)[order], dofs, points, "t")
    pairing = pair_modes(read_uff_modes(write_uff_modes(tmp_path / "test.uff", test)), frequencies, simulated)
    assert pairing.pairs == [(i, int(order[i])) for i in range(6)]
    table = pairing.to_pandas()
    # UFF 55 holds the frequencies to 6 digits
    np.testing.assert_allclose(table["error %"], 100 * (1 / factors - 1), atol=1e-3)
    assert table["MAC"].min() > 0.98
    # without shapes, by frequency: right where the perturbation keeps the order
    by_frequency = pair_modes(dataclasses.replace(test, shapes=None), frequencies)
    assert len(by_frequency.pairs) == 6 and by_frequency.mac is None


@pytest.mark.parametrize(("band", "message"), [
    (["200", "10"], "--band 200 10: expected LOW < HIGH"),
    (["2000", "3000"], "--band 2000 3000: no frequency of the H1 in it; it has 1 to 1024 Hz"),
])
def test_rig_frf_refuses_a_band_without_frequencies(band, message, capsys):
    record = Path(__file__).resolve().parents[1] / "cases" / "reference-lp-rig.csv"
    assert main(["rig", "frf", str(record), "--band", *band]) == 2
    assert message in capsys.readouterr().err


def test_rig_frf_and_modes_commands(reference_modes, tmp_path, capsys):
    record = write_record(tmp_path / "shaker.csv", broadband_record(frf, duration=16.0, noise=0.1))
    assert main(["rig", "frf", str(record), "--json", "--band", "10", "200", "--output", str(tmp_path / "h1.png")]) == 0
    output = json.loads(capsys.readouterr().out.split("FRF plot")[0])
    assert output["averages"] == 31 and min(output["T"]["frequency_hz"]) >= 10
    assert (tmp_path / "h1.png").stat().st_size > 10_000
    from workbook.model.codec import to_json

    case, modes = reference_modes
    case_file = tmp_path / "case.json"
    case_file.write_text(to_json(case))       # the coarse links' reductions are in the session's cache
    points = {k: np.array(p) for k, (p, _) in enumerate(case.engine_eyes(), start=1)}
    dofs = [(node, dof) for node in points for dof in range(3)]
    shapes = shapes_at_points(np.array([m.engine_shape for m in modes]), np.array(case.engine.center_of_mass),
                              points, dofs)
    test = write_uff_modes(tmp_path / "modes.uff", MeasuredModes(np.array([m.frequency_hz for m in modes]),
                                                             np.full(6, 0.02), shapes, dofs, points))
    assert main(["rig", "modes", str(case_file), "--test", str(test), "--output", str(tmp_path / "mac.png"),
                 "--json"]) == 0
    printed = json.loads(capsys.readouterr().out.split("MAC plot")[0])
    assert [row["sim mode"] for row in printed["pairs"]] == [1, 2, 3, 4, 5, 6]
    assert np.diag(printed["MAC"]) == pytest.approx(1.0)
    assert (tmp_path / "mac.png").stat().st_size > 5_000
    assert main(["rig", "modes", str(case_file), "--record", str(record)]) == 0
    assert "peaks of the H1: 1 test modes" in capsys.readouterr().out   # the 60 Hz SDOF peak (1 Hz resolution)
