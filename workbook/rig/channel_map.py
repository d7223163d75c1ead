"""A lab's CSV of force histories, read through a channel map.

A lab writes its own channel names (the seed study's rig: ``XX``, ``YY``,
``ZZ`` per three-way sensor, and the excitation's sensors). A channel map
(JSON) says what each column is, and what the CSV has no place for::

    {
      "run": "LP rotor",
      "nominal frequency [Hz]": 59,
      "time": {"column": "Time", "unit": "s"},
      "transducers": {"front-left": ["front-up-left"],
                      "rear-left": ["rear-up-left", "rear-up-middle"]},
      "channels": {
        "FL XX": {"sensor": "front-left", "direction": "x", "unit": "kN", "sign": 1},
        "FL YY": {"sensor": "front-left", "direction": "y", "unit": "kN", "sign": -1},
        "SHAKER XX": {"sensor": "excitation", "direction": "x", "unit": "N"}
      }
    }

``transducers`` names each transducer and the pylon-side hinges it carries;
each channel is one direction (x, y, z) of a transducer or of the
excitation (sensor ``"excitation"``), in a force unit (N, kN, lbf, ...:
converted to N; anything else is refused naming the channel), times
``sign`` (1, or -1 for a sensor mounted the other way; default 1). Every
sensor needs its three directions. The CSV is a header line of channel names
(after any ``#`` lines) and rows of numbers; its sample rate is the time
column's. A column the map does not cover, or a mapped channel missing in
the file, is refused naming it.
"""
from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from workbook.errors import RecordError, UnitProblem
from workbook.model.case import DIRECTIONS
from workbook.model.units import si_factor
from workbook.rig.records import EXCITATION_CHANNEL, RigRecord, check_sampling, record_text, table_values

__all__ = ["read_mapped_record", "read_channel_map", "ChannelMap"]

_KEYS = {"run", "nominal frequency [Hz]", "time", "transducers", "channels"}
_CHANNEL_KEYS = {"sensor", "direction", "unit", "sign"}


@dataclass(frozen=True)
class ChannelMap:
    """A checked channel map (module docstring).

    Attributes
    ----------
    path : str
    run : str
    nominal_hz : float
        Hz.
    time_column : str
    time_factor : float
        From the time column's unit to s.
    hinges : dict of str to tuple of str
        Pylon-side hinges of each transducer.
    channels : dict of str to tuple of (str, int, float)
        Per CSV column: sensor, direction index (0, 1, 2 for x, y, z) and
        the factor (sign x unit) to N.
    """

    path: str
    run: str
    nominal_hz: float
    time_column: str
    time_factor: float
    hinges: dict
    channels: dict


def _entry(path, data: dict, key: str, kind, what: str):
    value = data.get(key)
    if not isinstance(value, kind) or isinstance(value, bool):
        raise RecordError(path, f"'{key}': found {value!r}, expected {what}")
    return value


def read_channel_map(path: str | Path) -> ChannelMap:
    """Read and check a channel map (JSON, module docstring).

    Raises
    ------
    RecordError
        Not UTF-8 text or not JSON, an unknown or missing entry, a channel with an unknown
        sensor, direction, sign or a unit that is not a force, a direction
        of a sensor twice or missing, or a transducer without channels;
        naming the channel or sensor.
    """
    path = Path(path)
    try:
        data = json.loads(record_text(path))
    except json.JSONDecodeError as error:
        raise RecordError(path, f"not JSON: {error.msg}", line=error.lineno) from None
    if not isinstance(data, dict) or set(data) - _KEYS:
        raise RecordError(path, f"a channel map is a JSON object of {', '.join(sorted(_KEYS))}; found "
                          f"{', '.join(sorted(set(data) - _KEYS)) if isinstance(data, dict) else type(data).__name__}")
    run = _entry(path, data, "run", str, "the run's name")
    nominal = float(_entry(path, data, "nominal frequency [Hz]", (int, float), "a frequency in Hz"))
    time = _entry(path, data, "time", dict, '{"column": <name>, "unit": "s"}')
    try:
        time_factor = si_factor(str(time.get("unit", "s")), "s")
    except UnitProblem as problem:
        raise RecordError(path, f"time unit {time.get('unit')!r}: {problem}") from None
    time_column = _entry(path, time, "column", str, "the time column's name")
    transducers = _entry(path, data, "transducers", dict, "transducer -> list of the pylon-side hinges it carries")
    hinges = {}
    for name, carried in transducers.items():
        if name == EXCITATION_CHANNEL or not isinstance(carried, list) or not carried:
            raise RecordError(path, f"transducer {name!r}: expected a list of the pylon-side hinges it carries "
                              f"(and not named {EXCITATION_CHANNEL!r}), found {carried!r}")
        hinges[name] = tuple(str(h) for h in carried)
    channels: dict[str, tuple[str, int, float]] = {}
    seen: dict[tuple[str, str], str] = {}
    for column, entry in _entry(path, data, "channels", dict, "channel -> sensor, direction, unit, sign").items():
        where = f"channel {column!r}"
        if not isinstance(entry, dict) or set(entry) - _CHANNEL_KEYS or not {"sensor", "direction", "unit"} <= set(entry):
            raise RecordError(path, f"{where}: expected {{'sensor', 'direction', 'unit'[, 'sign']}}, found {entry!r}")
        sensor, direction, sign = entry["sensor"], str(entry["direction"]), entry.get("sign", 1)
        if sensor != EXCITATION_CHANNEL and sensor not in hinges:
            raise RecordError(path, f"{where}: sensor {sensor!r} is neither a transducer ({', '.join(hinges)}) nor "
                              f"{EXCITATION_CHANNEL!r}")
        if direction not in DIRECTIONS:
            raise RecordError(path, f"{where}: direction {direction!r}, expected one of {', '.join(DIRECTIONS)}")
        if sign not in (1, -1) or isinstance(sign, bool):
            raise RecordError(path, f"{where}: sign {sign!r}, expected 1 or -1")
        try:
            factor = si_factor(str(entry["unit"]), "N")
        except UnitProblem as problem:
            raise RecordError(path, f"{where}: unit {entry['unit']!r}: {problem}") from None
        if (sensor, direction) in seen:
            raise RecordError(path, f"{where}: {sensor} {direction} is channel {seen[sensor, direction]!r} already")
        seen[sensor, direction] = column
        channels[column] = (sensor, DIRECTIONS.index(direction), sign * factor)
    for sensor in (*hinges, EXCITATION_CHANNEL):
        missing = [d for d in DIRECTIONS if (sensor, d) not in seen]
        if missing:
            raise RecordError(path, f"sensor {sensor!r} has no channel in {', '.join(missing)}")
    return ChannelMap(str(path), run, nominal, time_column, time_factor, hinges, channels)


def read_mapped_record(path: str | Path, channel_map: str | Path | ChannelMap) -> RigRecord:
    """Read a lab's CSV of force histories through a channel map (module docstring).

    Parameters
    ----------
    path : str or Path
        The CSV.
    channel_map : str, Path or ChannelMap
        The map, or the path of its JSON file.

    Returns
    -------
    RigRecord
        Forces in N, signs applied, time in s; sample rate from the time column, Hz.

    Raises
    ------
    RecordError
        A bad map (:func:`read_channel_map`), a column the map does not
        cover, a mapped channel missing in the file, a cell that is not a
        number, or time not uniformly sampled; naming file, line and column.
    """
    mapping = channel_map if isinstance(channel_map, ChannelMap) else read_channel_map(channel_map)
    path = Path(path)
    lines = record_text(path).splitlines()
    start = next((number for number, text in enumerate(lines, start=1) if text.strip() and not text.startswith("#")),
                 None)
    if start is None:
        raise RecordError(path, "no column header line")
    headers = [h.strip() for h in next(csv.reader([lines[start - 1]]))]
    known = [mapping.time_column, *mapping.channels]
    for header in headers:
        if header not in known:
            raise RecordError(path, f"a column the channel map {mapping.path} does not cover", line=start,
                              column=header)
    for name in known:
        if name not in headers:
            raise RecordError(path, f"channel {name!r} of the channel map {mapping.path} is not in the file",
                              line=start)
    if len(set(headers)) != len(headers):
        twice = next(h for h in headers if headers.count(h) > 1)
        raise RecordError(path, "a second column of this channel", line=start, column=twice)
    values = table_values(path, lines, start, headers)
    time = values[:, headers.index(mapping.time_column)] * mapping.time_factor
    time = check_sampling(path, time, None, start, column=mapping.time_column)
    forces = {name: np.zeros((len(time), 3)) for name in (*mapping.hinges, EXCITATION_CHANNEL)}
    for column, (sensor, axis, factor) in mapping.channels.items():
        forces[sensor][:, axis] = factor * values[:, headers.index(column)]
    excitation = forces.pop(EXCITATION_CHANNEL)
    rate = (len(time) - 1) / (time[-1] - time[0])
    return RigRecord(time, forces, excitation, dict(mapping.hinges), rate, mapping.nominal_hz, mapping.run, str(path),
                     {"channel map": mapping.path})
