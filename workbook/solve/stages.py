"""What every stage of a run shares: its wall-time record, progress
reporting, and the warnings of the link models it uses."""
from __future__ import annotations

import time
from contextlib import contextmanager
from typing import Callable

from workbook.model.case import Case

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
    """Warnings of the flexible links whose mode selection is unsafe at the
    run's excitation (``flexbodies.ModeDecision.warning``)."""
    return [f"link {name!r}: {link.decision.warning}" for name, link in reduced.items()
            if case.link_is_flexible(name) and link.decision.warning]
