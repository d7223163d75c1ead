"""Runs of a case workbook: one excitation of the case with optional overrides.

A :class:`RunSpec` is one row of the Runs sheet; :func:`case_for_run` makes
the case that row asks for. Nothing here runs a simulation, so the reader
can check every run's case without Exudyn.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from workbook.model.case import Case, ModeRequest, Sweep

__all__ = ["RunSpec", "TestPoint", "case_for_run", "FIDELITY_RIGID"]

#: Fidelity value that makes every link rigid.
FIDELITY_RIGID = "rigid"


@dataclass(frozen=True)
class RunSpec:
    """One run: an excitation of the case and what it overrides (None: as in the case).

    Attributes
    ----------
    name : str
        Run name.
    excitation : str
        Name of an excitation of the case.
    frequency : float or None
        Excitation frequency, Hz (single-frequency excitations only).
    amplitude : float or None
        Excitation force amplitude, N.
    fidelity : str, int, float or None
        ``"rigid"`` (every link rigid), or a link ``modes`` value for every
        link: ``"static"``, ``"auto"``, a mode count or a cut-off in Hz.
    gap : float or None
        Radial clearance of every hinge, m.
    hinge_stiffness : float or None
        Stiffness of every hinge, N/m.
    hinge_damping : float or None
        Damping of every hinge, N s/m.
    preload : bool or None
        Solve the static loads first.
    steps_per_period, measured_periods : int or None
    settle_time : float or None
        Fixed settle time, s.
    """

    name: str
    excitation: str
    frequency: float | None = None
    amplitude: float | None = None
    fidelity: ModeRequest | None = None
    gap: float | None = None
    hinge_stiffness: float | None = None
    hinge_damping: float | None = None
    preload: bool | None = None
    steps_per_period: int | None = None
    settle_time: float | None = None
    measured_periods: int | None = None


@dataclass(frozen=True)
class TestPoint:
    """A measured force amplitude of a run.

    Attributes
    ----------
    run : str
    location : str
        ``"pylon sum"`` or a hinge name.
    direction : str
        ``"x"``, ``"y"`` or ``"z"``.
    frequency : float or None
        Hz; picks the point of a sweep run.
    amplitude : float
        Measured amplitude, N.
    """

    run: str
    location: str
    direction: str
    frequency: float | None
    amplitude: float


def _replace_excitation(excitation, run: RunSpec):
    """The excitation with the run's frequency and amplitude."""
    changes: dict[str, Any] = {}
    if run.frequency is not None:
        changes.update(frequency_hz=run.frequency, rpm=None)
    if run.amplitude is not None:
        changes.update(amplitude=run.amplitude)
        if hasattr(excitation, "unbalance"):
            changes.update(unbalance=None)
    return dataclasses.replace(excitation, **changes) if changes else excitation


def case_for_run(case: Case, run: RunSpec) -> Case:
    """The case of one run: its excitation only, with the run's overrides.

    Raises
    ------
    KeyError
        The excitation is not in the case.
    CaseError
        An override is not valid (named by the case field at fault).
    """
    excitation = {e.name: e for e in case.excitations}[run.excitation]
    if isinstance(excitation, Sweep):
        excitation = dataclasses.replace(excitation, template=_replace_excitation(excitation.template, run))
    else:
        excitation = _replace_excitation(excitation, run)
    links, effects = case.links, case.effects
    if run.fidelity == FIDELITY_RIGID:
        effects = dataclasses.replace(effects, flexible_links=False)
    elif run.fidelity is not None:
        links = tuple(dataclasses.replace(link, modes=run.fidelity) for link in links)
        effects = dataclasses.replace(effects, flexible_links=True)
    if run.preload is not None:
        effects = dataclasses.replace(effects, preload=run.preload)
    hinge_changes: dict[str, Any] = {name: value for name, value in (("radial_clearance", run.gap),
                                                     ("stiffness", run.hinge_stiffness),
                                                     ("damping", run.hinge_damping)) if value is not None}
    hinges = tuple(dataclasses.replace(h, **hinge_changes) for h in case.hinges) if hinge_changes else case.hinges
    analysis_changes = {name: getattr(run, name) for name in ("steps_per_period", "settle_time", "measured_periods")
                        if getattr(run, name) is not None}
    analysis = dataclasses.replace(case.analysis, **analysis_changes) if analysis_changes else case.analysis
    return dataclasses.replace(case, name=f"{case.name} / {run.name}", links=links, hinges=hinges,
                               excitations=(excitation,), effects=effects, analysis=analysis,
                               speed_spectra=tuple(s for s in case.speed_spectra if s.excitation == excitation.name))
