"""Rig records as Universal File Format (UFF) dataset 58 time histories.

A UFF file holds one dataset 58 ("function at nodal DOF") per channel;
:mod:`pyuff` reads and writes the text layout. A rig record is read from the
datasets of function type 1 (time response) as the standard defines their
fields:

- **channel**: the response node and direction (record 6). A node is a
  sensor; the direction ``+X``/``+Y``/``+Z`` (1, 2, 3) is the axis x, y, z,
  and ``-X``/``-Y``/``-Z`` (-1, -2, -3) a channel measuring the opposite
  way, whose values are negated. The excitation is the reference node: the
  datasets whose response node is their reference node (the driving-point
  force) are the excitation's channels; every other node is a transducer.
- **time**: the abscissa, evenly spaced (sample rate = 1 / increment) or
  uneven but uniform within 0.1 %; an abscissa units label (``s``, ``ms``)
  is converted. Every channel must share one time base.
- **unit**: the ordinate must be a force: specific data type 9 (reaction
  force) or 13 (excitation force), 1 (general) with length exponent 0 and
  force exponent 1, or 0 (unknown) with a force units label; a units label
  (``N``, ``kN``, ``lbf``) is converted to N. Anything else is refused
  naming the file and the channel.

What a UFF record has no field for comes from its ID lines (free text, 80
characters): ``key: value`` lines as the CSV record's header lines, ``run:
<name>``, ``nominal frequency [Hz]: <f>`` and, on each transducer's
datasets, ``transducer <name>: <hinge> + <hinge>``. :func:`write_uff_record`
writes them so; ID line 1 is the channel (``front-left x``).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from workbook.errors import RecordError, UnitProblem
from workbook.model.case import DIRECTIONS, TRANSDUCER_PREFIX
from workbook.model.units import si_factor
from workbook.rig.records import EXCITATION_CHANNEL, RigRecord, check_sampling, parse_header_line

__all__ = ["read_uff_record", "read_uff_sets", "write_uff_record", "UFF_SUFFIXES"]

#: File endings of a UFF record.
UFF_SUFFIXES = (".uff", ".unv")
#: Function type of a time response (record 6, field 1).
TIME_RESPONSE = 1
#: Specific data types (records 8-11, field 1) that are a force, and their names.
_FORCE_TYPES = {9: "reaction force", 13: "excitation force"}
_GENERAL, _UNKNOWN = 1, 0
_ID_LINES = ("id1", "id2", "id3", "id4", "id5")
_NONE = ("", "NONE")



def read_uff_sets(path: Path, kinds: tuple[int, ...]) -> list[tuple[int, dict]]:
    """The datasets of the types *kinds* in the UFF file *path*, with their indices in the file.

    Raises
    ------
    RecordError
        No such file, or a file pyuff cannot read.
    """
    import pyuff

    if not path.is_file():
        raise RecordError(path, "cannot read: no such file")
    try:
        uff = pyuff.UFF(str(path))
        types = list(uff.get_set_types()) if uff.get_n_sets() else []
        return [(i, uff.read_sets(i)) for i, kind in enumerate(types) if kind in kinds]
    except Exception as error:  # pyuff raises plain Exception for a file it cannot parse
        raise RecordError(path, f"not a readable UFF file: {error}") from None

def _direction_text(direction: int) -> str:
    return f"{'+' if direction > 0 else '-'}{'XYZ'[abs(direction) - 1]}" if 1 <= abs(direction) <= 3 else str(direction)


def _label(index: int, dataset: dict) -> str:
    """A dataset as an error names it: number, node, direction and ID line 1."""
    description = str(dataset.get("id1", "")).strip()
    return (f"dataset {index + 1} (node {dataset.get('rsp_node')} {_direction_text(int(dataset.get('rsp_dir', 0)))}"
            + (f", {description!r})" if description not in _NONE else ")"))


def _force_factor(path, label: str, dataset: dict) -> float:
    """Factor from the dataset's ordinate to N."""
    kind = int(dataset["ordinate_spec_data_type"])
    units = str(dataset.get("ordinate_axis_units_lab", "")).strip()
    exponents = tuple(int(dataset[f"ordinate_{name}_unit_exp"]) for name in ("len", "force", "temp"))
    if kind == _GENERAL and exponents != (0, 1, 0):
        raise RecordError(path, f"{label}: the ordinate is not a force: specific data type 1 (general) with unit "
                          f"exponents length {exponents[0]}, force {exponents[1]}, temperature {exponents[2]} "
                          "(a force has 0, 1, 0)")
    if kind not in (*_FORCE_TYPES, _GENERAL) and not (kind == _UNKNOWN and units not in _NONE):
        raise RecordError(path, f"{label}: the ordinate is not a force: specific data type {kind} (a force is 9, "
                          "reaction force, 13, excitation force, or 1, general, with force exponent 1)")
    if units in _NONE:
        return 1.0
    try:
        return si_factor(units, "N")
    except UnitProblem as problem:
        raise RecordError(path, f"{label}: ordinate unit {units!r}: {problem}") from None


def _time(path, label: str, dataset: dict) -> np.ndarray:
    """The dataset's abscissa in s, checked uniform (:func:`~workbook.rig.records.check_sampling`)."""
    units = str(dataset.get("abscissa_axis_units_lab", "")).strip()
    try:
        factor = 1.0 if units in _NONE else si_factor(units, "s")
    except UnitProblem as problem:
        raise RecordError(path, f"{label}: abscissa unit {units!r}: {problem}") from None
    return check_sampling(path, np.asarray(dataset["x"], dtype=float) * factor, None, None, column=label)


def read_uff_record(path: str | Path) -> RigRecord:
    """Read and check a rig record in a UFF file of dataset 58 time histories (module docstring).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    RigRecord
        Forces in N, time in s; sample rate 1 / abscissa increment, Hz.

    Raises
    ------
    RecordError
        Not a UFF file, no time response, a channel that is not a force or
        not a translation, channels on different time bases, a channel twice
        or missing, or a missing ID line (run, nominal frequency, a
        transducer's hinges), naming the file and the channel.
    """
    path = Path(path)
    datasets = [d for _, d in read_uff_sets(path, (58,))]
    datasets = [d for d in datasets if int(d.get("func_type", -1)) == TIME_RESPONSE]
    if not datasets:
        raise RecordError(path, "no dataset 58 of function type 1 (time response)")
    header: dict[str, tuple[str, str]] = {}
    names: dict[int, str] = {}
    hinges: dict[str, tuple[str, ...]] = {}
    channels: dict[tuple[int, str], np.ndarray] = {}
    time = None
    for index, dataset in enumerate(datasets):
        label = _label(index, dataset)
        node, direction = int(dataset["rsp_node"]), int(dataset["rsp_dir"])
        if not 1 <= abs(direction) <= 3:
            raise RecordError(path, f"{label}: response direction {direction} is not a translation "
                              "(+-1, +-2, +-3: X, Y, Z)")
        for key in _ID_LINES:
            parsed = parse_header_line(str(dataset.get(key, "")))
            if parsed is None:
                continue
            name, value = parsed
            if name.startswith(TRANSDUCER_PREFIX):
                transducer = name[len(TRANSDUCER_PREFIX):].strip()
                other = next((n for n, named in names.items() if named == transducer and n != node), None)
                if names.setdefault(node, transducer) != transducer or other is not None:
                    raise RecordError(path, f"{label}: " + (f"node {node} is transducer {names[node]!r}" if other is None
                                      else f"transducer {transducer!r} is node {other}") + " on another dataset")
                hinges[transducer] = tuple(h.strip() for h in value.split("+") if h.strip())
            elif header.setdefault(name, (value, label))[0] != value:
                raise RecordError(path, f"{label}: ID line '{name}: {value}' differs from "
                                  f"'{name}: {header[name][0]}' of {header[name][1]}")
        here = _time(path, label, dataset)
        if time is None:
            time = here
        elif len(here) != len(time) or not np.allclose(here, time, rtol=0, atol=1e-3 * (time[1] - time[0])):
            raise RecordError(path, f"{label}: another time base ({len(here)} samples from {here[0]:g} s) than "
                              f"{_label(0, datasets[0])} ({len(time)} samples from {time[0]:g} s)")
        axis = DIRECTIONS[abs(direction) - 1]
        sensor = -1 if node == int(dataset["ref_node"]) else node  # -1: the excitation
        if (sensor, axis) in channels:
            raise RecordError(path, f"{label}: a second channel of node {node} in {axis}")
        channels[sensor, axis] = np.sign(direction) * _force_factor(path, label, dataset) * np.asarray(
            dataset["data"], dtype=float)
    assert time is not None
    for key in ("run", "nominal frequency [Hz]"):
        if key not in header:
            raise RecordError(path, f"no ID line '{key}: ...' in any dataset")
    try:
        nominal = float(header["nominal frequency [Hz]"][0])
    except ValueError:
        raise RecordError(path, f"{header['nominal frequency [Hz]'][1]}: nominal frequency "
                          f"{header['nominal frequency [Hz]'][0]!r} is not a number") from None
    nodes = sorted({sensor for sensor, _ in channels})
    unnamed = [node for node in nodes if node != -1 and node not in names]
    if unnamed:
        raise RecordError(path, f"node {unnamed[0]}: no ID line 'transducer <name>: <hinge> + <hinge>' on its datasets")
    if -1 not in nodes:
        raise RecordError(path, "no excitation: no dataset whose response node is its reference node")
    forces = {}
    for node in nodes:
        missing = [axis for axis in DIRECTIONS if (node, axis) not in channels]
        name = EXCITATION_CHANNEL if node == -1 else names[node]
        if missing:
            raise RecordError(path, f"channel {name!r} has no {', '.join(missing)} dataset")
        forces[name] = np.column_stack([channels[node, axis] for axis in DIRECTIONS])
    excitation = forces.pop(EXCITATION_CHANNEL)
    return RigRecord(time, forces, excitation, {name: hinges[name] for name in forces},
                     (len(time) - 1) / (time[-1] - time[0]), nominal,
                     header["run"][0], str(path), {k: v for k, (v, _) in header.items()
                                                   if k not in ("run", "nominal frequency [Hz]")})


def write_uff_record(path: str | Path, record: RigRecord) -> Path:
    """Write *record* as UFF dataset 58 time histories, one dataset per channel (module docstring).

    Transducer i (in the record's order) is response node i + 1, the
    excitation node n + 1 for n transducers, each channel's reference the
    excitation node in the same direction; forces are reaction forces
    (specific data type 9, the excitation's 13) in N, time in s, double
    precision.

    Returns
    -------
    Path
    """
    import pyuff

    path = Path(path)
    excitation_node = len(record.transducers) + 1
    channels = [(node, name, forces, [f"transducer {name}: {' + '.join(record.hinges[name])}"])
                for node, (name, forces) in enumerate(record.transducers.items(), start=1)]
    channels.append((excitation_node, EXCITATION_CHANNEL, record.excitation, []))
    header = [f"run: {record.run}", f"nominal frequency [Hz]: {record.nominal_hz:.10g}"]
    datasets = []
    for node, name, forces, lines in channels:
        for axis_index, axis in enumerate(DIRECTIONS):
            ids = [f"{name} {axis}", *header, *lines]
            datasets.append(pyuff.prepare_58(
                func_type=TIME_RESPONSE, rsp_node=node, rsp_dir=axis_index + 1, ref_node=excitation_node,
                ref_dir=axis_index + 1, data=np.ascontiguousarray(forces[:, axis_index], dtype=float),
                x=np.asarray(record.time, dtype=float), abscissa_spacing=1, abscissa_spec_data_type=17,
                abscissa_axis_units_lab="s", ordinate_spec_data_type=13 if node == excitation_node else 9,
                ordinate_axis_units_lab="N", orddenom_spec_data_type=0, z_axis_spec_data_type=0,
                **dict(zip(_ID_LINES, ids + ["NONE"] * (len(_ID_LINES) - len(ids)), strict=True))))
    pyuff.UFF(str(path)).write_sets(datasets, mode="overwrite")
    return path
