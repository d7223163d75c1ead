"""Runs on a flexible pylon: a point dynamic stiffness table, a box beam or a mesh at the pins.

The mount's four-pole set at the excitation's frequency
(:func:`workbook.solve.four_pole.condense`, formed from the harmonic model
of the preloaded scene with the pins on rigid ground) is closed by the
pylon, exactly in the frequency domain. The case's
:class:`~workbook.model.pylon.PylonModel` gives at the pins
(:meth:`~workbook.model.pylon.PylonModel.pins_at`) either

- a point dynamic stiffness ``Z_p(f)`` per pin (an impedance table):
  ``(Z_e + K11 - K12 (K22 + Z_p)^-1 K21) x1 = B f``,
  ``x2 = -(K22 + Z_p)^-1 K21 x1``, the pylon loaded with ``Z_p x2``; or
- its compliance ``G`` at the pins, coupled through the structure (the box
  beam, the reduced mesh):
  ``(Z_e + K11 - K12 G (I + K22 G)^-1 K21) x1 = B f``, the pylon loaded with
  ``-(I + K22 G)^-1 K21 x1``.

The pylon force is the sum of the pin forces, whose amplitudes give T and
eta as on a rigid pylon.

The time domain refuses them all: a dynamic stiffness known only at table
frequencies has no time-domain model here (a convolution kernel would need
its causal, stable fit over all frequencies, which a table over a band does
not give), and the box beam and the mesh are built as a frequency-domain
compliance, not as bodies of the time-domain scene.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import cast

import numpy as np

from workbook.answers.model_card import EffectEntry, model_card
from workbook.answers.results import ExcitationResult
from workbook.errors import CaseError
from workbook.model.case import Case, SingleFrequencyExcitation
from workbook.model.pylon import PinDynamics
from workbook.solve.four_pole import condense
from workbook.solve.harmonic import point_phasors
from workbook.solve.method import MethodChoice
from workbook.solve.modes import mounted_modes
from workbook.solve.stages import link_warnings

__all__ = ["PylonAt", "refuse_time_domain", "pylon_at", "solve_on_pylon"]


@dataclass(frozen=True)
class PylonAt:
    """The case's flexible pylon at the frequencies of its excitations.

    Attributes
    ----------
    dynamics : PinDynamics
        Its stiffness or compliance at the pins per excitation, and warnings.
    effect : EffectEntry
        The model-card entry.
    seconds : float
        Wall time of forming it, s.
    """

    dynamics: PinDynamics
    effect: EffectEntry
    seconds: float

    def closure(self, j: int) -> dict:
        """The keyword arguments of :meth:`~workbook.solve.four_pole.FourPole.respond` at excitation *j*."""
        if self.dynamics.stiffness is not None:
            return {"pylon": self.dynamics.stiffness[j][None]}
        assert self.dynamics.compliance is not None
        return {"compliance": self.dynamics.compliance[j][None]}

    def warnings(self, j: int) -> list[str]:
        """What the pylon model cannot resolve at excitation *j* (an impedance table too coarse across a
        resonance)."""
        return self.dynamics.warnings[j] if self.dynamics.warnings else []


def refuse_time_domain(case: Case, reason: str) -> None:
    """Refuse a time-domain run of *case* when it has a flexible pylon.

    Raises
    ------
    workbook.errors.CaseError
        The case gives a flexible pylon (``Case.pylon``).
    """
    if case.pylon is not None:
        raise CaseError(f"case {case.name!r}", "pylon", case.pylon.label, case.pylon.time_domain_refusal(reason))


def pylon_at(case: Case, points: tuple[SingleFrequencyExcitation, ...]) -> PylonAt:
    """The flexible pylon of *case* at the frequencies of *points*, in the order of ``case.pylon_pins()``.

    Raises
    ------
    workbook.errors.CaseError
        Input the pylon model cannot answer (:meth:`~workbook.model.pylon.PylonModel.pins_at`):
        an excitation frequency outside the impedance table, a pin beyond the beam's ends, a mesh
        that cannot be read.
    """
    start = time.perf_counter()
    pylon = case.pylon
    assert pylon is not None
    highest = max(x.frequency for x in (*case.single_frequency_excitations(), *points))  # one reduction serves every run
    dynamics = pylon.pins_at(case.pylon_pins(), [x.frequency for x in points], highest)
    return PylonAt(dynamics, EffectEntry(pylon.effect, True, dynamics.detail), time.perf_counter() - start)


def _result(excitation: SingleFrequencyExcitation, pins: list, pin_forces: np.ndarray,
            steady_tolerance: float) -> ExcitationResult:
    return ExcitationResult(
        name=excitation.name, frequency_hz=excitation.frequency,
        excitation_amplitude=excitation.force_amplitude, pylon_amplitude=np.abs(pin_forces.sum(axis=0)),
        hinge_amplitudes={pin: np.abs(force) for pin, force in zip(pins, pin_forces, strict=True)},
        pylon_hinges=list(pins), steady_change=0.0, steady_tolerance=steady_tolerance,
        warnings=[],
        hinge_phasors=dict(zip(pins, np.asarray(pin_forces, dtype=complex), strict=True)))


def solve_on_pylon(case: Case, prepared, points: tuple[SingleFrequencyExcitation, ...], pylon: PylonAt,
                   method: MethodChoice) -> list[ExcitationResult]:
    """Frequency-domain answers of *points* on the flexible pylon of *case*.

    Parameters
    ----------
    case : Case
        With a flexible pylon (``Case.pylon``).
    prepared : PreparedScene
        The scene of ``mount_case(case)`` prepared with its harmonic model.
    points : tuple of RotatingForce, HarmonicForce or Imbalance
    pylon : PylonAt
        The pylon at the frequencies of *points* (:func:`pylon_at`).
    method : MethodChoice

    Returns
    -------
    list of ExcitationResult
        The pylon force is the sum of the pin forces; ``hinge_amplitudes``
        holds the force on the pylon at each pin (named by its hinges). Each
        with its model card and preload.

    Raises
    ------
    workbook.errors.FourPoleError
        A singular set (an undamped resonance at an excitation frequency).
    """
    mounted = mounted_modes(prepared.modes)
    runs = []
    for j, excitation in enumerate(points):
        start = time.perf_counter()
        forces = point_phasors(excitation)  # one force, or one per imbalance plane: their responses add
        pole = condense(prepared.model, case, [excitation.frequency], points=[point for point, _ in forces])
        pin_forces = cast(np.ndarray, sum(pole.respond(phasor, point, **pylon.closure(j))[0].pin_forces for point, phasor in forces))
        seconds = time.perf_counter() - start
        result = _result(excitation, pole.pins, pin_forces, case.analysis.steady_tolerance)
        result.warnings.extend(link_warnings(case, prepared.scene.reduced))
        result.warnings.extend(pylon.warnings(j))
        timings = dict(prepared.timings, **{"pylon": pylon.seconds, "harmonic solve on the pylon": seconds})
        solver = {"analysis": "frequency domain on a flexible pylon: the mount's four-pole set (6 engine + "
                              f"{3 * len(pole.pins)} pin coordinates) closed by the pylon",
                  "independent coordinates": prepared.model.dof,
                  "static equilibrium check": f"relative {case.analysis.equilibrium_tolerance:g}"}
        card = model_card(prepared.scene, prepared.preload, mounted, None, timings, method, solver)
        card.effects.append(EffectEntry(pylon.effect.name, True, f"{pylon.effect.detail}; exact through the "
                                        f"mount's four-pole set; the mounted modes listed are those on a rigid "
                                        f"pylon"))
        card.run_name = excitation.name
        result.model_card, result.preload = card, prepared.preload
        runs.append(result)
    return runs
