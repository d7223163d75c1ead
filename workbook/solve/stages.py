"""What every stage of a run shares: its wall-time record, progress
reporting, and the warnings of the link models it uses."""
from __future__ import annotations

import time
from contextlib import contextmanager
from typing import Callable

from flexbodies.selection import LOW_FREQUENCY_RATIO
from workbook.model.case import Case
from workbook.scene.build import scene_warnings

__all__ = ["ProgressFactory", "timed", "link_warnings"]


#: Makes a progress reporter for a long stage: ``factory(description, total)``
#: returns ``(update, close)``; ``update(done)`` reports the amount done so
#: far (links reduced, or simulated seconds), ``close()`` ends the stage.
ProgressFactory = Callable[[str, float], tuple]


@contextmanager
def timed(timings: dict, stage: str):
    """Add the wall time of the ``with`` block to ``timings[stage]``, s."""
    start = time.perf_counter()
    yield
    timings[stage] = timings.get(stage, 0.0) + time.perf_counter() - start


def link_warnings(case: Case, reduced: dict) -> list[str]:
    """Warnings of the links whose model is unsafe at the run's excitation:
    flexible links whose mode selection is (``flexbodies.ModeDecision.warning``),
    and rigid links excited as high as that (their own dynamics are missing
    as well), plus the scene's own warnings (:func:`workbook.scene.build.scene_warnings`)."""
    warnings = []
    for name, link in reduced.items():
        decision = link.decision
        if not decision.warning:
            continue
        if case.link_is_flexible(name):
            warnings.append(f"link {name!r}: {decision.warning}")
        else:
            warnings.append(f"link {name!r} is rigid although the excitation {decision.excitation_hz:g} Hz is "
                            f"{decision.ratio:.2f} of its mounted fundamental {decision.fundamental_hz:.0f} Hz "
                            f"(a link without its own modes needs < {LOW_FREQUENCY_RATIO}): its own dynamics are "
                            f"missing; make it flexible")
    return warnings + scene_warnings(case)
