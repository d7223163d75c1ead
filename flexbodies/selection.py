"""Which fixed-interface modes a link keeps, and why.

The seed study's *low-frequency approximation*: when the highest excitation
frequency is below a quarter of the link's fundamental frequency, the
link's response is quasi-static and the fixed-interface modes can all be
dropped (static modes only, with their mass kept). Otherwise fixed-interface
modes are kept up to at least four times the highest excitation frequency.

"The fundamental frequency" is the one with the boundary condition the link
has in the mount: pinned at both ball hinges, spin about its own axis
restrained.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

from .errors import LinkModelError

__all__ = ["ModeDecision", "decide_modes", "LOW_FREQUENCY_RATIO", "MOUNTED_BOUNDARY"]

#: The low-frequency rule holds when f_exc / f1 is below this ratio.
LOW_FREQUENCY_RATIO = 0.25
#: Modes kept up to this multiple of the highest excitation frequency otherwise.
MODE_MARGIN = 4.0
#: The boundary condition of the fundamental frequency used by the rule.
MOUNTED_BOUNDARY = "pinned at both bore centres, spin about the link axis restrained"


@dataclass(frozen=True)
class ModeDecision:
    """The resolved mode selection of one reduced link.

    Attributes
    ----------
    request : str
        What was asked: ``"auto"``, ``"static"``, ``"count=N"`` or ``"cutoff=F Hz"``.
    count : int or None
        Number of fixed-interface modes to keep, when fixed by count.
    cutoff_hz : float or None
        Keep fixed-interface modes up to (and one past) this frequency, Hz.
    fundamental_hz : float
        First frequency with the mounted boundary condition, Hz.
    excitation_hz : float or None
        Highest excitation frequency the link must represent, Hz.
    reason : str
        One sentence an engineer can check.
    """

    request: str
    count: int | None
    cutoff_hz: float | None
    fundamental_hz: float
    excitation_hz: float | None
    reason: str

    @property
    def ratio(self) -> float | None:
        """Excitation over fundamental frequency, or None without an excitation."""
        if self.excitation_hz is None:
            return None
        return self.excitation_hz / self.fundamental_hz

    @property
    def warning(self) -> str | None:
        """Why the selection is unsafe, or None.

        Unsafe: no fixed-interface modes kept (``"static"`` or a count of 0
        asked for) while the excitation is at or above
        :data:`LOW_FREQUENCY_RATIO` of the mounted fundamental, where the
        low-frequency approximation does not hold.
        """
        ratio = self.ratio
        if self.count != 0 or ratio is None or ratio < LOW_FREQUENCY_RATIO:
            return None
        return (f"no fixed-interface modes ({self.request}) although the excitation {self.excitation_hz:g} Hz is "
                f"{ratio:.2f} of the mounted fundamental {self.fundamental_hz:.0f} Hz (the low-frequency "
                f"approximation needs < {LOW_FREQUENCY_RATIO}): the link's own dynamics are missing; "
                f"use modes='auto'")

    @property
    def key(self) -> str:
        """What the reduction depends on: the resolved count or cut-off."""
        return f"count={self.count}" if self.count is not None else f"cutoff={self.cutoff_hz:.6g}"

    def to_dict(self) -> dict:
        return asdict(self)


def _parse_request(modes):
    """Normalise a mode request to (kind, value)."""
    if isinstance(modes, str):
        word = modes.strip().lower()
        if word in ("auto", "static"):
            return word, None
        raise LinkModelError(f"unknown mode selection {modes!r}; expected 'auto', 'static', a count or a cut-off in Hz")
    if isinstance(modes, bool):
        raise LinkModelError("mode selection must be 'auto', 'static', an int count or a float cut-off in Hz")
    if isinstance(modes, int):
        if modes < 0:
            raise LinkModelError(f"mode count must be >= 0, got {modes}")
        return "count", modes
    if isinstance(modes, float):
        if not modes > 0:
            raise LinkModelError(f"mode cut-off must be a positive frequency in Hz, got {modes}")
        return "cutoff", modes
    raise LinkModelError(f"mode selection must be 'auto', 'static', an int count or a float cut-off in Hz, got {modes!r}")


def decide_modes(modes, fundamental_hz: float, excitation_hz: float | None = None) -> ModeDecision:
    """Resolve a mode request for a link.

    Parameters
    ----------
    modes : {"auto", "static"} or int or float
        ``"auto"`` applies the low-frequency rule, ``"static"`` keeps static
        modes only, an int keeps that many fixed-interface modes, a float keeps
        them up to that cut-off frequency in Hz.
    fundamental_hz : float
        The link's first frequency as mounted (:data:`MOUNTED_BOUNDARY`), Hz.
    excitation_hz : float, optional
        Highest excitation frequency, Hz. Required for ``"auto"``.

    Returns
    -------
    ModeDecision

    Raises
    ------
    ValueError
        A bad request, or a fundamental frequency that is not positive.
    """
    kind, value = _parse_request(modes)
    f1 = float(fundamental_hz)
    if not f1 > 0:
        raise LinkModelError(f"the body's first elastic frequency is {f1:g} Hz: part of it moves freely (a mesh of "
                         f"unconnected pieces, or a piece held by nothing), so it cannot be reduced")
    if kind == "static":
        return ModeDecision("static", 0, None, f1, excitation_hz, "static modes only, as requested")
    if kind == "count":
        return ModeDecision(f"count={value}", value, None, f1, excitation_hz, f"{value} fixed-interface modes, as requested")
    if kind == "cutoff":
        return ModeDecision(
            f"cutoff={value:g} Hz", None, value, f1, excitation_hz,
            f"fixed-interface modes up to {value:g} Hz, as requested",
        )
    if excitation_hz is None or not excitation_hz > 0:
        raise LinkModelError("mode selection 'auto' needs the highest excitation frequency (Hz > 0)")
    ratio = excitation_hz / f1
    if ratio < LOW_FREQUENCY_RATIO:
        reason = (
            f"low-frequency rule met: f_exc {excitation_hz:g} Hz is {ratio:.3f} of f1 {f1:.0f} Hz "
            f"({MOUNTED_BOUNDARY}) < {LOW_FREQUENCY_RATIO}; static modes only"
        )
        return ModeDecision("auto", 0, None, f1, excitation_hz, reason)
    cutoff = MODE_MARGIN * excitation_hz
    reason = (
        f"low-frequency rule not met: f_exc {excitation_hz:g} Hz is {ratio:.3f} of f1 {f1:.0f} Hz "
        f"({MOUNTED_BOUNDARY}) >= {LOW_FREQUENCY_RATIO}; fixed-interface modes kept up to "
        f"at least {MODE_MARGIN:g} x f_exc = {cutoff:g} Hz"
    )
    return ModeDecision("auto", None, cutoff, f1, excitation_hz, reason)
