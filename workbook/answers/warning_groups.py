"""Warnings of many runs (a sweep's points, a run-up's speeds) collected: one line per distinct text.

A warning that every point of a 25-point sweep raises is printed once,
with how many points raised it and their frequency range.
"""
from __future__ import annotations

from dataclasses import dataclass

from workbook.model.case import SPEED_UNITS, SpeedUnit

__all__ = ["WarningGroup", "group_warnings", "warning_lines"]


@dataclass(frozen=True)
class WarningGroup:
    """One distinct warning text and the runs that raised it.

    Attributes
    ----------
    text : str
    names : tuple of str
        The runs, in order.
    frequencies_hz : tuple of float
        Their frequencies, Hz.
    """

    text: str
    names: tuple
    frequencies_hz: tuple

    @property
    def count(self) -> int:
        """How many runs raised it."""
        return len(self.names)

    def where(self, unit: SpeedUnit = "Hz") -> str:
        """The run, or the count and the frequency range in *unit* (Hz, or rpm for a run-up), in words."""
        if self.count == 1:
            return self.names[0]
        low, high = (bound / SPEED_UNITS[unit] for bound in (min(self.frequencies_hz), max(self.frequencies_hz)))
        span = f"at {low:.6g} {unit}" if low == high else f"from {low:.6g} to {high:.6g} {unit}"
        return f"{self.count} points {span}"


def group_warnings(runs) -> list[WarningGroup]:
    """Group the warnings of *runs* by their text, in the order first raised.

    Parameters
    ----------
    runs : iterable
        Objects with ``name``, ``frequency_hz`` (Hz) and ``warnings`` (list of
        str), as :class:`~workbook.answers.results.ExcitationResult`.

    Returns
    -------
    list of WarningGroup
        One per distinct text; a run raising the same text twice counts once.
    """
    seen: dict[str, tuple[list, list]] = {}
    for run in runs:
        for text in dict.fromkeys(run.warnings):
            names, frequencies = seen.setdefault(text, ([], []))
            names.append(run.name)
            frequencies.append(float(run.frequency_hz))
    return [WarningGroup(text, tuple(names), tuple(frequencies)) for text, (names, frequencies) in seen.items()]


def warning_lines(runs, label: str = "", unit: SpeedUnit = "Hz") -> list[str]:
    """One ``WARNING`` line per distinct warning of *runs*, with its count and frequency range.

    Parameters
    ----------
    runs : iterable
        As for :func:`group_warnings`.
    label : str
        Put before where the warning arose (e.g. a workbook run's name).
    unit : {"Hz", "rpm"}
        Unit of the frequency ranges (a run-up's speed unit).

    Returns
    -------
    list of str
    """
    prefix = f"{label} / " if label else ""
    return [f"WARNING {prefix}{group.where(unit)}: {group.text}" for group in group_warnings(runs)]
