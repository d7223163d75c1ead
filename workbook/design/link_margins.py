"""Static margins of a design's links under the limit load cases, on the fast path, with their derivatives.

A limit load case (:mod:`workbook.solve.load_cases`) is a static solve with
other static loads (a fail-safe one without a link): :func:`load_case_mounts`
prepares a linear mount on each (:func:`~workbook.solve.load_cases.load_case_scene_case`,
with the case's highest-frequency excitation as its one item, for the links
to be reduced as ``mountwb loads`` reduces them), whose preloaded state is
then the design's state under that load case. A link's stress is its stress
shapes times its modal coordinates there; its margin of safety is the
smaller of ``F_ty / sigma_vM - 1`` and ``F_tu / (FS sigma_vM) - 1`` at the
peak von Mises stress over its nodes, as :func:`~workbook.solve.load_cases.link_stress`
gives them; its derivative follows from the coordinates' derivative at that node.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from flexbodies.stress import state_stress, von_mises
from workbook.design.linear_mount import ItemSolution, LinearMount
from workbook.design.link_fatigue import VON_MISES_FORM
from workbook.errors import InputError
from workbook.model.case import Case

__all__ = ["LinkMargin", "load_case_mounts", "link_margins"]


@dataclass(frozen=True)
class LinkMargin:
    """The margin of safety of one link under one load case and its gradient (P,)."""

    link: str
    margin: float
    gradient: np.ndarray


def load_case_mounts(case: Case) -> list:
    """A linear mount per load case of *case*: ``(LoadCase, LinearMount)``.

    Raises
    ------
    InputError
        *case* has no load cases or no single-frequency excitation.
    """
    from workbook.solve.load_cases import load_case_scene_case

    if not case.load_cases:
        raise InputError(f"case {case.name!r}: a link margin constraint needs limit load cases (the Load cases "
                         "sheet, or Case.load_cases); the case has none")
    points = case.single_frequency_excitations()
    if not points:
        raise InputError(f"case {case.name!r}: expected an excitation (the links are reduced for its frequency)")
    highest = max(points, key=lambda point: point.frequency)
    return [(load_case, LinearMount.prepare(dataclasses.replace(load_case_scene_case(case, load_case),
                                                                excitations=(highest,))))
            for load_case in case.load_cases]


def link_margins(solution: ItemSolution, d_state: np.ndarray, factor_of_safety: float) -> list[LinkMargin]:
    """The margin of safety of each link with stress shapes and known strengths at the solved state.

    Parameters
    ----------
    solution : ItemSolution
        The load case's item of a design.
    d_state : ndarray, shape (N, P)
        The derivatives of its state change (full coordinates).
    factor_of_safety : float
        The load case's ultimate over limit load.
    """
    state = solution.prepared.expansion.state + solution.state.dq
    margins = []
    for name, stressed in solution.prepared.stressed.items():
        material = stressed.link.model.material
        strengths = [s for s in (material.yield_strength, None if material.ultimate_strength is None
                                 else material.ultimate_strength / factor_of_safety) if s is not None]
        if not strengths:
            continue
        stress = state_stress(stressed.reduced, state[stressed.coordinates])
        peak = von_mises(stress)
        node = int(np.argmax(peak))
        strength = min(strengths)
        d_stress = stressed.reduced.stress_modes[node] @ d_state[stressed.coordinates]      # (6, P)
        d_peak = stress[node] @ VON_MISES_FORM @ d_stress / peak[node]
        margins.append(LinkMargin(name, float(strength / peak[node] - 1.0), -strength / peak[node] ** 2 * d_peak))
    return margins
