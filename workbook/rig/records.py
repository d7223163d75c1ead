"""Measured rig records: read, check and write force time histories.

A rig record (CSV) holds the time, the three channels x, y, z of every
three-way force transducer between a pylon-side fitting and ground, and the
three channels of the excitation force. Its ``#`` header lines name the run,
the nominal rotor frequency, the sample rate, and which pylon-side hinges
(or group of hinges) each transducer carries::

    # mountwb rig record
    # run: LP rotor
    # nominal frequency [Hz]: 59
    # sample rate [Hz]: 2048
    # transducer front-left: front-up-left
    # transducer rear-left: rear-up-left + rear-up-middle
    time [s],front-left x [N],front-left y [N],front-left z [N],...,excitation x [N],...

Channel columns are ``<transducer> <axis> [<unit>]`` and ``excitation <axis>
[<unit>]``; any force unit (N, kN, lbf) and time unit (s, ms) is converted
to SI on read. Every problem is a :class:`RecordError` naming the file, the
line (1-based, as an editor counts) and the column.
"""
from __future__ import annotations

import csv
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from workbook.answers.isolation import pylon_sum
from workbook.answers.saving import save_text
from workbook.errors import RecordError
from workbook.model.case import DIRECTIONS, TRANSDUCER_PREFIX

__all__ = ["RigRecord", "read_record", "record_text", "write_record", "parse_header_line", "table_values",
           "check_sampling", "EXCITATION_CHANNEL",
           "SAMPLE_RATE_TOLERANCE"]

#: Channel name of the excitation force.
EXCITATION_CHANNEL = "excitation"
#: Largest relative difference between the stated and the sampled rate.
SAMPLE_RATE_TOLERANCE = 1e-3
_MAGIC = "mountwb rig record"
_HEADER = re.compile(r"^\s*(?P<key>[^:]+?)\s*:\s*(?P<value>.*?)\s*$")
_COLUMN = re.compile(r"^\s*(?P<name>.+?)\s*\[\s*(?P<unit>[^\]]+?)\s*\]\s*$")


@dataclass
class RigRecord:
    """Force histories measured on the rig.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Uniformly sampled times, s.
    transducers : dict of str to ndarray, shape (n, 3)
        Force of each transducer, x, y, z, N.
    excitation : ndarray, shape (n, 3)
        Excitation force, N.
    hinges : dict of str to tuple of str
        Pylon-side hinges carried by each transducer.
    sample_rate_hz : float
        Stated sample rate, Hz.
    nominal_hz : float
        Nominal rotor frequency, Hz.
    run : str
        Run (excitation) name the record belongs to.
    path : str
        Where it was read from ("" if made in memory).
    notes : dict of str to str
        Other header lines (how it was made).
    """

    time: np.ndarray
    transducers: dict
    excitation: np.ndarray
    hinges: dict
    sample_rate_hz: float
    nominal_hz: float
    run: str
    path: str = ""
    notes: dict = field(default_factory=dict)

    @property
    def pylon(self) -> np.ndarray:
        """Pylon force: the vector sum of the transducers, shape (n, 3), N."""
        return pylon_sum(self.transducers, self.transducers)

    def check_hinges(self, pylon_hinges) -> None:
        """Raise RecordError unless the transducers carry every pylon-side hinge exactly once.

        Parameters
        ----------
        pylon_hinges : sequence of str
            The case's pylon-side hinges.
        """
        carried = [h for hinges in self.hinges.values() for h in hinges]
        expected = set(pylon_hinges)
        unknown = sorted(set(carried) - expected)
        twice = sorted({h for h in carried if carried.count(h) > 1})
        missing = sorted(expected - set(carried))
        problems = [f"{label}: {', '.join(names)}" for label, names in
                    (("not a pylon-side hinge of the case", unknown), ("carried twice", twice),
                     ("carried by no transducer", missing)) if names]
        if problems:
            raise RecordError(self.path or "rig record", "transducer header lines do not match the case's "
                              f"pylon-side hinges ({', '.join(pylon_hinges)}): {'; '.join(problems)}")


def parse_header_line(text: str) -> tuple[str, str] | None:
    """``(key, value)`` of a header line ``key: value`` (without its ``#``), or None for another text."""
    match = _HEADER.match(text)
    return None if match is None else (match["key"], match["value"])


def read_record(path: str | Path) -> RigRecord:
    """Read and check a rig record: a CSV, or a UFF file (``.uff``, ``.unv``: :mod:`workbook.rig.uff`).

    Raises
    ------
    RecordError
        A file that is not UTF-8 text, missing or bad header line, unknown unit, missing channel, a cell
        that is not a number, time not uniformly sampled, or a sampled rate
        that differs from the stated one.
    """
    path = Path(path)
    from workbook.rig.uff import UFF_SUFFIXES, read_uff_record

    if path.suffix.lower() in UFF_SUFFIXES:
        return read_uff_record(path)
    lines = record_text(path).splitlines()
    header, hinges, table_start = _read_header(path, lines)
    nominal = _header_number(path, header, "nominal frequency [Hz]")
    rate = _header_number(path, header, "sample rate [Hz]")
    headers, data = _read_table(path, lines, table_start)
    if "time" not in data:
        raise RecordError(path, "no 'time [s]' column", line=table_start)
    time = data.pop("time")
    time = check_sampling(path, time, rate, table_start)
    channels = {}
    for name in (*hinges, EXCITATION_CHANNEL):
        for axis in DIRECTIONS:
            if f"{name} {axis}" not in data:
                raise RecordError(path, f"missing channel '{name} {axis} [N]'", line=table_start,
                                  column=f"{name} {axis}")
        channels[name] = np.column_stack([data.pop(f"{name} {axis}") for axis in DIRECTIONS])
    if data:
        stray = next(h for h in headers if (match := _COLUMN.match(h)) and match["name"] in data)
        raise RecordError(path, f"channel without a '# transducer' header line: {', '.join(data)}",
                          line=table_start, column=stray)
    notes = {k: v for k, (v, _) in header.items() if k not in ("run", "nominal frequency [Hz]", "sample rate [Hz]")}
    excitation = channels.pop(EXCITATION_CHANNEL)
    return RigRecord(time, channels, excitation, hinges, rate, nominal, header["run"][0], str(path), notes)


def record_text(path: Path) -> str:
    """The text of the rig record or channel map at *path*: UTF-8, a byte-order mark (as a
    spreadsheet saves "CSV UTF-8") dropped.

    Raises
    ------
    RecordError
        The file cannot be read, or is not UTF-8 text (naming the line).
    """
    try:
        data = path.read_bytes()
    except OSError as error:
        raise RecordError(path, f"cannot read: {error.strerror}") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise RecordError(path, f"not UTF-8 text (byte {data[error.start]:#04x}); save it as UTF-8 text "
                          "(CSV UTF-8)", line=data.count(b"\n", 0, error.start) + 1) from None


def _read_header(path, lines: list[str]) -> tuple[dict, dict, int]:
    """The ``#`` lines: ``{key: (value, line)}``, the transducers' hinges, and the table's first line."""
    header, hinges, table_start = {}, {}, None
    for number, text in enumerate(lines, start=1):
        if not text.startswith("#"):
            table_start = number
            break
        parsed = parse_header_line(text[1:])
        if parsed is None:
            continue
        key, value = parsed
        if key.startswith(TRANSDUCER_PREFIX):
            names = tuple(n.strip() for n in value.split("+") if n.strip())
            if not names:
                raise RecordError(path, "a transducer line must name its hinges ('a + b')", line=number)
            hinges[key[len(TRANSDUCER_PREFIX):].strip()] = names
        else:
            header[key] = (value, number)
    if table_start is None:
        raise RecordError(path, "no column header line after the '#' lines")
    for key in ("run", "nominal frequency [Hz]", "sample rate [Hz]"):
        if key not in header:
            raise RecordError(path, f"missing header line '# {key}: ...'")
    if not hinges:
        raise RecordError(path, "no '# transducer <name>: <hinge> + <hinge>' header line")
    return header, hinges, table_start


def _header_number(path, header: dict, key: str) -> float:
    value, number = header[key]
    try:
        result = float(value)
    except ValueError:
        raise RecordError(path, f"'{key}' must be a number, found {value!r}", line=number) from None
    if not np.isfinite(result) or result <= 0:
        raise RecordError(path, f"'{key}' must be positive, found {value!r}", line=number)
    return result


def _read_table(path, lines: list[str], start: int) -> tuple[list, dict]:
    """Headers of the table at line *start*, and each channel's values in SI units by channel name."""
    from workbook.errors import UnitProblem
    from workbook.model.units import si_factor

    headers = next(csv.reader([lines[start - 1]]))
    names, factors = [], []
    for header in headers:
        match = _COLUMN.match(header)
        if match is None:
            raise RecordError(path, "a column header must read '<channel> [<unit>]'", line=start, column=header)
        if match["name"] in names:
            raise RecordError(path, "a second column of this channel", line=start, column=header)
        try:
            factors.append(si_factor(match["unit"], "s" if match["name"] == "time" else "N"))
        except UnitProblem as problem:
            raise RecordError(path, f"unit {match['unit']!r}: {problem}", line=start, column=header) from None
        names.append(match["name"])
    values = table_values(path, lines, start, headers)
    return headers, {name: values[:, j] * factor for j, (name, factor) in enumerate(zip(names, factors, strict=True))}


def table_values(path, lines: list[str], start: int, headers: list[str]) -> np.ndarray:
    """The numbers of the CSV rows after the column header line *start* (1-based), shape (rows, columns).

    Raises
    ------
    RecordError
        A row of another length, or a cell that is not a finite number, naming its line and column.
    """
    rows = [row for row in csv.reader(lines[start:]) if row]
    values = np.empty((len(rows), len(headers)))
    for index, row in enumerate(rows):
        line = start + 1 + index
        if len(row) != len(headers):
            raise RecordError(path, f"{len(row)} cells, expected {len(headers)}", line=line)
        for j, cell in enumerate(row):
            try:
                values[index, j] = float(cell)
            except ValueError:
                raise RecordError(path, f"{cell!r} is not a number", line=line, column=headers[j]) from None
    if not np.isfinite(values).all():
        index, j = np.argwhere(~np.isfinite(values))[0]
        raise RecordError(path, "not a finite number", line=start + 1 + int(index), column=headers[j])
    return values


def check_sampling(path, time: np.ndarray, rate: float | None, start: int | None,
                   column: str = "time [s]") -> np.ndarray:
    """Check that *time* (s) is sampled uniformly at *rate* (Hz); return the uniform times, s.

    The times returned lie on the checked grid, without the rounding of the file's digits.

    Parameters
    ----------
    rate : float or None
        The stated sample rate, Hz (None: none is stated; the record's rate is its time's).
    start : int or None
        Line of the column header (the first sample is on the next line;
        None: the times are not lines of a file).
    column : str
        The time column (or channel), for the message.

    Raises
    ------
    RecordError
        Fewer than 2 samples, a step that differs from the others by more
        than 0.1 % (naming its line), or a sampled rate that differs from
        *rate* by more than :data:`SAMPLE_RATE_TOLERANCE`.
    """
    if len(time) < 2:
        raise RecordError(path, f"{len(time)} samples; a record needs many periods of the rotor")
    steps = np.diff(time)
    bad = np.flatnonzero(np.abs(steps - np.median(steps)) > 1e-3 * np.median(steps))
    if steps.min() <= 0 or len(bad):
        index = int(np.flatnonzero(steps <= 0)[0] if steps.min() <= 0 else bad[0])
        raise RecordError(path, f"time is not uniformly sampled: step {steps[index]:.6g} s here, "
                          f"{np.median(steps):.6g} s elsewhere", line=None if start is None else start + 2 + index,
                          column=column)
    sampled = 1.0 / float(np.median(steps))
    if rate is not None and abs(sampled - rate) > SAMPLE_RATE_TOLERANCE * rate:
        raise RecordError(path, f"wrong sample rate: the header states {rate:g} Hz, the time column is "
                          f"sampled at {sampled:.6g} Hz (step {1.0 / rate:.6g} s expected)", column=column)
    return time[0] + np.arange(len(time)) * (time[-1] - time[0]) / (len(time) - 1)


def write_record(path: str | Path, record: RigRecord, *, digits: int = 4) -> Path:
    """Write *record* as a rig record CSV (forces in N with *digits* decimals, time in s), or as a UFF
    file for a path ending in ``.uff`` or ``.unv`` (:func:`workbook.rig.uff.write_uff_record`).

    Returns
    -------
    Path
    """
    path = Path(path)
    from workbook.rig.uff import UFF_SUFFIXES, write_uff_record

    if path.suffix.lower() in UFF_SUFFIXES:
        return write_uff_record(path, record)
    lines = [f"# {_MAGIC}", f"# run: {record.run}", f"# nominal frequency [Hz]: {record.nominal_hz:.10g}",
             f"# sample rate [Hz]: {record.sample_rate_hz:.10g}"]
    lines += [f"# transducer {name}: {' + '.join(hinges)}" for name, hinges in record.hinges.items()]
    lines += [f"# {key}: {value}" for key, value in record.notes.items()]
    channels = {**record.transducers, EXCITATION_CHANNEL: record.excitation}
    lines.append(",".join(["time [s]"] + [f"{name} {axis} [N]" for name in channels for axis in DIRECTIONS]))
    table = np.column_stack([record.time, *channels.values()])
    row_format = ",".join(["{:.9f}"] + [f"{{:.{digits}f}}"] * (table.shape[1] - 1))
    lines += [row_format.format(*row) for row in table]
    return save_text("\n".join(lines) + "\n", path)
