"""Run a case in the frequency domain: reduction, scene, preload, harmonic model,
then one complex solve per excitation frequency, each stage timed.

A single excitation and a whole sweep each cost one scene, one preload and
one linearisation (the sweep's links are reduced for its highest frequency,
as in the time domain); every frequency is then one dense complex solve.
The answers are the same :class:`~workbook.answers.results.ExcitationResult` and
:class:`~workbook.answers.results.MountResult` as in the time domain (without time
histories), so they tabulate, plot and serialise alike.
"""
from __future__ import annotations

import dataclasses
import logging
import time
from typing import Union

from workbook.answers.model_card import model_card
from workbook.answers.results import MountResult
from workbook.model.case import Case, SingleFrequencyExcitation, Sweep
from workbook.scene.build import build_scene, reduce_links
from workbook.scene.hinge_law import linearised_gap_warnings
from workbook.solve.guards import check_undamped_resonance, run_label
from workbook.solve.harmonic import COORDINATE_STEP, VELOCITY_STEP, HarmonicModel, harmonic_model
from workbook.solve.method import MethodChoice, choose_method
from workbook.solve.modes import modes_of, mounted_modes
from workbook.solve.preload import solve_preload
from workbook.solve.stages import ProgressFactory, link_warnings, timed

__all__ = ["prepare", "PreparedScene", "results_of", "run_case_frequency"]

log = logging.getLogger(__name__)

#: Relative distance from an undamped mounted mode at which the harmonic
#: solution is refused (the dynamic matrix is singular on the mode).
RESONANCE_BAND = 1e-6


@dataclasses.dataclass
class PreparedScene:
    """A preloaded scene with its harmonic model and mounted modes.

    Attributes
    ----------
    scene : workbook.scene.build.Scene
    preload : workbook.solve.preload.Preload
    model : HarmonicModel
    modes : list of workbook.solve.modes.Mode
        Every linearised mode, ascending.
    timings : dict of str to float
        Wall time per stage, s.
    """

    scene: object
    preload: object
    model: HarmonicModel
    modes: list
    timings: dict


def prepare(case: Case, excitation: SingleFrequencyExcitation, *, reduce_for=None, reduced=None) -> PreparedScene:
    """Reduce, build, preload and linearise the scene of *case* with *excitation*.

    Parameters
    ----------
    case : Case
    excitation : RotatingForce or HarmonicForce
        Sets the excitation point (and, by default, the reduction frequency).
    reduce_for : RotatingForce or HarmonicForce, optional
        The excitation whose frequency the link reductions must serve.
    reduced : dict, optional
        Reduced links to use (skips the reduction).

    The caller closes the prepared scene (``with prepared.scene:``) when done.
    """
    timings = {}
    with timed(timings, "reduce links"):
        if reduced is None:
            reduced = reduce_links(case, reduce_for or excitation)
    with timed(timings, "build scene"):
        scene = build_scene(case, excitation, reduced=reduced)
    try:
        with timed(timings, "static preload"):
            preload = solve_preload(scene)
        with timed(timings, "linearisation"):
            model = harmonic_model(scene)
        with timed(timings, "mounted modes"):
            modes = modes_of(model.linearization)
    except BaseException:
        scene.close()
        raise
    return PreparedScene(scene, preload, model, modes, timings)


def _solver_entries(case: Case, model: HarmonicModel) -> dict:
    return {
        "analysis": "frequency domain: (K - w^2 M + i w D) z = B f per frequency (dense complex solve), "
                    "F_hinge = (C_k + i w C_d) z",
        "linearisation": "Exudyn ComputeLinearizedSystem at the preloaded state (geometric stiffness included); "
                         "Euler-parameter constraints projected out (null space by SVD)",
        "independent coordinates": model.dof,
        "input and outputs": f"central differences of Exudyn's engine-point position and the hinge (and "
                             f"transducer) Force outputs (coordinate step {COORDINATE_STEP:g}, velocity step "
                             f"{VELOCITY_STEP:g})",
        "damping": "viscous: hinge damping and Rayleigh link damping exactly as in the time domain, plus the "
                   "rotors' gyroscopic coupling when built",
        "static equilibrium check": f"relative {case.analysis.equilibrium_tolerance:g}",
    }


def results_of(case: Case, prepared: PreparedScene, points: tuple, method: MethodChoice, *,
               progress: Union[ProgressFactory, None] = None):
    """Answers of the single-frequency excitations *points* on a prepared scene
    (all at the excitation point the scene was prepared with or any other
    point of the engine).

    Returns
    -------
    runs : list of ExcitationResult
    cards : dict of str to ModelCard
    preloads : dict of str to Preload
    """
    mounted = mounted_modes(prepared.modes)
    solver = _solver_entries(case, prepared.model)
    gaps = [h for h in case.hinges if prepared.scene.hinges[h.name].clearance]
    update, close = progress(f"{points[0].name}: frequencies", len(points)) if progress else (None, None)
    runs, cards, preloads = [], {}, {}
    try:
        for done, excitation in enumerate(points, start=1):
            check_undamped_resonance(run_label(case.name, excitation.name), excitation.frequency, mounted,
                                     RESONANCE_BAND, "the response grows without bound: no steady state exists")
            start = time.perf_counter()
            result = prepared.model.result(excitation, case.analysis.steady_tolerance)
            result.warnings.extend(link_warnings(case, prepared.scene.reduced))
            result.warnings.extend(linearised_gap_warnings(gaps, prepared.preload.hinge_forces,
                                                           result.hinge_amplitudes))
            timings = dict(prepared.timings, **{"harmonic solve": time.perf_counter() - start})
            card = model_card(prepared.scene, prepared.preload, mounted, None, timings, method, solver)
            card.run_name = excitation.name
            runs.append(result)
            cards[result.name] = card
            preloads[result.name] = prepared.preload
            if update:
                update(done)
    finally:
        if close:
            close()
    return runs, cards, preloads


def run_case_frequency(case: Case, method: Union[MethodChoice, None] = None, *,
                       progress: Union[ProgressFactory, None] = None) -> MountResult:
    """Run every excitation of *case* in the frequency domain.

    Parameters
    ----------
    case : Case
    method : MethodChoice, optional
        Recorded on the model cards (default: :func:`choose_method` of the case).
    progress : callable, optional

    Returns
    -------
    MountResult
    """
    method = method or choose_method(case)
    runs, cards, preloads = [], {}, {}
    for item in case.excitations:
        points = item.expand() if isinstance(item, Sweep) else (item,)
        prepared = prepare(case, points[0], reduce_for=points[-1])
        with prepared.scene:  # frees Exudyn's system, which dropping the scene does not
            item_runs, item_cards, item_preloads = results_of(case, prepared, points, method, progress=progress)
        runs += item_runs
        cards.update(item_cards)
        preloads.update(item_preloads)
    log.info("%s: %d frequency-domain runs", case.name, len(runs))
    return MountResult(case.name, runs, cards, preloads)
