"""Which analysis answers a case: time domain or frequency domain, and why.

``AnalysisSettings.method``:

- ``"auto"`` (the default): the frequency domain when the scene is linear
  (no nonlinear hinge law, such as a clearance, is built), since the
  harmonic solution of the linearised scene is then exact and costs no
  transient; the time domain when a nonlinear hinge law
  (:mod:`workbook.scene.hinge_laws`) makes the scene nonlinear;
- ``"time"`` or ``"frequency"``: forced by the user. Forcing the frequency
  domain on a nonlinear scene linearises its laws about the preloaded
  state (clearance gaps frozen open or closed): the card says so.

A sweep on a linear scene always takes the frequency domain, whatever the
case asks: one linearisation serves every frequency, where the time domain
would run every point from rest.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Final, Literal

from workbook.model.case import Case
from workbook.scene.hinge_laws import linear_note, nonlinear_hinges, nonlinear_reason

__all__ = ["MethodChoice", "choose_method", "TIME", "FREQUENCY"]

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
    laws = nonlinear_hinges(case)
    nonlinear = nonlinear_reason(case)
    if sweep and not laws:
        return MethodChoice(FREQUENCY, f"a sweep on a linear scene ({linear_note()}): one linearisation "
                            f"serves every frequency (the case asks for method {asked!r})")
    if asked == TIME:
        return MethodChoice(TIME, "the case asks for it (method 'time')"
                            + (f"; {nonlinear}" if laws else "; the scene is linear, so the frequency domain "
                               "would give the same answers faster"))
    if asked == FREQUENCY:
        if laws:
            return MethodChoice(FREQUENCY, f"the case asks for it (method 'frequency') although {nonlinear}: "
                                + "; ".join(law.linearised for law in laws) + ", an approximation")
        return MethodChoice(FREQUENCY, "the case asks for it (method 'frequency'); the scene is linear, "
                            "so the harmonic solution is exact")
    if laws:
        return MethodChoice(TIME, f"auto: {nonlinear}; " + "; ".join(law.time_domain_note for law in laws))
    return MethodChoice(FREQUENCY, f"auto: the scene is linear ({linear_note()}), so the harmonic solution "
                        "is exact")
