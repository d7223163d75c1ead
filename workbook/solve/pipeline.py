"""Run a case: one sequence of stages for every method.

Every excitation goes through the same stages, each timed:

1. reduce links (for the excitation's frequency, or a sweep's highest);
2. build the scene;
3. static preload, then stress stiffening of the flexible links by their
   axial preload (:mod:`~workbook.solve.stress_stiffening`: the scene is
   rebuilt and preloaded again when a link is stiffened);
4. linearisation and mounted modes (the harmonic model in the frequency
   domain);
5. solve: time integration and amplitude extraction (time domain) or one
   dense complex solve per frequency (frequency domain);
6. answers: the :class:`~workbook.answers.results.ExcitationResult` and its
   model card.

Stages 1-4 are :func:`prepare`. In the frequency domain a single excitation
and a whole sweep each cost one :func:`prepare`; in the time domain every
sweep frequency is its own run (its links reduced for the sweep's highest
frequency so that every point uses the same link models).

The four-pole set of a case (:func:`four_pole`) is its mount's scene
prepared by the same stages, then condensed onto the engine and the pylon
pins (:func:`workbook.solve.four_pole.condense`).
"""
from __future__ import annotations

import dataclasses
import logging
import time

from workbook.answers.model_card import model_card
from workbook.answers.results import ExcitationResult, MountResult
from workbook.model.case import Case, HarmonicForce, Simultaneous, SingleFrequencyExcitation, Sweep
from workbook.scene.build import Scene, build_scene, reduce_links
from workbook.scene.hinge_laws import nonlinear_hinges
from workbook.solve.flexible_pylon import pylon_at, refuse_time_domain, solve_on_pylon
from workbook.solve.four_pole import REPORT_GRID, FourPole, checked_frequencies, condense, frequency_grid, mount_case
from workbook.solve.guards import RESONANCE_BAND, check_undamped_resonance, run_label, singular_solve_guard
from workbook.solve.harmonic import COORDINATE_STEP, VELOCITY_STEP, HarmonicModel, harmonic_model
from workbook.solve.method import FREQUENCY, TIME, MethodChoice, choose_method
from workbook.solve.modes import STIFFNESS_STEP, Mode, linearize, modes_of, mounted_modes
from workbook.solve.preload import Preload, solve_preload
from workbook.solve.simultaneous import extract_simultaneous, plan_simultaneous
from workbook.solve.stages import ProgressFactory, link_warnings, timed
from workbook.solve.steady_start import STEADY, choose_start, steady_start
from workbook.solve.stress_stiffening import stiffen_links
from workbook.solve.sweep_grid import add_grid_warnings
from workbook.solve.time_domain import TimeHistories, extract, integrate, plan_run
from workbook.solve.truncation import describe_truncation, truncation_error

__all__ = ["PreparedScene", "prepare", "run_excitation", "run_in_time", "solve_frequencies", "run_case",
           "four_pole", "report_four_pole"]

log = logging.getLogger(__name__)



@dataclasses.dataclass
class PreparedScene:
    """A preloaded scene with its mounted modes (stages 1-4 of a run).

    Attributes
    ----------
    scene : Scene
    preload : Preload
    modes : list of Mode
        Every linearised mode, ascending.
    model : HarmonicModel or None
        The harmonic model (None when prepared for the time domain without
        ``linear_model``).
    timings : dict of str to float
        Wall time per stage, s.
    """

    scene: Scene
    preload: Preload
    modes: list[Mode]
    model: HarmonicModel | None
    timings: dict[str, float]


def _reduce(case: Case, excitation: SingleFrequencyExcitation | Simultaneous, reduce_for: SingleFrequencyExcitation | Simultaneous,
            progress: ProgressFactory | None) -> dict:
    if progress is None or not case.links:
        return reduce_links(case, reduce_for)
    update, close = progress(f"{excitation.name}: reducing links", len(case.links))
    try:
        return reduce_links(case, reduce_for, update)
    finally:
        close()


def prepare(case: Case, excitation: SingleFrequencyExcitation | Simultaneous, *,
            reduce_for: SingleFrequencyExcitation | None = None, reduced: dict | None = None,
            progress: ProgressFactory | None = None, harmonic: bool = True,
            linear_model: bool = False) -> PreparedScene:
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
    progress : callable, optional
        Progress factory for the link reduction (see :data:`ProgressFactory`).
    harmonic : bool
        Build the scene for the frequency domain (loss factors left to the
        harmonic model as complex stiffness) and its harmonic model; False
        builds it for the time domain (their viscous equivalents built in)
        and linearises it for the mounted modes only.
    linear_model : bool
        With ``harmonic=False``: build the harmonic model of that time-domain
        scene too (its steady state is where a steady start begins).

    Raises
    ------
    workbook.errors.SimulationError
        A mechanism or a failed equilibrium.

    The caller closes the prepared scene (``with prepared.scene:``) when done:
    dropping a scene does not free Exudyn's system.
    """
    timings: dict[str, float] = {}
    with timed(timings, "reduce links"):
        if reduced is None:
            reduced = _reduce(case, excitation, reduce_for or excitation, progress)
    with timed(timings, "build scene"):
        scene = build_scene(case, excitation, reduced=reduced, exact_loss_factors=harmonic)
    try:
        with timed(timings, "static preload"):
            preload = solve_preload(scene)
        with timed(timings, "stress stiffening"):
            scene, preload = stiffen_links(case, excitation, scene, preload)
        model = None
        if harmonic or linear_model:
            with timed(timings, "linearisation"):
                model = harmonic_model(scene)
        with timed(timings, "mounted modes"):
            modes = modes_of(model.linearization if model else linearize(scene))
    except BaseException:
        scene.close()
        raise
    return PreparedScene(scene, preload, modes, model, timings)


def run_excitation(case: Case, excitation: SingleFrequencyExcitation, *,
                   reduce_for: SingleFrequencyExcitation | None = None,
                   progress: ProgressFactory | None = None,
                   method: MethodChoice | None = None) -> ExcitationResult:
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
        Why the time domain answers this run, for the model card (default:
        asked for directly).

    Returns
    -------
    ExcitationResult
        With its model card and preload.

    Raises
    ------
    workbook.errors.SimulationError
        A mechanism or a failed equilibrium (preload stage), an excitation on
        an undamped mode, a failed or diverging integration, or an exhausted
        time budget; the message says when and why.
    """
    return run_in_time(case, excitation, reduce_for=reduce_for, progress=progress, method=method)[0]


def run_in_time(case: Case, excitation: SingleFrequencyExcitation | Simultaneous, *,
                reduce_for: SingleFrequencyExcitation | None = None, progress: ProgressFactory | None = None,
                method: MethodChoice | None = None) -> list[ExcitationResult]:
    """One time-domain run of *excitation*: one result, or one per part of a
    :class:`~workbook.model.case.Simultaneous` excitation (all parts in the
    same run, see :mod:`workbook.solve.simultaneous`, sharing its model card);
    see :func:`run_excitation`."""
    method = method or MethodChoice(TIME, "asked for directly (run_excitation)")
    refuse_time_domain(case, method.reason)
    start = choose_start(case)
    steady = start.start == STEADY
    # from the steady state the excitation acts in full from the first step
    built = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, ramp_periods=0.0)) if steady else case
    prepared = prepare(built, excitation, reduce_for=reduce_for, progress=progress, harmonic=False,
                       linear_model=steady)
    timings, scene = prepared.timings, prepared.scene
    mounted = mounted_modes(prepared.modes)
    with scene:
        where = run_label(case.name, excitation.name)
        if isinstance(excitation, Simultaneous):
            plan = plan_simultaneous(case.analysis, excitation, prepared.modes, where, start.start)
        else:
            assert scene.excitation is not None and scene.excitation.signal is not None
            plan = plan_run(case.analysis, scene.excitation.signal, prepared.modes, where, start.start)
        if steady:
            with timed(timings, "steady start"):
                assert prepared.model is not None
                steady_start(prepared.model, excitation).apply(scene)
        log.info("%s / %s: %d steps of %.3g s from %s", case.name, excitation.name, plan.steps, plan.step,
                 start.start)

        def extract_all(histories: TimeHistories) -> list[ExcitationResult]:
            return (extract_simultaneous(scene, plan, histories, excitation) if isinstance(excitation, Simultaneous)
                    else [extract(scene, plan, histories)])

        def settled(histories: TimeHistories) -> bool:
            return all(result.steady for result in extract_all(histories))

        with timed(timings, "time integration"):
            if progress is None:
                histories = integrate(scene, plan, steady=settled)
            else:
                update, close = progress(f"{excitation.name} ({excitation.frequency:g} Hz)", plan.end_time)
                try:
                    histories = integrate(scene, plan, update, steady=settled)
                finally:
                    close()
        with timed(timings, "amplitude extraction"):
            results = extract_all(histories)
        for result in results:
            result.warnings.extend(link_warnings(case, scene.reduced))
        card = model_card(scene, prepared.preload, mounted, plan, timings, method)
    card.solver["start"] = f"{start.start}: {start.reason}"
    card.solver["windows beyond the plan"] = (
        f"{histories.extended_periods} periods: the first windows disagreed" if histories.extended_periods
        else "none")
    card.solver["step retries"] = "; ".join(histories.retries) or "none: Newton converged at the planned step"
    for result in results:
        result.model_card, result.preload = card, prepared.preload
    return results


def _frequency_solver(case: Case, model: HarmonicModel) -> dict:
    return {
        "analysis": "frequency domain: (K - w^2 M + i w D + i H) z = B f per frequency (dense complex solve), "
                    "F_hinge = (C_k + i C_h + i w C_d) z",
        "linearisation": "at the preloaded state: Exudyn's M and D, K by central differences of Exudyn's equations "
                         f"(coordinate step {STIFFNESS_STEP:g}; geometric stiffness of the preload for "
                         "the rigid-body motion of the engine and the links; the links' elastic modes stiffened by "
                         "their axial preload only where the stress-stiffening effect is on); "
                         "Euler-parameter constraints projected out (null space by SVD)",
        "independent coordinates": model.dof,
        "input and outputs": f"central differences of Exudyn's engine-point position and the hinge (and "
                             f"transducer) Force outputs (coordinate step {COORDINATE_STEP:g}, velocity step "
                             f"{VELOCITY_STEP:g})",
        "damping": "viscous: hinge damping and Rayleigh link damping exactly as in the time domain, plus the "
                   "rotors' gyroscopic coupling when built; structural: the loss factors as complex stiffness "
                   "k (1 + i eta), exact at every frequency",
        "static equilibrium check": f"relative {case.analysis.equilibrium_tolerance:g}",
    }


def solve_frequencies(case: Case, prepared: PreparedScene, points: tuple[SingleFrequencyExcitation, ...],
                      method: MethodChoice, *, progress: ProgressFactory | None = None
                      ) -> list[ExcitationResult]:
    """Frequency-domain answers of the single-frequency excitations *points*
    on a scene prepared with its harmonic model (at the excitation point it
    was prepared with or any other point of the engine).

    Returns
    -------
    list of ExcitationResult
        Each with its model card and preload.
    """
    model = prepared.model
    assert model is not None
    mounted = mounted_modes(prepared.modes)
    solver = _frequency_solver(case, model)
    laws = nonlinear_hinges(case)
    update, close = progress(f"{points[0].name}: frequencies", len(points)) if progress else (None, None)
    runs = []
    try:
        for done, excitation in enumerate(points, start=1):
            where = run_label(case.name, excitation.name)
            check_undamped_resonance(where, excitation.frequency, prepared.modes,
                                     RESONANCE_BAND, "the response grows without bound: no steady state exists")
            start = time.perf_counter()
            with singular_solve_guard(where, excitation.frequency, prepared.modes):
                result = model.result(excitation, case.analysis.steady_tolerance)
            result.warnings.extend(link_warnings(case, prepared.scene.reduced))
            for law, hinges in laws.items():
                result.warnings.extend(law.linearised_warnings(hinges, prepared.preload.hinge_forces,
                                                               result.hinge_amplitudes))
            timings = dict(prepared.timings, **{"harmonic solve": time.perf_counter() - start})
            if model.residual_mass is not None:
                start = time.perf_counter()
                result.truncation_error = truncation_error(model, excitation)
                timings["truncation estimate"] = time.perf_counter() - start
            card = model_card(prepared.scene, prepared.preload, mounted, None, timings, method,
                              {**solver, "truncation error": describe_truncation(result.truncation_error)})
            card.run_name = excitation.name
            result.model_card, result.preload = card, prepared.preload
            runs.append(result)
            if update:
                update(done)
    finally:
        if close:
            close()
    return runs


def run_case(case: Case, *, progress: ProgressFactory | None = None,
             method: MethodChoice | None = None) -> MountResult:
    """Run every excitation of *case* by the method the case asks for.

    Parameters
    ----------
    case : Case
    progress : callable, optional
        Progress factory for the long stages (see :data:`ProgressFactory`).
    method : MethodChoice, optional
        The method and why (default: :func:`workbook.solve.method.choose_method`
        of the case, per excitation: a sweep on a linear scene always takes
        the frequency domain).

    Returns
    -------
    MountResult

    A case with a flexible pylon (``Case.pylon``: an impedance table, a box
    beam or a mesh) is answered on that pylon
    (:mod:`workbook.solve.flexible_pylon`), in the frequency domain only.
    """
    runs: list[ExcitationResult] = []
    for item in case.excitations:
        points = item.expand() if isinstance(item, (Sweep, Simultaneous)) else (item,)
        highest = max(points, key=lambda point: point.frequency)
        chosen = method or choose_method(case, sweep=isinstance(item, Sweep))
        if chosen.method == FREQUENCY and case.flexible_pylon:
            pylon = pylon_at(case, points)              # bad pylon input refused before any work
            prepared = prepare(mount_case(case), points[0], reduce_for=highest, progress=progress)
            with prepared.scene:
                item_runs = solve_on_pylon(case, prepared, points, pylon, chosen)
        elif chosen.method == FREQUENCY:
            if isinstance(item, Simultaneous):
                chosen = dataclasses.replace(chosen, reason=f"{chosen.reason}; {item.name!r} by superposition: "
                                             "each part solved at its own frequency, the response is their sum")
            prepared = prepare(case, points[0], reduce_for=highest, progress=progress)
            with prepared.scene:
                item_runs = solve_frequencies(case, prepared, points, chosen, progress=progress)
            if isinstance(item, Sweep):
                add_grid_warnings(item, item_runs, prepared.modes)
        elif isinstance(item, Simultaneous):
            item_runs = run_in_time(case, item, reduce_for=highest, progress=progress, method=chosen)
        else:
            item_runs = [run_excitation(case, excitation, reduce_for=points[-1], progress=progress, method=chosen)
                         for excitation in points]
            if isinstance(item, Sweep):        # the modes as the frequency domain counts their damping
                prepared = prepare(case, points[0], reduce_for=highest)
                with prepared.scene:
                    add_grid_warnings(item, item_runs, prepared.modes)
        runs += item_runs
    log.info("%s: %d runs", case.name, len(runs))
    return MountResult(case.name, runs)


def four_pole(case: Case, frequencies_hz, *, points=()) -> FourPole:
    """The four-pole set of the mount of *case* at *frequencies_hz*, about
    its preloaded equilibrium.

    Parameters
    ----------
    case : Case
        Its links are reduced for the highest frequency. Test-rig
        transducers are not part of the mount (give them as a pylon
        impedance).
    frequencies_hz, points
        As :func:`~workbook.solve.four_pole.condense` takes them.

    Raises
    ------
    workbook.errors.CaseError
        A hinge with a clearance law, no pylon-side hinge, or no frequency.
    workbook.errors.SimulationError
        A mechanism or a failed equilibrium (preload); a singular set
        (:class:`~workbook.errors.FourPoleError`).
    """
    frequencies = checked_frequencies(frequencies_hz)
    probe = HarmonicForce("four-pole probe", point=case.engine.center_of_mass, direction=(1.0, 0.0, 0.0),
                          amplitude=1.0, frequency_hz=float(frequencies.max()))
    prepared = prepare(mount_case(case), probe)
    with prepared.scene:
        return condense(prepared.model, case, frequencies, points=points, modes=prepared.modes)


def report_four_pole(case: Case) -> FourPole:
    """The four-pole set of *case* on the default grid (:data:`~workbook.solve.four_pole.REPORT_GRID`),
    for the report workbook's Four-pole sheet."""
    return four_pole(case, frequency_grid(*REPORT_GRID))
