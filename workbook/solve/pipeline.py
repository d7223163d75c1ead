"""Run a case: every excitation through reduction, scene, preload, modes,
time integration and amplitude extraction, each stage timed."""
from __future__ import annotations

import logging
from typing import Union

from workbook.answers.model_card import model_card
from workbook.answers.results import MountResult
from workbook.model.case import Case, SingleFrequencyExcitation, Sweep
from workbook.scene.build import build_scene, reduce_links
from workbook.solve.frequency_pipeline import run_case_frequency
from workbook.solve.guards import run_label
from workbook.solve.method import FREQUENCY, MethodChoice, choose_method
from workbook.solve.modes import linearize, modes_of, mounted_modes
from workbook.solve.preload import solve_preload
from workbook.solve.stages import ProgressFactory, link_warnings, timed
from workbook.solve.time_domain import extract, integrate, plan_run

__all__ = ["run_excitation", "run_case"]

log = logging.getLogger(__name__)

def run_excitation(case: Case, excitation: SingleFrequencyExcitation, *,
                   reduce_for: Union[SingleFrequencyExcitation, None] = None,
                   progress: Union[ProgressFactory, None] = None,
                   method: Union[MethodChoice, None] = None):
    """Run one single-frequency excitation of *case* in the time domain.

    Parameters
    ----------
    case : Case
    excitation : RotatingForce or HarmonicForce
    reduce_for : RotatingForce or HarmonicForce, optional
        The excitation whose frequency the link reductions must serve
        (default: *excitation*; a sweep passes its highest frequency so that
        every point uses the same link models).
    progress : callable, optional
        Progress factory for the long stages (see :data:`ProgressFactory`).
    method : MethodChoice, optional
        Why the time domain answers this run, for the model card.

    Returns
    -------
    result : ExcitationResult
    card : ModelCard
    preload : Preload

    Raises
    ------
    workbook.solve.guards.SimulationError
        A mechanism or a failed equilibrium (preload stage), an excitation on
        an undamped mode, a failed or diverging integration, or an exhausted
        time budget; the message says when and why.
    """
    timings = {}
    with timed(timings, "reduce links"):
        reduction = reduce_for or excitation
        if progress is None or not case.links:
            reduced = reduce_links(case, reduction)
        else:
            update, close = progress(f"{excitation.name}: reducing links", len(case.links))
            try:
                reduced = reduce_links(case, reduction, update)
            finally:
                close()
    with timed(timings, "build scene"):
        scene = build_scene(case, excitation, reduced=reduced)
    with scene:  # frees Exudyn's system, which dropping the scene does not
        with timed(timings, "static preload"):
            preload = solve_preload(scene)
        with timed(timings, "mounted modes"):
            mounted = mounted_modes(modes_of(linearize(scene)))
        plan = plan_run(case.analysis, scene.excitation.signal, mounted,
                        where=run_label(case.name, excitation.name))
        log.info("%s / %s: %d steps of %.3g s", case.name, excitation.name, plan.steps, plan.step)
        with timed(timings, "time integration"):
            if progress is None:
                histories = integrate(scene, plan)
            else:
                update, close = progress(f"{excitation.name} ({excitation.frequency:g} Hz)", plan.end_time)
                try:
                    histories = integrate(scene, plan, update)
                finally:
                    close()
        with timed(timings, "amplitude extraction"):
            result = extract(scene, plan, histories)
        result.warnings.extend(link_warnings(case, reduced))
        card = model_card(scene, preload, mounted, plan, timings, method)
    card.solver["step retries"] = "; ".join(histories.retries) or "none: Newton converged at the planned step"
    return result, card, preload


def run_case(case: Case, *, progress: Union[ProgressFactory, None] = None) -> MountResult:
    """Run every excitation of *case* (sweeps frequency by frequency) by the
    method the case asks for (:func:`workbook.solve.method.choose_method`).

    Returns
    -------
    MountResult
    """
    method = choose_method(case)
    if method.method == FREQUENCY:
        return run_case_frequency(case, method, progress=progress)
    runs, cards, preloads = [], {}, {}
    for item in case.excitations:
        points = item.expand() if isinstance(item, Sweep) else (item,)
        for excitation in points:
            result, card, preload = run_excitation(case, excitation, reduce_for=points[-1], progress=progress,
                                                   method=method)
            runs.append(result)
            cards[result.name] = card
            preloads[result.name] = preload
    return MountResult(case.name, runs, cards, preloads)
