"""The pylon as a point dynamic stiffness per pin: a table against frequency.

A measured or computed pylon (or wing) is given at its pins by its point
dynamic stiffness ``Z_p(f)``: the complex 3x3 matrix of the force on the
pylon at a pin per motion of that pin (N/m), ``F = Z_p x``, one per pin
and table frequency (pins do not couple through the pylon in this table).
Between table frequencies the real and imaginary parts of every entry are
interpolated linearly in frequency; a frequency outside the table's range is
refused (no extrapolation).

The table format (a CSV file, or a sheet of a case workbook laid out the
same way): a header row, a units row, then one row per frequency and pin::

    frequency, pin,       Kxx re, Kxx im, Kxy re, Kxy im, ..., Kzz re, Kzz im
    Hz,        ,          MN/m,   MN/m,   MN/m,   MN/m,   ..., MN/m,   MN/m
    10,        rear-left, 250,    2.5,    0,      0,      ..., 400,    4

``frequency`` in a frequency unit (Hz, kHz, rpm), ``pin`` the name of a
pylon-side hinge on the pin (any one of them, when several share it), and
the 18 stiffness columns ``K<row><column> re`` / ``im`` (row: the force
direction, column: the motion direction, x, y, z) each in a stiffness unit
(N/m, kN/mm, MN/m, ...). Every pin has a row at every table frequency;
the frequencies increase.
"""
from __future__ import annotations

import csv
import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np

from workbook.errors import CaseError, Problem, TableError, UnitProblem
from workbook.model.pylon import Pin, PinDynamics, PylonModel
from workbook.model.units import si_factor

__all__ = ["PylonImpedance", "read_impedance_csv", "impedance_from_rows", "STIFFNESS_COLUMNS", "FORMAT_HEADER"]

_AXES = "xyz"
#: The 18 stiffness columns: ``K<force direction><motion direction> re|im``.
STIFFNESS_COLUMNS = tuple(f"K{a}{b} {part}" for a, b in itertools.product(_AXES, _AXES) for part in ("re", "im"))
#: The header row of the table.
FORMAT_HEADER = ("frequency", "pin", *STIFFNESS_COLUMNS)
#: Largest table read, rows.
MAX_ROWS = 200_000
#: A row is passive when the least eigenvalue of the Hermitian part of its
#: imaginary part, ``(Z - Z^H) / 2i``, is above minus this share of its
#: largest entry: the round-off of a table printed to six digits.
PASSIVITY_TOLERANCE = 1e-6


def _nested(array: np.ndarray) -> tuple:
    return tuple(_nested(part) for part in array) if array.ndim > 1 else tuple(float(v) for v in array)


@dataclass(frozen=True)
class PylonImpedance(PylonModel):
    """Point dynamic stiffness of the pylon at each pin against frequency (a :class:`~workbook.model.pylon.PylonModel`).

    Parameters
    ----------
    source : str
        Where the table comes from (file, sheet), for messages.
    frequencies_hz : tuple of float
        Table frequencies, Hz, increasing, > 0.
    pins : tuple of str
        Per pin: the name of a pylon-side hinge on it.
    real, imag : nested tuples, shape (f, p, 3, 3)
        Real and imaginary parts of ``Z_p``, N/m: force on the pylon at a
        pin (row x, y, z) per motion of the pin (column x, y, z).

    Raises
    ------
    workbook.errors.CaseError
        Values of the wrong shape, or a row that is not passive
        (:data:`PASSIVITY_TOLERANCE`).
    """

    effect: ClassVar[str] = "flexible pylon (point dynamic stiffness)"
    noun: ClassVar[str] = "pylon impedance"
    legacy_field: ClassVar[str] = "pylon_impedance"
    time_domain_what: ClassVar[str] = "frequency-dependent pylon impedance"
    time_domain_note: ClassVar[str] = ("a dynamic stiffness tabulated against frequency has no time-domain model "
                                       "here")

    source: str
    frequencies_hz: tuple
    pins: tuple
    real: tuple
    imag: tuple

    def __post_init__(self):
        item = f"pylon impedance {self.source}"
        frequencies = np.asarray(self.frequencies_hz, dtype=float)
        pins = tuple(self.pins)
        if frequencies.ndim != 1 or frequencies.size < 1:
            raise CaseError(item, "frequencies_hz", self.frequencies_hz, "one or more frequencies, Hz")
        if not (np.all(np.isfinite(frequencies)) and frequencies[0] > 0 and np.all(np.diff(frequencies) > 0)):
            raise CaseError(item, "frequencies_hz", self.frequencies_hz, "increasing frequencies > 0 Hz")
        if not pins or len(set(pins)) != len(pins) or not all(isinstance(p, str) and p for p in pins):
            raise CaseError(item, "pins", self.pins, "one or more distinct pin (hinge) names")
        shape = (frequencies.size, len(pins), 3, 3)
        for name in ("real", "imag"):
            try:
                values = np.asarray(getattr(self, name), dtype=float)
            except (TypeError, ValueError):
                values = None
            if values is None or values.shape != shape or not np.all(np.isfinite(values)):
                raise CaseError(item, name, "values of another shape or not finite",
                                f"finite stiffnesses (N/m) of shape {shape} (frequencies, pins, 3, 3)")
            object.__setattr__(self, name, _nested(values))
        object.__setattr__(self, "frequencies_hz", tuple(float(f) for f in frequencies))
        object.__setattr__(self, "pins", pins)
        self._check_passive(item)

    def _check_passive(self, item: str) -> None:
        """Refuse rows that give energy to the mount.

        The mean power a pin puts into the pylon moving as ``x e^{iwt}`` is
        ``w/2 x^H (Z - Z^H)/2i x``: a passive structure absorbs it for every
        ``x``, so the Hermitian part of the imaginary part is positive
        semi-definite (for a symmetric Z: ``Im Z``). A row where it is not
        (an active damper) makes the coupled mount unstable, and a steady
        answer on it is no answer.
        """
        values = self.values
        dissipation = (values - np.conj(np.swapaxes(values, -1, -2))) / 2j
        least = np.linalg.eigvalsh(dissipation)[..., 0]
        scale = np.abs(values).max(axis=(-2, -1))
        active = np.argwhere(least < -PASSIVITY_TOLERANCE * scale)
        if not active.size:
            return
        listed = "; ".join(f"pin {self.pins[p]!r} at {self.frequencies_hz[f]:g} Hz (least eigenvalue "
                           f"{least[f, p]:.3g} N/m)" for f, p in active[:3])
        more = f" and {len(active) - 3} more" if len(active) > 3 else ""
        raise CaseError(item, "imag", f"{len(active)} of {least.size} rows giving energy to the mount: {listed}{more}",
                        "a passive pylon: at every row the Hermitian part of the imaginary part, (Z - Z^H)/2i, "
                        "positive semi-definite (for a symmetric Z: every 'K.. im' on the diagonal >= 0, the "
                        "damping of each direction). A negative imaginary part is an active damper: the mount "
                        "on it is unstable and has no steady answer. Check the sign convention of the table "
                        "(the force on the pylon per motion of its pin)")

    @classmethod
    def from_array(cls, source: str, frequencies_hz, pins, values) -> "PylonImpedance":
        """From a complex array *values* of shape (f, p, 3, 3), N/m."""
        values = np.asarray(values, dtype=complex)
        return cls(source, tuple(frequencies_hz), tuple(pins), values.real, values.imag)

    @property
    def values(self) -> np.ndarray:
        """``Z_p`` at the table frequencies, complex, shape (f, p, 3, 3), N/m."""
        return np.asarray(self.real) + 1j * np.asarray(self.imag)

    def pin_order(self, case_pins: Sequence[Pin]) -> list[int]:
        """The table's pin of each of *case_pins* (``Case.pylon_pins()``).

        Raises
        ------
        workbook.errors.CaseError
            A pin of the case without rows (rows of a name that is no
            pylon-side hinge are not used).
        """
        order = []
        for _, hinges in case_pins:
            given = [n for n, pin in enumerate(self.pins) if pin in hinges]
            if len(given) != 1:
                found = f"rows of {', '.join(self.pins)}" if not given else [self.pins[n] for n in given]
                raise CaseError(f"pylon impedance {self.source}", "pin", found,
                                f"the rows of one hinge of the pylon pin of {' + '.join(hinges)}")
            order.append(given[0])
        return order

    def at(self, frequencies_hz, order: Sequence[int]) -> np.ndarray:
        """``Z_p`` at *frequencies_hz* for the table pins *order*, complex, shape (f, p, 3, 3), N/m.

        Real and imaginary parts are interpolated linearly in frequency.

        Raises
        ------
        workbook.errors.CaseError
            A frequency outside the table's range.
        """
        wanted = np.atleast_1d(np.asarray(frequencies_hz, dtype=float))
        self.check_covers(wanted)
        table = np.asarray(self.frequencies_hz)
        values = self.values[:, list(order)]
        flat = values.reshape(len(table), -1)
        clipped = np.clip(wanted, table[0], table[-1])
        columns = [np.interp(clipped, table, flat[:, c].real) + 1j * np.interp(clipped, table, flat[:, c].imag)
                   for c in range(flat.shape[1])]
        return np.array(columns).T.reshape(len(wanted), *values.shape[1:])

    @property
    def label(self) -> str:
        """Its source (file, sheet)."""
        return self.source

    def covered_hz(self) -> tuple[float, float]:
        """The table's lowest and highest frequency, Hz (it is not extrapolated)."""
        return self.frequencies_hz[0], self.frequencies_hz[-1]

    def check(self, pins: Sequence[Pin]) -> None:
        """Refuse a pin of the case without rows (:meth:`pin_order`)."""
        self.pin_order(pins)

    def pins_at(self, pins: Sequence[Pin], frequencies_hz: Sequence[float], highest_hz: float) -> PinDynamics:
        """``Z_p`` at *pins* and *frequencies_hz*, interpolated (:meth:`at`), with its interpolation warnings."""
        order = self.pin_order(pins)
        return PinDynamics(self.at(frequencies_hz, order), None,
                           f"{self.describe()}; real and imaginary parts interpolated linearly in frequency",
                           self.interpolation_warnings(frequencies_hz, order))

    def interpolation_warnings(self, frequencies_hz, order: Sequence[int]) -> list[list[str]]:
        """Warnings for the frequencies the table's rows cannot resolve.

        A real part that changes sign between two rows is a resonance of
        the pylon between them. Linear interpolation follows it only when
        the rows lie closer than its half-power bandwidth, estimated as
        ``2 |Im Z| / |d Re Z / df|`` at the zero of the interpolated real
        part (a mass-spring-damper's bandwidth); otherwise a frequency
        between the two rows is warned.

        Parameters
        ----------
        frequencies_hz : sequence of float
            Frequencies within the table, Hz.
        order : sequence of int
            The table's pin of each pin of the case (:meth:`pin_order`).

        Returns
        -------
        list of list of str
            The warnings of each frequency.
        """
        table = np.asarray(self.frequencies_hz)
        values = self.values[:, list(order)]
        pins = [self.pins[n] for n in order]
        scale = np.abs(values).max(axis=(1, 2, 3))
        warned: list[list[str]] = []
        for frequency in np.atleast_1d(np.asarray(frequencies_hz, dtype=float)):
            row = int(np.searchsorted(table, frequency))
            if row == 0 or row == len(table) or frequency == table[row]:
                warned.append([])
                continue
            low, high = values[row - 1], values[row]
            width = table[row] - table[row - 1]
            # an element that matters (above 1e-3 of the rows' largest) whose real part changes sign
            floor = 1e-3 * max(scale[row - 1], scale[row])
            crossing = (low.real * high.real < 0) & (np.minimum(abs(low.real), abs(high.real)) > floor)
            found = []
            for pin, a, b in np.argwhere(crossing):
                share = low[pin, a, b].real / (low[pin, a, b].real - high[pin, a, b].real)
                damping = abs(low[pin, a, b].imag + share * (high[pin, a, b].imag - low[pin, a, b].imag))
                band_hz = 2 * damping * width / abs(high[pin, a, b].real - low[pin, a, b].real)
                if width > band_hz:
                    found.append((band_hz, pins[pin], f"K{_AXES[a]}{_AXES[b]}", low[pin, a, b].real,
                                  high[pin, a, b].real))
            if found:
                band_hz, pin, entry, before, after = min(found)
                warned.append([
                    f"pylon impedance {self.source}: {frequency:g} Hz lies between the rows at {table[row - 1]:g} "
                    f"and {table[row]:g} Hz, where Re {entry} of pin {pin!r} changes sign ({before:.4g} to "
                    f"{after:.4g} N/m; {len(found)} entries change sign there): a resonance of the pylon between "
                    f"the rows, about {band_hz:.2g} Hz wide, which linear interpolation between rows {width:g} Hz "
                    f"apart does not follow (T there may be many times off). Give rows no more than "
                    f"{band_hz / 4:.2g} Hz apart from {table[row - 1]:g} to {table[row]:g} Hz"])
            else:
                warned.append([])
        return warned

    def describe(self) -> str:
        """One line for the model card."""
        return (f"{len(self.pins)} pin(s), {len(self.frequencies_hz)} frequencies from "
                f"{self.frequencies_hz[0]:g} to {self.frequencies_hz[-1]:g} Hz, from {self.source}")


def _number(value) -> float | None:
    """A finite float from a cell value, or None."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        number = float(value)
    else:
        try:
            number = float(str(value).strip())
        except ValueError:
            return None
    return number if math.isfinite(number) else None


def _text(value) -> str:
    return "" if value is None else str(value).strip()


def impedance_from_rows(rows: Iterable[Sequence], file: str, sheet: str | None = None) -> PylonImpedance:
    """Read the table (header row, units row, data rows; see the module) from *rows*.

    Parameters
    ----------
    rows : iterable of sequences
        Cell values, row by row (the first row is row 1).
    file : str
        The file's name, for messages.
    sheet : str, optional
        The sheet's name (a workbook), for messages.

    Raises
    ------
    workbook.errors.TableError
        Naming the file, sheet, row and column of every problem found.
    """
    rows = list(itertools.islice(rows, MAX_ROWS + 3))
    problems: list[Problem] = []

    def problem(row: int | None, column: str | None, value, expected: str) -> None:
        problems.append(Problem(file, sheet, None if row is None else f"row {row}", column, value, expected))

    def fail() -> TableError:
        return TableError(problems)

    if len(rows) > MAX_ROWS + 2:
        problem(None, None, f"more than {MAX_ROWS} data rows", f"at most {MAX_ROWS} rows")
        raise fail()
    if len(rows) < 3:
        problem(None, None, f"{len(rows)} row(s)", "a header row, a units row and one or more data rows")
        raise fail()
    header = [_text(v).lower() for v in rows[0]]
    while header and not header[-1]:
        header.pop()
    position = {}
    for n, name in enumerate(header):
        normal = " ".join(name.split())
        if normal in position:
            problem(1, name, name, "each column once")
        position[normal] = n
    wanted = {name.lower(): name for name in FORMAT_HEADER}
    for name in header:
        if " ".join(name.split()) not in wanted:
            problem(1, name or None, name, f"the columns {', '.join(FORMAT_HEADER)}")
    for key, name in wanted.items():
        if key not in position:
            problem(1, name, None, f"a column {name!r}")
    if problems:
        raise fail()
    column = {wanted[key]: n for key, n in position.items()}

    def cell(row: Sequence, name: str):
        n = column[name]
        return row[n] if n < len(row) else None

    factors = {}
    units = rows[1]
    for name, si in [("frequency", "Hz")] + [(name, "N/m") for name in STIFFNESS_COLUMNS]:
        text = _text(cell(units, name))
        try:
            factors[name] = si_factor(text, si)
        except UnitProblem as unit:
            problem(2, name, text, unit.expected)
    if problems:
        raise fail()

    table: dict[float, dict[str, np.ndarray]] = {}
    order: list[float] = []
    for number, row in enumerate(rows[2:], start=3):
        if all(_text(v) == "" for v in row):
            continue
        frequency = _number(cell(row, "frequency"))
        if frequency is None or frequency * factors["frequency"] <= 0:
            problem(number, "frequency", cell(row, "frequency"), "a frequency > 0")
            continue
        frequency *= factors["frequency"]
        pin = _text(cell(row, "pin"))
        if not pin:
            problem(number, "pin", cell(row, "pin"), "the name of a pylon-side hinge")
            continue
        values = []
        for name in STIFFNESS_COLUMNS:
            value = _number(cell(row, name))
            if value is None:
                problem(number, name, cell(row, name), "a finite number (a stiffness)")
            values.append(0.0 if value is None else value * factors[name])
        if not order or frequency != order[-1]:
            if order and frequency < order[-1]:
                problem(number, "frequency", cell(row, "frequency"),
                        f"a frequency >= {order[-1]:g} Hz (the frequencies increase down the table)")
                continue
            order.append(frequency)
            table[frequency] = {}
        if pin in table[frequency]:
            problem(number, "pin", pin, f"one row per pin at {frequency:g} Hz")
            continue
        pairs = np.array(values).reshape(3, 3, 2)
        table[frequency][pin] = pairs[..., 0] + 1j * pairs[..., 1]
    if not problems and not order:
        problem(None, None, "no data rows", "one or more rows under the units row")
    if problems:
        raise fail()
    pins = list(dict.fromkeys(pin for frequency in order for pin in table[frequency]))
    for frequency in order:
        missing = [pin for pin in pins if pin not in table[frequency]]
        if missing:
            problem(None, "pin", f"no row of pin {missing[0]!r} at {frequency:g} Hz",
                    "a row for every pin at every frequency")
    if problems:
        raise fail()
    source = file if sheet is None else f"{file}, sheet '{sheet}'"
    matrix = np.array([[table[frequency][pin] for pin in pins] for frequency in order])
    return PylonImpedance.from_array(source, order, pins, matrix)


def read_impedance_csv(path: str | Path) -> PylonImpedance:
    """Read a pylon impedance table from a CSV file (see the module for the format).

    Raises
    ------
    workbook.errors.TableError
        A table that cannot be used (file, row and column named).
    OSError
        The file cannot be read.
    """
    path = Path(path)
    try:
        with path.open(newline="", encoding="utf-8-sig") as handle:
            return impedance_from_rows(csv.reader(handle), path.name)
    except UnicodeDecodeError:
        raise TableError([Problem(path.name, None, None, None, "bytes that are not UTF-8 text",
                                  "a CSV table (UTF-8 text)")]) from None
    except csv.Error as error:
        raise TableError([Problem(path.name, None, None, None, str(error), "a CSV table")]) from None
