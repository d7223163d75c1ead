"""Measured rig records: the synthetic record's known T is recovered; bad records are refused."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import COARSE_ELEMENT_SIZE

from workbook.cli.main import main
from workbook.errors import RecordError
from workbook.model.case import AnalysisSettings
from workbook.model.reference import LP_ROTOR, reference_case
from workbook.rig.correlation import comparison_frame, force_amplitude, measure
from workbook.rig.records import read_record, write_record
from workbook.rig.synthetic import REFERENCE_TRANSDUCERS, synthetic_record
from workbook.solve.pipeline import run_excitation

CASES = Path(__file__).resolve().parents[1] / "cases"
#: Short, steady runs on rigid links.
SHORT = AnalysisSettings(settle_time=0.2, measured_periods=10)


@pytest.fixture(scope="module")
def lp_run(cache_dir):
    # the former viscous hinge damping: a short, cheap time run whose lateral pylon force
    # (T_y 0.0012) is not the deeper cancellation of the loss-factor mount (0.0004)
    case = reference_case(analysis=SHORT, element_size=COARSE_ELEMENT_SIZE,
                          hinge_damping="viscous").with_rigid_links()
    return run_excitation(case, LP_ROTOR)


def test_clean_record_gives_the_simulated_transmissibility(lp_run, tmp_path):
    record = synthetic_record(lp_run, REFERENCE_TRANSDUCERS, noise=0.0, drift=0.0)
    measurement = measure(read_record(write_record(tmp_path / "clean.csv", record)), periods=20)
    assert measurement.frequency_hz == pytest.approx(59.0, rel=1e-6)
    # the window spans 20 periods to within one sample (34.7 samples per period): 1e-3
    assert measurement.excitation_amplitude == pytest.approx(1000.0, rel=1e-3)
    # the transducers' sum is the pylon force, whatever the grouping
    np.testing.assert_allclose(measurement.transmissibility, lp_run.transmissibility, rtol=1e-3)
    front = measurement.transducer_amplitudes["front-left"]
    np.testing.assert_allclose(front, lp_run.hinge_amplitudes["front-up-left"], rtol=1e-3, atol=1e-3)


def test_noisy_drifting_record_recovers_t_where_the_pylon_force_is_not_a_cancellation(lp_run, tmp_path):
    record = synthetic_record(lp_run, REFERENCE_TRANSDUCERS, duration=2.0, noise=0.03, drift=0.002, seed=1)
    periods = 50
    measurement = measure(read_record(write_record(tmp_path / "rig.csv", record)), periods=periods)
    # the rotor speed found: the mean speed over the two measured windows at the record's end
    duration, start = 2.0, 2.0 - 2 * periods / 59.0
    expected = 59.0 * (1 + 0.002 * ((start + duration) / (2 * duration) - 0.5))
    assert measurement.frequency_hz == pytest.approx(expected, abs=0.005)
    error = (measurement.transmissibility - lp_run.transmissibility) / lp_run.transmissibility
    # x (heading) and z (vertical): T of 0.037 and 0.019, within 1 %
    assert abs(error[0]) < 0.01 and abs(error[2]) < 0.01, error
    # y (lateral) nearly cancels at the pylon (T 0.0012, 1.2 N against 40 N per front transducer):
    # 3 % transducer noise leaves several % there
    assert abs(error[1]) < 0.15, error
    table = comparison_frame(measurement, lp_run)
    assert table.loc["z", "error %"] == pytest.approx(-100 * error[2] / (1 + error[2]), rel=1e-9)
    # the DFT at the nominal 59 Hz, 0.009 Hz below the mean speed of the windows: T (a ratio) hardly moves
    nominal = measure(record, periods=periods, search=0.0)
    assert nominal.frequency_hz == 59.0
    np.testing.assert_allclose(nominal.transmissibility[[0, 2]], measurement.transmissibility[[0, 2]], rtol=2e-3)


def test_the_synthetic_record_recovers_t_within_one_percent(lp_run, tmp_path):
    # the default record: 4 s at 2048 Hz, 0.5 % transducer noise, 0.2 % speed drift
    record = synthetic_record(lp_run, REFERENCE_TRANSDUCERS)
    measurement = measure(read_record(write_record(tmp_path / "rig.csv", record)), periods=100)
    error = (measurement.transmissibility - lp_run.transmissibility) / lp_run.transmissibility
    assert np.all(np.abs(error) < 0.01), error


def test_force_amplitude_is_the_largest_magnitude_over_a_period():
    rotating = np.array([0.0, 3.0, -3.0j])
    harmonic = 5.0 * np.exp(0.3j) * np.array([0.6, 0.8, 0.0])
    assert force_amplitude(rotating) == pytest.approx(3.0)
    assert force_amplitude(harmonic) == pytest.approx(5.0)


@pytest.mark.slow
def test_committed_record_is_what_the_code_generates(tmp_path, cache_dir):
    assert main(["rig", "synthesize", str(tmp_path / "rig.csv"), "--rigid", "--rate", "2048"]) == 0
    committed, made = read_record(CASES / "reference-lp-rig.csv"), read_record(tmp_path / "rig.csv")
    assert committed.hinges == made.hinges and committed.notes == made.notes
    np.testing.assert_allclose(committed.excitation, made.excitation, atol=2e-4)
    for name, forces in made.transducers.items():
        np.testing.assert_allclose(committed.transducers[name], forces, atol=2e-4)


def _edit(path: Path, tmp_path: Path, change) -> Path:
    lines = path.read_text().splitlines()
    out = tmp_path / "edited.csv"
    out.write_text("\n".join(change(lines)) + "\n")
    return out


def _header_line(lines):
    return next(i for i, line in enumerate(lines) if not line.startswith("#"))


@pytest.fixture(scope="module")
def record_file(lp_run, tmp_path_factory):
    record = synthetic_record(lp_run, REFERENCE_TRANSDUCERS, duration=0.5)
    return write_record(tmp_path_factory.mktemp("rig") / "rig.csv", record)


def test_wrong_sample_rate_is_refused(record_file, tmp_path):
    path = _edit(record_file, tmp_path,
                 lambda lines: [line.replace("sample rate [Hz]: 2048", "sample rate [Hz]: 2000") for line in lines])
    with pytest.raises(RecordError, match=r"edited.csv, column 'time \[s\]': wrong sample rate: .*2000 Hz.*2048 Hz"):
        read_record(path)


def test_irregular_time_names_the_line(record_file, tmp_path):
    def change(lines):
        row = _header_line(lines) + 6
        cells = lines[row].split(",")
        cells[0] = f"{float(cells[0]) + 2e-4:.9f}"
        lines[row] = ",".join(cells)
        return lines

    with pytest.raises(RecordError) as error:
        read_record(_edit(record_file, tmp_path, change))
    header = _header_line(record_file.read_text().splitlines()) + 1
    assert error.value.line == header + 6 and error.value.column == "time [s]"
    assert "not uniformly sampled" in str(error.value)


def test_too_short_record_is_refused(record_file):
    with pytest.raises(RecordError, match=r"too short: 0\.5 s recorded, two windows of 20 periods at 59 Hz need"):
        measure(read_record(record_file), periods=20)


def test_missing_channel_and_bad_cell_name_the_column(record_file, tmp_path):
    def drop(lines):
        header = _header_line(lines)
        index = lines[header].split(",").index("rear-left z [N]")
        return lines[:header] + [",".join(c for j, c in enumerate(line.split(",")) if j != index)
                                 for line in lines[header:]]

    with pytest.raises(RecordError, match="missing channel 'rear-left z") as error:
        read_record(_edit(record_file, tmp_path, drop))
    assert error.value.column == "rear-left z"

    def garble(lines):
        row = _header_line(lines) + 3
        cells = lines[row].split(",")
        cells[2] = "n/a"
        lines[row] = ",".join(cells)
        return lines

    with pytest.raises(RecordError, match=r"line \d+, column 'front-left y \[N\]': 'n/a' is not a number"):
        read_record(_edit(record_file, tmp_path, garble))


def test_transducers_must_carry_every_pylon_hinge_once(record_file):
    record = read_record(record_file)
    case = reference_case()
    record.check_hinges([h.name for h in case.pylon_hinges])
    wrong = dataclasses.replace(record, hinges={**record.hinges, "rear-right": ("rear-up-right",)})
    with pytest.raises(RecordError, match="carried by no transducer: rear-up-lateral"):
        wrong.check_hinges([h.name for h in case.pylon_hinges])


def test_cli_exits_2_on_a_bad_record(record_file, capsys):
    assert main(["rig", "measure", str(record_file), "--periods", "20"]) == 2
    assert "too short" in capsys.readouterr().err


@pytest.mark.parametrize(("args", "message"), [
    (["synthesize", "out.csv", "--noise", "-0.01"], "argument --noise: expected a number >= 0, found '-0.01'"),
    (["synthesize", "out.csv", "--duration", "0"], "argument --duration: expected a number > 0, found '0'"),
    (["synthesize", "out.csv", "--rate", "nan"], "argument --rate: expected a number > 0, found 'nan'"),
    (["frf", str(CASES / "reference-lp-rig.csv"), "--segment", "0"], "argument --segment: expected a number > 0"),
    (["order", str(CASES / "reference-lp-rig.csv"), "--frame", "-1"], "argument --frame: expected a number > 0"),
    (["modes", "--record", str(CASES / "reference-lp-rig.csv"), "--upper", "-1"],
     "argument --upper: expected a number > 0, found '-1'"),
])
def test_a_number_out_of_range_is_refused_before_any_work(args, message, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as stopped:
        main(["rig", *args])
    assert stopped.value.code == 2 and message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_synthesize_refuses_a_sample_rate_its_record_could_not_be_measured_at(tmp_path, capsys):
    assert main(["rig", "synthesize", str(tmp_path / "slow.csv"), "--rigid", "--rate", "500"]) == 2
    assert ("--rate 500: 8.47 samples per period of 'LP rotor' at 59 Hz; a record needs at least 10 (a rate of "
            "590 Hz or more)") in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_record_saved_with_a_byte_order_mark_is_read_and_one_not_in_utf8_is_refused_by_line(record_file, tmp_path,
                                                                                               capsys):
    text = record_file.read_text()
    marked = tmp_path / "marked.csv"
    marked.write_text(text, encoding="utf-8-sig")  # as a spreadsheet saves "CSV UTF-8"
    np.testing.assert_array_equal(read_record(marked).transducers["front-left"],
                                  read_record(record_file).transducers["front-left"])
    latin = tmp_path / "latin.csv"
    latin.write_text(text.replace("# run:", "# bench: Prüfstand 3\n# run:"), encoding="latin-1")
    with pytest.raises(RecordError, match=r"latin.csv, line 2: not UTF-8 text") as error:
        read_record(latin)
    assert error.value.line == 2
    assert main(["rig", "measure", str(CASES / "reference.xlsx")]) == 2
    assert "reference.xlsx, line 1: not UTF-8 text" in capsys.readouterr().err


def _workbook_with_record(folder: Path, run_row: int, periods=50) -> Path:
    """The reference workbook with short rigid runs and a Test data row naming the committed record."""
    import shutil

    from excel_helpers import copy_reference, set_cells

    path = copy_reference(folder)
    shutil.copyfile(CASES / "reference-lp-rig.csv", folder / "rig.csv")
    set_cells(path, {("Case", "settle time", 3): SHORT.settle_time, ("Case", "measured periods", 3): 10,
                     ("Runs", "fidelity", 3): "rigid", ("Test data", "run", 3): ["LP rotor", "HP rotor"][run_row],
                     ("Test data", "rig record", 3): "rig.csv", ("Test data", "record periods", 3): periods,
                     # coarse link meshes: rigid links need only their mass properties
                     **{("Links", "element size", row): COARSE_ELEMENT_SIZE * 1000 for row in range(3, 11)}})
    return path


def test_workbook_compares_a_rig_record_in_the_result_sheets(lp_run, tmp_path):
    from openpyxl import load_workbook

    from workbook.excel.reader import read_workbook

    path = _workbook_with_record(tmp_path, 0)
    measured = measure(read_record(CASES / "reference-lp-rig.csv"), periods=50).transmissibility
    points = read_workbook(path).tests
    assert [(p.run, p.location, p.direction) for p in points] == [("LP rotor", "pylon sum", d) for d in "xyz"]
    np.testing.assert_allclose([p.amplitude for p in points], measured * 1000.0, rtol=1e-12)
    assert main(["run", str(path), "--run", "LP rotor", "--no-progress"]) == 0
    sheet = load_workbook(path)["Result efficiency"]
    header = [c.value for c in sheet[2]]
    rows = [dict(zip(header, r, strict=True)) for r in sheet.iter_rows(min_row=3, values_only=True)]
    for row, t_test in zip(rows, measured, strict=True):
        assert row["test amplitude N"] == pytest.approx(t_test * 1000.0, rel=1e-9)
        assert row["error %"] == pytest.approx((row["T"] - t_test) / t_test * 100, rel=1e-6)
    # the same answers as the record's own simulation: x and z within 1 % of the test
    assert abs(rows[0]["error %"]) < 1 and abs(rows[2]["error %"]) < 1


def test_workbook_names_the_cell_of_a_record_of_another_run(tmp_path, capsys):
    path = _workbook_with_record(tmp_path, 1)
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "Test data" in err and "rig record" in err and "nominal frequency 59 Hz is not run 'HP rotor'" in err


@pytest.mark.parametrize(("run", "suffix"), [("LP rotor", ".csv"), ("HP rotor", ".uff")])
def test_a_record_synthesized_at_the_default_rate_can_be_compared_for_either_rotor(tmp_path, cache_dir, run, suffix):
    """The default rate samples the HP rotor (248.5 Hz) at least 10 times a period: 4096 Hz, 16.5 samples.

    (2048 Hz, the former default, gave 8.2 and compare refused the HP rotor's record.)"""
    import pandas as pd

    from workbook.cli.loading import load_case
    from workbook.cli.rig import simulate_run
    from workbook.model.codec import to_json

    case = tmp_path / "case.json"
    case.write_text(to_json(reference_case(analysis=SHORT, element_size=COARSE_ELEMENT_SIZE)))
    record, table = tmp_path / f"rig{suffix}", tmp_path / "validation.csv"
    assert main(["rig", "synthesize", str(record), str(case), "--rigid", "--run", run, "--duration", "1", "--noise", "0", "--drift", "0"]) == 0
    # (a UFF file's abscissa increment has 6 digits: 2.44141e-04 s)
    assert read_record(record).sample_rate_hz == pytest.approx(4096.0, rel=1e-5)
    assert main(["rig", "compare", str(record), str(case), "--rigid", "--periods", "20", "--csv", str(table)]) == 0
    # the record's T is the time-domain run's that made it (the table's "T sim" is the frequency domain's)
    made = simulate_run(load_case(str(case), rigid=True), run, histories=True).transmissibility
    measured = pd.read_csv(table, index_col="direction")["T test"].to_numpy()
    # a window of 20 periods spans them to within one sample: 1 / (20 x 16.5) = 3e-3 at the HP rotor
    np.testing.assert_allclose(measured, made, rtol=3e-3)


def test_a_sine_on_a_bin_reads_its_amplitude_in_the_spectrum():
    from workbook.rig.plots import amplitude_spectrum, coherent_samples

    rate, frequency, amplitude = 1000.0, 50.0, 3.0
    time = np.arange(1000) / rate  # 50 whole periods: the sine is on bin 50
    frequencies, amplitudes = amplitude_spectrum(2.0 + amplitude * np.sin(2 * np.pi * frequency * time + 0.7), rate)
    assert frequencies[np.argmax(amplitudes[1:]) + 1] == frequency
    assert amplitudes[50] == pytest.approx(amplitude, rel=1e-12) and amplitudes[0] == pytest.approx(2.0, rel=1e-12)
    # 8000 samples at 2048 Hz hold 230.5 periods of 59 Hz: 230 periods are 7983.7 samples -> 7984
    assert coherent_samples(2048.0, 59.0, 8000) == 7984
    assert coherent_samples(2048.0, 59.0, 8192) == 8192  # 4 s: 236 whole periods


def test_rig_plot_shows_the_excitation_at_the_rotor_frequency_with_its_amplitude(lp_run, tmp_path):
    """The spectra of a synthetic record (no noise, no drift): the rotating 1000 N force on its rotor line."""
    from workbook.rig.plots import plot_record

    record = read_record(write_record(tmp_path / "rig.csv", synthetic_record(lp_run, REFERENCE_TRANSDUCERS, noise=0.0,
                                                                             drift=0.0)))
    figure = plot_record(record)
    # a column per sensor (4 transducers and the excitation): time on top, spectra below
    assert len(figure.axes) == 2 * 5
    spectrum = figure.axes[2 * 4 + 1]
    assert spectrum.get_xlabel() == "frequency [Hz]" and figure.axes[2 * 4].get_title() == "excitation"
    lines = {line.get_label(): line.get_data() for line in spectrum.get_lines()}
    assert lines["rotor 59.00 Hz"][0][0] == pytest.approx(59.0, rel=1e-6)
    for axis in "yz":  # the LP rotor's force rotates about the engine axis x: 1000 N in y and z
        frequencies, amplitudes = lines[axis]
        peak = np.argmax(amplitudes)
        # 4 s at 2048 Hz hold 236 whole periods: the rotor line is on a bin
        assert frequencies[peak] == pytest.approx(59.0, abs=0.5 * (frequencies[1] - frequencies[0]))
        assert amplitudes[peak] == pytest.approx(1000.0, rel=1e-3)
    # each transducer's line at the rotor frequency is its amplitude by the single-bin DFT of the measurement
    measured = measure(record, periods=100)
    front = {line.get_label(): line.get_data()[1] for line in figure.axes[1].get_lines()}
    for axis, amplitude in zip("xyz", measured.transducer_amplitudes["front-left"], strict=True):
        assert front[axis][np.argmax(lines["y"][1])] == pytest.approx(amplitude, rel=2e-3, abs=1e-3)
    # with the comparison: one more row
    assert len(plot_record(record, comparison_frame(measured, lp_run)).axes) == 2 * 5 + 1


def test_rig_plot_command_writes_the_png_beside_an_existing_one(tmp_path, cache_dir, capsys):
    from PIL import Image

    from workbook.model.codec import to_json

    case = tmp_path / "case.json"
    case.write_text(to_json(reference_case(analysis=SHORT, element_size=COARSE_ELEMENT_SIZE)))
    out = tmp_path / "rig.png"
    record = str(CASES / "reference-lp-rig.csv")
    assert main(["rig", "plot", record, "--output", str(out)]) == 0
    assert Image.open(out).size[0] > Image.open(out).size[1]
    assert main(["rig", "plot", record, "--case", str(case), "--rigid", "--periods", "50", "--output", str(out)]) == 0
    assert "rig.png was not overwritten" in capsys.readouterr().out
    assert main(["rig", "plot", record, "--output", str(tmp_path / "rig.jpg")]) == 2
