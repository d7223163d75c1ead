"""Runs on a flexible pylon given as a point dynamic stiffness at its pins.

The case's :class:`~workbook.model.pylon_impedance.PylonImpedance` ``Z_p(f)``
enters exactly in the frequency domain: the mount's four-pole set at the
excitation's frequency (:func:`workbook.solve.four_pole.condense`, formed
from the harmonic model of the preloaded scene with the pins on rigid
ground) is closed by the pylon,

    (Z_e + K11 - K12 (K22 + Z_p)^-1 K21) x1 = B f,    x2 = -(K22 + Z_p)^-1 K21 x1,

and the pylon is loaded with ``Z_p x2`` at each pin. The pylon force is the
sum of the pin forces, whose amplitudes give T and eta as on a rigid pylon.

The time domain cannot take a dynamic stiffness that is only known at
frequencies (a convolution kernel would need its causal, stable fit over all
frequencies, which a table over a band does not give): it refuses the case.
"""
from __future__ import annotations

import time

import numpy as np

from workbook.answers.model_card import EffectEntry, ModelCard, model_card
from workbook.answers.results import ExcitationResult
from workbook.errors import CaseError
from workbook.model.case import Case, SingleFrequencyExcitation
from workbook.solve.four_pole import condense
from workbook.solve.harmonic import excitation_phasor
from workbook.solve.method import MethodChoice
from workbook.solve.modes import mounted_modes
from workbook.solve.stages import link_warnings

__all__ = ["refuse_time_domain", "pylon_stiffness", "solve_on_pylon", "pylon_effect"]


def refuse_time_domain(case: Case, reason: str) -> None:
    """Refuse a time-domain run of *case* when it has a pylon impedance.

    Raises
    ------
    workbook.errors.CaseError
        The case gives a pylon impedance: a table against frequency has no
        time-domain counterpart.
    """
    impedance = case.pylon_impedance
    if impedance is not None:
        raise CaseError(f"case {case.name!r}", "pylon_impedance", impedance.source,
                        f"no frequency-dependent pylon impedance in the time domain ({reason}): a dynamic "
                        f"stiffness tabulated against frequency has no time-domain model here; run the "
                        f"frequency domain (method 'auto' or 'frequency', no hinge clearance) or remove the "
                        f"pylon impedance")


def pylon_effect(case: Case, seconds: float) -> EffectEntry:
    """The model-card entry of the pylon impedance of *case* (which must have one)."""
    return EffectEntry(
        "flexible pylon (point dynamic stiffness)", True,
        f"{case.pylon_impedance.describe()}; real and imaginary parts interpolated linearly in frequency; "
        f"enters exactly through the mount's four-pole set closed by the pylon (6 engine + "
        f"{3 * len(case.pylon_pins())} pin coordinates, {seconds:.3g} s); the mounted modes listed are "
        f"those on a rigid pylon")


def _result(excitation: SingleFrequencyExcitation, pins: list, pin_forces: np.ndarray,
            steady_tolerance: float) -> ExcitationResult:
    empty = np.zeros((0, 3))
    return ExcitationResult(
        name=excitation.name, frequency_hz=excitation.frequency,
        excitation_amplitude=excitation.force_amplitude, pylon_amplitude=np.abs(pin_forces.sum(axis=0)),
        hinge_amplitudes={pin: np.abs(force) for pin, force in zip(pins, pin_forces)},
        pylon_hinges=list(pins), steady_change=0.0, steady_tolerance=steady_tolerance,
        warnings=[], time=np.zeros(0), hinge_histories={pin: empty for pin in pins},
        pylon_history=empty, excitation_history=empty, window=slice(0, 0))


def pylon_stiffness(case: Case, points: tuple[SingleFrequencyExcitation, ...]) -> np.ndarray:
    """``Z_p`` of the pylon impedance of *case* at the frequencies of *points*, in the order of
    ``case.pylon_pins()``, complex, shape (len(points), pins, 3, 3), N/m.

    Raises
    ------
    workbook.errors.CaseError
        An excitation frequency outside the impedance table.
    """
    impedance = case.pylon_impedance
    return impedance.at([x.frequency for x in points], impedance.pin_order(case.pylon_pins()))


def solve_on_pylon(case: Case, prepared, points: tuple[SingleFrequencyExcitation, ...], stiffness: np.ndarray,
                   method: MethodChoice) -> tuple[list[ExcitationResult], dict[str, ModelCard], dict]:
    """Frequency-domain answers of *points* on the pylon impedance of *case*.

    Parameters
    ----------
    case : Case
        With a pylon impedance.
    prepared : PreparedScene
        The scene of ``mount_case(case)`` prepared with its harmonic model.
    points : tuple of RotatingForce or HarmonicForce
    stiffness : ndarray, complex, shape (len(points), pins, 3, 3)
        The pylon's point dynamic stiffness at each excitation (:func:`pylon_stiffness`), N/m.
    method : MethodChoice

    Returns
    -------
    runs : list of ExcitationResult
        The pylon force is the sum of the pin forces; ``hinge_amplitudes``
        holds the force on the pylon at each pin (named by its hinges).
    cards : dict of str to ModelCard
    preloads : dict of str to Preload

    Raises
    ------
    workbook.errors.FourPoleError
        A singular set (an undamped resonance at an excitation frequency).
    """
    mounted = mounted_modes(prepared.modes)
    runs, cards, preloads = [], {}, {}
    for excitation, pylon in zip(points, stiffness):
        start = time.perf_counter()
        pole = condense(prepared.model, case, [excitation.frequency], points=[excitation.point])
        response = pole.respond(excitation_phasor(excitation), excitation.point, pylon[None])[0]
        seconds = time.perf_counter() - start
        result = _result(excitation, pole.pins, response.pin_forces, case.analysis.steady_tolerance)
        result.warnings.extend(link_warnings(case, prepared.scene.reduced))
        timings = dict(prepared.timings, **{"harmonic solve on the pylon": seconds})
        solver = {"analysis": "frequency domain on a flexible pylon: (Z_e + K11 - K12 (K22 + Z_p)^-1 K21) x1 = B f, "
                              "pin forces Z_p x2, x2 = -(K22 + Z_p)^-1 K21 x1",
                  "independent coordinates": prepared.model.dof,
                  "static equilibrium check": f"relative {case.analysis.equilibrium_tolerance:g}"}
        card = model_card(prepared.scene, prepared.preload, mounted, None, timings, method, solver)
        card.effects.append(pylon_effect(case, seconds))
        card.run_name = excitation.name
        runs.append(result)
        cards[result.name] = card
        preloads[result.name] = prepared.preload
    return runs, cards, preloads
