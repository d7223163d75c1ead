"""The pylon model interface: what every flexible pylon gives the solvers.

A case's pylon is rigid (``Case.pylon`` None) or one :class:`PylonModel`:
an impedance table (:mod:`workbook.model.pylon_impedance`), a box beam
(:mod:`workbook.model.pylon_beam`) or a user's mesh
(:mod:`workbook.model.pylon_mesh`), one module each. Every model gives its
point dynamic stiffness or its compliance at the pins at the frequencies
asked (:meth:`PylonModel.pins_at`), a line for the model card, its checks
against the case's pins and frequencies, and the time-domain refusal; it is
a frozen dataclass, so the case JSON holds it as ``"pylon"`` tagged by its
class name (:mod:`workbook.model.codec`). The four-pole set is closed by it
in :mod:`workbook.solve.flexible_pylon`.

A structure given by its (reduced) stiffness and mass, the beam's and the
mesh's, closes it through :class:`PylonStructure`:
``D(w) = K (1 + i eta) - w^2 M`` with the structural loss factor eta, and
the compliance (receptance) at the pins ``G(w) = T D^-1 T^T``: pin motion
per force on the pylon at the pins, coupled through the structure, shape
(3 p, 3 p).
"""
from __future__ import annotations

import abc
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from workbook.errors import CaseError

__all__ = ["PylonModel", "PinDynamics", "PylonStructure"]

#: A pin of the case, ``Case.pylon_pins()``: its position (m) and the names of its pylon-side hinges.
Pin = tuple[object, Sequence[str]]

_IN_FREQUENCY = ("run the frequency domain (method 'auto' or 'frequency', no hinge clearance) or remove the "
                 "{noun}")


@dataclass(frozen=True)
class PinDynamics:
    """A pylon at the pins at each frequency asked: one of a stiffness and a compliance.

    Attributes
    ----------
    stiffness : ndarray or None, complex, shape (n, p, 3, 3)
        Point dynamic stiffness per pin (uncoupled pins), N/m.
    compliance : ndarray or None, complex, shape (n, 3 p, 3 p)
        Compliance at the pins, coupled between them, m/N.
    detail : str
        The model-card entry's detail.
    warnings : list of list of str
        Per frequency, what the model cannot resolve there.
    """

    stiffness: np.ndarray | None
    compliance: np.ndarray | None
    detail: str
    warnings: list[list[str]] = field(default_factory=list)


class PylonModel(abc.ABC):
    """A flexible pylon carrying the pylon pins; frequency domain only.

    Implementations are frozen dataclasses registered in
    :mod:`workbook.model.codec`.
    """

    #: Name of the model-card entry, e.g. ``"flexible pylon (box beam)"``.
    effect: ClassVar[str]
    #: What messages call it, e.g. ``"pylon beam"``.
    noun: ClassVar[str]
    #: Its ``Case`` field of version 0.1.0 (``"pylon_beam"``), still read from case files; empty for a new kind.
    legacy_field: ClassVar[str] = ""
    #: Why the time domain has no model of it, for :meth:`time_domain_refusal`.
    time_domain_note: ClassVar[str]
    #: What the time domain has not, if not :attr:`noun`.
    time_domain_what: ClassVar[str] = ""

    @property
    @abc.abstractmethod
    def label(self) -> str:
        """Its name (or source) in messages."""

    @abc.abstractmethod
    def describe(self) -> str:
        """One line for the model card."""

    @abc.abstractmethod
    def pins_at(self, pins: Sequence[Pin], frequencies_hz: Sequence[float], highest_hz: float) -> PinDynamics:
        """The pylon at *pins* (``Case.pylon_pins()``) at *frequencies_hz*.

        Parameters
        ----------
        pins : sequence of (position, hinge names)
        frequencies_hz : sequence of float
            Hz.
        highest_hz : float
            Highest frequency of every run of the case, Hz (a reduction
            made for it serves them all).

        Raises
        ------
        workbook.errors.CaseError
            Input the model cannot answer (a pin it does not reach, a
            frequency outside its table, a mesh that cannot be read).
        """

    def check(self, pins: Sequence[Pin]) -> None:
        """Refuse *pins* (``Case.pylon_pins()``) the model cannot carry, when the case is built
        (by default every pin: a structure's pins are checked when it is built, by :meth:`pins_at`).

        Raises
        ------
        workbook.errors.CaseError
        """
        return None

    def covered_hz(self) -> tuple[float, float] | None:
        """The frequencies it answers, lowest and highest, Hz (None: any)."""
        return None

    def check_covers(self, frequencies_hz) -> None:
        """Refuse *frequencies_hz* (Hz) unless :meth:`covered_hz` holds every one of them.

        Raises
        ------
        workbook.errors.CaseError
            Naming the frequencies asked for (one, or the lowest to the
            highest) and the range; a table is not extrapolated.
        """
        covered = self.covered_hz()
        if covered is None:
            return
        low, high = covered
        wanted = np.atleast_1d(np.asarray(frequencies_hz, dtype=float))
        outside = wanted[(wanted < low * (1 - 1e-12)) | (wanted > high * (1 + 1e-12))]
        if outside.size:
            asked = f"{wanted[0]:g} Hz" if wanted.size == 1 else f"{wanted.min():g} to {wanted.max():g} Hz"
            raise CaseError(f"{self.noun} {self.label}", "frequency", asked,
                            f"frequencies the table covers, {low:g} to {high:g} Hz ({outside.size} of "
                            f"{wanted.size} outside; the table is not extrapolated: extend it or narrow the "
                            "excitation's frequencies)")

    def time_domain_refusal(self, reason: str) -> str:
        """What a time-domain run of a case on this pylon is told (*reason*: why it took the time domain)."""
        return (f"no {self.time_domain_what or self.noun} in the time domain ({reason}): {self.time_domain_note}; "
                + _IN_FREQUENCY.format(noun=self.noun))


@dataclass(frozen=True)
class PylonStructure:
    """A clamped pylon's matrices and its pin map.

    Attributes
    ----------
    stiffness, mass : ndarray, shape (n, n)
        Free DOF (the clamped ones removed): N/m (N m/rad for rotations) and
        kg (kg m^2).
    pin_map : ndarray, shape (3 p, n)
        Pin translations per DOF.
    loss_factor : float
    """

    stiffness: np.ndarray
    mass: np.ndarray
    pin_map: np.ndarray
    loss_factor: float

    def compliance(self, frequencies_hz) -> np.ndarray:
        """``G`` at each frequency, complex, shape (f, 3 p, 3 p), m/N."""
        import scipy.linalg as sla

        result = []
        for frequency in np.atleast_1d(np.asarray(frequencies_hz, dtype=float)):
            omega = 2 * np.pi * frequency
            dynamic = self.stiffness * (1 + 1j * self.loss_factor) - omega ** 2 * self.mass
            result.append(self.pin_map @ sla.solve(dynamic, self.pin_map.T.astype(complex), check_finite=False))
        return np.array(result)
