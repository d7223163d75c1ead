"""The registry of hinge laws: which law builds each hinge, and what the nonlinear ones do to a scene.

A hinge takes the first law of :data:`HINGE_LAWS` that applies to it, else
the plain diagonal spring-damper
(:data:`~workbook.scene.hinge_law_base.SPRING_DAMPER`). The scene, the
choice of method, the four-pole set, the linear mount and the model card ask
this registry, never a law's own fields. A new law is one module (a
:class:`~workbook.scene.hinge_law_base.HingeLaw`), its entry here and its
fields on :class:`~workbook.model.case.Hinge`. Users read the registry
through this module (``hinge_laws.HINGE_LAWS``), so a law registered by
rebinding it (as a test does) is seen everywhere.
"""
from __future__ import annotations

from workbook.model.case import Case, Hinge
from workbook.scene.bearing import PER_DIRECTION
from workbook.scene.hinge_law import CLEARANCE
from workbook.scene.hinge_law_base import SPRING_DAMPER, HingeLaw

__all__ = ["HINGE_LAWS", "law_of", "nonlinear_hinges", "nonlinear_reason", "linear_note"]

#: The laws in order of precedence (a hinge takes the first that applies).
HINGE_LAWS: tuple[HingeLaw, ...] = (CLEARANCE, PER_DIRECTION)


def law_of(case: Case, hinge: Hinge) -> HingeLaw:
    """The law *hinge* of *case* is built with."""
    return next((law for law in HINGE_LAWS if law.applies(case, hinge)), SPRING_DAMPER)


def nonlinear_hinges(case: Case) -> dict[HingeLaw, list[Hinge]]:
    """The hinges built with a nonlinear law (they make the scene nonlinear), by law; empty for a linear scene."""
    found: dict[HingeLaw, list[Hinge]] = {}
    for hinge in case.hinges:
        law = law_of(case, hinge)
        if law.nonlinear:
            found.setdefault(law, []).append(hinge)
    return found


def nonlinear_reason(case: Case) -> str:
    """Why the scene of *case* is nonlinear, in words ("" when it is linear)."""
    return "; ".join(f"{law.name} on {', '.join(repr(h.name) for h in hinges)} makes the scene nonlinear"
                     for law, hinges in nonlinear_hinges(case).items())


def linear_note() -> str:
    """What a linear scene has none of: ``"no hinge clearance"``."""
    return "no " + " or ".join(law.name for law in HINGE_LAWS if law.nonlinear)
