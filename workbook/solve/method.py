"""Which analysis answers a case: time domain or frequency domain, and why.

``AnalysisSettings.method``:

- ``"auto"`` (the default): the frequency domain when the scene is linear
  (no hinge clearance law is built), since the harmonic solution of the
  linearised scene is then exact and costs no transient; the time domain
  when a clearance law makes the scene nonlinear;
- ``"time"`` or ``"frequency"``: forced by the user. Forcing the frequency
  domain on a scene with clearance linearises the clearance laws about the
  preloaded state (gaps frozen open or closed): the card says so.

A sweep on a linear scene always takes the frequency domain, whatever the
case asks: one linearisation serves every frequency, where the time domain
would run every point from rest.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Final, Literal

from workbook.model.case import Case

__all__ = ["MethodChoice", "choose_method", "clearance_hinges", "TIME", "FREQUENCY"]

#: The methods a run is answered with.
Method = Literal["time", "frequency"]
TIME: Final = "time"
FREQUENCY: Final = "frequency"


@dataclass(frozen=True)
class MethodChoice:
    """The analysis method of a case and the reason for it.

    Attributes
    ----------
    method : {"time", "frequency"}
    reason : str
    """

    method: Method
    reason: str

    @property
    def label(self) -> str:
        return f"{self.method} domain"


def clearance_hinges(case: Case) -> list[str]:
    """Names of the hinges whose clearance law is built (they make the scene nonlinear)."""
    if not case.effects.clearance:
        return []
    return [h.name for h in case.hinges if h.radial_clearance > 0]


def choose_method(case: Case, *, sweep: bool = False) -> MethodChoice:
    """Choose the analysis method of *case* from ``case.analysis.method``.

    Parameters
    ----------
    case : Case
    sweep : bool
        The choice is for a sweep: on a linear scene the frequency domain
        answers it whatever the case asks.
    """
    asked = case.analysis.method
    gaps = clearance_hinges(case)
    nonlinear = (f"hinge clearance on {', '.join(repr(g) for g in gaps)} makes the scene nonlinear"
                 if gaps else "")
    if sweep and not gaps:
        return MethodChoice(FREQUENCY, f"a sweep on a linear scene (no hinge clearance): one linearisation "
                            f"serves every frequency (the case asks for method {asked!r})")
    if asked == TIME:
        return MethodChoice(TIME, "the case asks for it (method 'time')"
                            + (f"; {nonlinear}" if gaps else "; the scene is linear, so the frequency domain "
                               "would give the same answers faster"))
    if asked == FREQUENCY:
        if gaps:
            return MethodChoice(FREQUENCY, f"the case asks for it (method 'frequency') although {nonlinear}: "
                                "the clearance laws are linearised about the preloaded state (gaps frozen "
                                "as they are there), an approximation")
        return MethodChoice(FREQUENCY, "the case asks for it (method 'frequency'); the scene is linear, "
                            "so the harmonic solution is exact")
    if gaps:
        return MethodChoice(TIME, f"auto: {nonlinear}; the time domain resolves the contact")
    return MethodChoice(FREQUENCY, "auto: the scene is linear (no hinge clearance), so the harmonic solution "
                        "is exact")
