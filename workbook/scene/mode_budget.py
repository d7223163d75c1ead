"""A flexible body asked for more fixed-interface modes than a reduction keeps,
refused as bad input naming the excitation (or the body's cut-off) at fault.

An excitation frequency sets the modes a flexible link or casing keeps (up
to :data:`flexbodies.selection.MODE_MARGIN` times it, under
``modes="auto"``). A frequency far above a mount's range (a speed in rpm
typed as Hz: 14910 Hz for 14910 rpm) would ask for thousands of modes;
:func:`flexbodies.craig_bampton.fixed_interface_set` refuses before it
computes them, and :func:`mode_budget_error` says which input to change.
"""
from __future__ import annotations

from flexbodies.craig_bampton import MODE_BUDGET, ModeBudgetExceeded
from flexbodies.selection import MODE_MARGIN
from workbook.errors import CaseError
from workbook.model.case import Case, ModeRequest

__all__ = ["mode_budget_error"]


def mode_budget_error(case: Case, body: str, modes: ModeRequest, error: ModeBudgetExceeded) -> CaseError:
    """The case error for *body* (e.g. ``"link 'thrust-left'"``) whose reduction refused.

    Parameters
    ----------
    case : Case
    body : str
        The body, in words.
    modes : {"auto"} or float
        Its mode request: a cut-off of its own (Hz) names the body's
        ``modes``; ``"auto"`` names the excitation whose frequency asked.
    error : flexbodies.craig_bampton.ModeBudgetExceeded

    Returns
    -------
    CaseError
    """
    asks = (f"about {error.estimate} fixed-interface modes of {body} (below {error.cutoff_hz:.6g} Hz), more than "
            f"the {MODE_BUDGET} a reduction keeps")
    if isinstance(modes, float):
        return CaseError(body, "modes", modes, f"a cut-off below about {error.served_hz:.5g} Hz, or a mode count: "
                                               f"{modes:g} Hz asks for {asks}")
    frequency = error.cutoff_hz / MODE_MARGIN
    excitation = min(case.excitations, key=lambda item: abs(item.frequency - frequency), default=None)
    name = "excitation" if excitation is None else f"excitation {excitation.name!r}"
    rpm = getattr(excitation, "rpm", None)
    if hasattr(excitation, "frequencies_hz"):
        field, value = "frequencies_hz", frequency          # a sweep: its highest frequency
    else:
        field, value = ("rpm", rpm) if rpm is not None else ("frequency_hz", frequency)
    hint = "" if rpm is not None else (f"; is it a speed in rpm? ({frequency:.6g} rpm is "
                                       f"{frequency / 60:.4g} Hz: give it as rpm)")
    return CaseError(name, field, value,
                     f"a frequency whose link and casing modes a reduction can keep (up to about "
                     f"{error.served_hz / MODE_MARGIN:.5g} Hz for {body}): an excitation of {frequency:.6g} Hz asks "
                     f"for {asks}{hint}. Otherwise make {body} rigid or give it a mode count")
