"""Rig records as labs write them: UFF dataset 58 time histories, read with real files.

The hand-written UFF file follows the standard's text layout (records 1-12
of dataset 58) character by character, not this package's writer: one
transducer (node 10) and the excitation (node 20, the reference node: a
force of constant magnitude rotating in the x-y plane, as an imbalance), sines
of known amplitude at 50 Hz sampled at 2000 Hz (40 samples per period, 100
whole periods), so the measured T is a ratio of amplitudes given here.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from workbook.cli.main import main
from workbook.errors import RecordError
from workbook.rig.correlation import measure
from workbook.rig.records import read_record, write_record

CASES = Path(__file__).resolve().parents[1] / "cases"
RATE, NOMINAL, SAMPLES = 2000.0, 50.0, 4000
#: Amplitudes of the hand-written record, N: the rotating excitation, the transducer's x, y, z.
EXCITATION, TRANSDUCER = 1000.0, np.array([50.0, 20.0, 10.0])


def _dataset58(values, *, node, direction, ref_node, ids, ordinate=(9, 0, 0, 0, "N"), single=False,
               abscissa_units="s", increment=1 / RATE):
    """One dataset 58 of a time response, evenly spaced, in the standard's text layout."""
    kind, length, force, temperature, units = ordinate
    lines = ["    -1", "    58"] + [f"{text:<80}" for text in [*ids, *["NONE"] * (5 - len(ids))]]
    lines.append(f"{1:5d}{0:10d}{0:5d}{0:10d} {'NONE':>10}{node:10d}{direction:4d} {'NONE':>10}{ref_node:10d}"
                 f"{abs(direction):4d}")
    lines.append(f"{2 if single else 4:10d}{len(values):10d}{1:10d}{0.0:13.5e}{increment:13.5e}{0.0:13.5e}")
    lines.append(f"{17:10d}{0:5d}{0:5d}{0:5d} {'Time':<20} {abscissa_units:<20}")
    lines.append(f"{kind:10d}{length:5d}{force:5d}{temperature:5d} {'Force':<20} {units:<20}")
    lines += [f"{0:10d}{0:5d}{0:5d}{0:5d} {'NONE':<20} {'NONE':<20}"] * 2
    per_line, fmt = (6, "{:13.5e}") if single else (4, "{:20.11e}")
    lines += ["".join(fmt.format(v) for v in values[i:i + per_line]) for i in range(0, len(values), per_line)]
    lines.append("    -1")
    return lines


def _hand_written(path: Path, **changes) -> Path:
    """The hand-written record: the transducer's y channel measures -Y, its z channel in kN."""
    phase = 2 * np.pi * NOMINAL * np.arange(SAMPLES) / RATE
    header = ["run: bench run", f"nominal frequency [Hz]: {NOMINAL:g}"]
    transducer = [*header, "transducer pin: front-up-left + front-up-right"]
    channels = [
        dict(values=EXCITATION * np.sin(phase), node=20, direction=1, ref_node=20, ids=["shaker x", *header],
             ordinate=(13, 0, 0, 0, "N"), single=True),
        dict(values=EXCITATION * np.cos(phase), node=20, direction=2, ref_node=20, ids=["shaker y", *header]),
        dict(values=0.0 * phase, node=20, direction=3, ref_node=20, ids=["shaker z", *header]),
        dict(values=TRANSDUCER[0] * np.sin(phase), node=10, direction=1, ref_node=20, ids=["pin x", *transducer]),
        dict(values=-TRANSDUCER[1] * np.sin(phase), node=10, direction=-2, ref_node=20, ids=["pin -y", *transducer]),
        dict(values=TRANSDUCER[2] / 1000 * np.cos(phase), node=10, direction=3, ref_node=20,
             ids=["pin z", *transducer], ordinate=(1, 0, 1, 0, "kN")),
    ]
    for index, change in changes.items():  # c<i>: a change of channel i, None leaves it out
        channels[int(index[1:])] = None if change is None else {**channels[int(index[1:])], **change}
    path.write_text("\n".join(line for channel in channels if channel for line in _dataset58(**channel)) + "\n")
    return path


def test_a_hand_written_uff_record_is_read_as_the_standard_defines_it(tmp_path):
    record = read_record(_hand_written(tmp_path / "bench.unv"))
    assert record.run == "bench run" and record.nominal_hz == NOMINAL
    assert record.sample_rate_hz == pytest.approx(RATE, rel=1e-12)
    assert record.hinges == {"pin": ("front-up-left", "front-up-right")}
    phase = 2 * np.pi * NOMINAL * record.time
    # -Y negated back to +y; kN to N; the single-precision excitation to its 6 digits
    np.testing.assert_allclose(record.transducers["pin"][:, 1], TRANSDUCER[1] * np.sin(phase), atol=1e-9)
    np.testing.assert_allclose(record.transducers["pin"][:, 2], TRANSDUCER[2] * np.cos(phase), atol=1e-9)
    np.testing.assert_allclose(record.excitation[:, 0], EXCITATION * np.sin(phase), atol=1e-2)
    measured = measure(record, periods=20)
    # whole periods of pure sines: T_d = transducer amplitude / excitation amplitude
    assert measured.frequency_hz == pytest.approx(NOMINAL, rel=1e-6)
    np.testing.assert_allclose(measured.transmissibility, TRANSDUCER / EXCITATION, rtol=1e-5)


@pytest.mark.parametrize(("change", "message"), [
    ({"ordinate": (12, 0, 0, 0, "m/s^2")}, r"dataset 5 \(node 10 -Y, 'pin -y'\): the ordinate is not a force: "
                                           r"specific data type 12"),
    ({"ordinate": (0, 0, 0, 0, "mm")}, r"dataset 5 \(node 10 -Y, 'pin -y'\): ordinate unit 'mm'"),
    ({"ordinate": (1, 1, 1, 0, "NONE")}, r"dataset 5 .*general\) with unit exponents length 1, force 1"),
    ({"direction": 5}, r"dataset 5 \(node 10 5, 'pin -y'\): response direction 5 is not a translation"),
    ({"increment": 1 / 1000}, r"dataset 5 .*another time base"),
    ({"ids": ["pin -y", "run: bench run"]}, None),
    ({"ids": ["pin -y", "run: another run"]}, r"dataset 5 .*ID line 'run: another run' differs from 'run: bench run'"),
], ids=["acceleration", "length unit", "exponents", "rotation", "time base", "ID lines on one dataset", "two runs"])
def test_a_uff_channel_that_cannot_be_used_is_refused_naming_it(tmp_path, change, message):
    path = _hand_written(tmp_path / "bench.uff", c4=change)
    if message is None:  # the header lines need to be on one dataset of a node only
        read_record(path)
        return
    with pytest.raises(RecordError, match=message) as error:
        read_record(path)
    assert error.value.path == str(path)


@pytest.mark.parametrize(("change", "message"), [
    (None, "channel 'pin' has no z dataset"),
    ({"node": 30, "ids": ["pin z", "run: bench run"]}, "node 30: no ID line 'transducer <name>: <hinge> \\+ <hinge>'"),
    ({"node": 30}, r"dataset 6 \(node 30 \+Z, 'pin z'\): transducer 'pin' is node 10 on another dataset"),
    ({"direction": 2}, r"dataset 6 \(node 10 \+Y, 'pin z'\): a second channel of node 10 in y"),
], ids=["missing", "unnamed node", "one name on two nodes", "twice"])
def test_a_missing_or_doubled_uff_channel_is_named(tmp_path, change, message):
    with pytest.raises(RecordError, match=message):
        read_record(_hand_written(tmp_path / "bench.uff", c5=change))


def test_uff_written_by_pyuff_round_trips_the_committed_record(tmp_path, capsys):
    committed = read_record(CASES / "reference-lp-rig.csv")
    uff = read_record(write_record(tmp_path / "rig.uff", committed))
    assert (uff.run, uff.nominal_hz, uff.hinges) == (committed.run, committed.nominal_hz, committed.hinges)
    # the abscissa increment has 6 digits in the standard's record 7: 4.88281e-04 s for 2048 Hz
    assert uff.sample_rate_hz == pytest.approx(2048.0, rel=1e-6)
    np.testing.assert_allclose(uff.time, committed.time, rtol=0, atol=1e-5)
    for name, forces in committed.transducers.items():
        np.testing.assert_array_equal(uff.transducers[name], forces)
    np.testing.assert_array_equal(uff.excitation, committed.excitation)
    np.testing.assert_allclose(measure(uff, periods=100).transmissibility,
                               measure(committed, periods=100).transmissibility, rtol=1e-4)
    assert main(["rig", "measure", str(tmp_path / "rig.uff"), "--periods", "100"]) == 0
    assert "run 'LP rotor'" in capsys.readouterr().out


def test_a_file_that_is_not_uff_is_refused(tmp_path):
    path = tmp_path / "notes.uff"
    path.write_text("a lab's notes, not a universal file\n")
    with pytest.raises(RecordError, match="notes.uff: no dataset 58 of function type 1"):
        read_record(path)


#: The hand-written lab CSV: time in ms, one transducer in kN mounted with y reversed, the shaker in lbf.
LAB_CSV = """# bench 3, run 12
t_ms,PIN XX,PIN YY,PIN ZZ,SHK XX,SHK YY,SHK ZZ
0.0,0.010,0.020,0.030,100,0,0
0.5,0.011,0.021,0.031,101,0,0
1.0,0.012,0.022,0.032,102,0,0
"""
LBF = 4.4482216152605  # N


def _lab_map(**changes) -> dict:
    channels = {f"PIN {d * 2}": {"sensor": "pin", "direction": d.lower(), "unit": "kN"} for d in "XYZ"}
    channels["PIN YY"]["sign"] = -1
    channels |= {f"SHK {d * 2}": {"sensor": "excitation", "direction": d.lower(), "unit": "lbf"} for d in "XYZ"}
    data = {"run": "LP rotor", "nominal frequency [Hz]": 59, "time": {"column": "t_ms", "unit": "ms"},
            "transducers": {"pin": ["front-up-left", "front-up-right"]}, "channels": channels}
    for key, value in changes.items():  # "channels.PIN XX.unit": a change inside; None removes the entry
        *parents, last = key.split(".")
        target = data
        for parent in parents:
            target = target[parent]
        if value is None:
            del target[last]
        else:
            target[last] = value
    return data


def _lab_files(tmp_path, csv_text=LAB_CSV, **changes):
    import json

    (tmp_path / "lab.csv").write_text(csv_text)
    (tmp_path / "map.json").write_text(json.dumps(_lab_map(**changes)))
    return tmp_path / "lab.csv", tmp_path / "map.json"


def test_a_lab_csv_is_read_through_its_channel_map(tmp_path):
    from workbook.rig.channel_map import read_mapped_record

    record = read_mapped_record(*_lab_files(tmp_path))
    assert (record.run, record.nominal_hz, record.hinges) == ("LP rotor", 59.0, {"pin": ("front-up-left", "front-up-right")})
    assert record.sample_rate_hz == pytest.approx(2000.0) and record.time[-1] == pytest.approx(1e-3)
    # kN to N, the reversed y negated; lbf to N
    np.testing.assert_allclose(record.transducers["pin"], [[10, -20, 30], [11, -21, 31], [12, -22, 32]], rtol=1e-12)
    np.testing.assert_allclose(record.excitation[:, 0], np.array([100, 101, 102]) * LBF, rtol=1e-12)


@pytest.mark.parametrize(("changes", "csv_text", "message"), [
    ({"channels.PIN ZZ": None}, LAB_CSV, r"map.json: sensor 'pin' has no channel in z"),
    ({"transducers.rear": ["rear-up-left"]}, LAB_CSV, r"map.json: sensor 'rear' has no channel in x, y, z"),
    ({"channels.PIN XX.unit": "m/s^2"}, LAB_CSV, r"map.json: channel 'PIN XX': unit 'm/s\^2'"),
    ({"channels.PIN XX.sensor": "rear"}, LAB_CSV, r"map.json: channel 'PIN XX': sensor 'rear' is neither a transducer"),
    ({}, LAB_CSV.replace(",SHK ZZ", "").replace(",0\n", "\n"), r"lab.csv, line 2: channel 'SHK ZZ' of the channel map"),
    ({}, LAB_CSV.replace("SHK ZZ", "SHK RZ"), r"lab.csv, line 2, column 'SHK RZ': a column the channel map .* does not cover"),
], ids=["missing direction", "missing sensor", "wrong unit", "unknown sensor", "missing channel", "unmapped column"])
def test_a_wrong_channel_map_is_refused_naming_the_channel(tmp_path, changes, csv_text, message):
    from workbook.rig.channel_map import read_mapped_record

    with pytest.raises(RecordError, match=message):
        read_mapped_record(*_lab_files(tmp_path, csv_text, **changes))


def test_a_lab_csv_or_map_not_in_utf8_is_refused_naming_the_file(tmp_path):
    from workbook.rig.channel_map import read_mapped_record

    record, channel_map = _lab_files(tmp_path)
    record.write_text(LAB_CSV.replace("bench 3", "Prüfstand 3"), encoding="cp1252")
    with pytest.raises(RecordError, match=r"lab.csv, line 1: not UTF-8 text"):
        read_mapped_record(record, channel_map)
    record.write_text(LAB_CSV, encoding="utf-8-sig")
    assert read_mapped_record(record, channel_map).run == "LP rotor"
    channel_map.write_text(channel_map.read_text().replace("LP rotor", "LP-Rotor µ"), encoding="cp1252")
    with pytest.raises(RecordError, match=r"map.json, line 1: not UTF-8 text"):
        read_mapped_record(record, channel_map)


def test_rig_measure_reads_the_committed_record_as_a_lab_writes_it(tmp_path, capsys):
    """The committed record renamed as the seed study's lab names its channels, in kN with the rear y reversed."""
    import json

    committed = read_record(CASES / "reference-lp-rig.csv")
    short = {"front-left": "FL", "front-right": "FR", "rear-left": "RL", "rear-right": "RR", "excitation": "EXC"}
    columns = {"Time": committed.time}
    channels = {}
    for name, forces in {**committed.transducers, "excitation": committed.excitation}.items():
        for axis, label in enumerate(("XX", "YY", "ZZ")):
            sign = -1 if name.startswith("rear") and label == "YY" else 1
            columns[f"{short[name]} {label}"] = sign * forces[:, axis] / 1000
            channels[f"{short[name]} {label}"] = {"sensor": name, "direction": "xyz"[axis], "unit": "kN", "sign": sign}
    lines = [",".join(columns)] + [",".join(f"{v:.10g}" for v in row) for row in np.column_stack(list(columns.values()))]
    (tmp_path / "lab.csv").write_text("\n".join(lines) + "\n")
    (tmp_path / "map.json").write_text(json.dumps({
        "run": committed.run, "nominal frequency [Hz]": committed.nominal_hz, "time": {"column": "Time", "unit": "s"},
        "transducers": {name: list(h) for name, h in committed.hinges.items()}, "channels": channels}))
    assert main(["rig", "measure", str(tmp_path / "lab.csv"), "--map", str(tmp_path / "map.json"), "--periods", "100"]) == 0
    lab = capsys.readouterr().out
    assert main(["rig", "measure", str(CASES / "reference-lp-rig.csv"), "--periods", "100"]) == 0
    own = capsys.readouterr().out
    assert lab.splitlines()[1:] == own.splitlines()[1:]  # all but the file's name: the same T and eta
