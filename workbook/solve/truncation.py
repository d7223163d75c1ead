"""The truncation error of an answer: what the fixed-interface modes a link omits would change.

A flexible link keeps static modes (exact at zero frequency) and some
fixed-interface modes; the modes it omits respond to the inertia of its
motion. To leading order in ``(f / f_j)^2`` (``f_j`` the omitted modes'
frequencies, above four times the excitation under the low-frequency rule)
they add the dynamic stiffness ``-w^4 R`` on the link's coordinates, R its
residual mass (:func:`flexbodies.reduction.residual_mass`, stored with each
reduction: no omitted mode is computed). In the scene's independent
coordinates z,

    R_z = sum over flexible links of J^T R J,

with J the link's frame translation and rotation (link frame) and modal
coordinates per z (the frame's by central differences of Exudyn's node
outputs). The corrected answer solves ``(K - w^2 M + i w D + i H - w^4 R_z)
z = B f``; the estimate per direction is ``|T_corrected - T| / T``. Its cost
is one more dense solve per frequency. Links only: a flexible engine
casing's omitted modes are not estimated.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["residual_stiffness", "truncation_error", "describe_truncation", "complete_model", "COMPLETE_MODES",
           "with_modes", "run_to_accuracy", "MODE_LADDER", "AccuracyStep"]

#: Coordinate step of the frame's central differences (m, Euler parameters).
FRAME_STEP = 1e-7


def _frame_jacobian(scene, node: int, rows: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """d(frame translation, rotation in the frame's own axes)/dz of an Exudyn rigid node, shape (6, n)."""
    import exudyn as exu

    data, current = scene.mbs.systemData, exu.ConfigurationType.Current
    q0 = np.array(data.GetODE2Coordinates(configuration=current))

    def pose():
        position = np.array(scene.mbs.GetNodeOutput(node, exu.OutputVariableType.Position, configuration=current))
        rotation = np.array(scene.mbs.GetNodeOutput(node, exu.OutputVariableType.RotationMatrix,
                                                    configuration=current)).reshape(3, 3)
        return position, rotation

    p0, a0 = pose()
    columns = []
    for j in rows:
        values = []
        for sign in (1.0, -1.0):
            shifted = q0.copy()
            shifted[j] += sign * FRAME_STEP
            data.SetODE2Coordinates(list(shifted), configuration=current)
            position, rotation = pose()
            relative = a0.T @ rotation
            values.append(np.concatenate([a0.T @ (position - p0),
                                          0.5 * np.array([relative[2, 1] - relative[1, 2],
                                                          relative[0, 2] - relative[2, 0],
                                                          relative[1, 0] - relative[0, 1]])]))
        columns.append((values[0] - values[1]) / (2 * FRAME_STEP))
    data.SetODE2Coordinates(list(q0), configuration=current)
    return np.array(columns).T @ basis[rows]


def residual_stiffness(scene, basis: np.ndarray) -> np.ndarray | None:
    """R_z of the scene's flexible links (module docstring), kg s^2, shape (n, n).

    Parameters
    ----------
    scene : workbook.scene.build.Scene
        At its preloaded state.
    basis : ndarray, shape (N, n)
        Full ODE2 coordinates per independent coordinate (the linearisation's).

    Returns
    -------
    ndarray or None
        None when a flexible link's reduction holds no residual mass (made
        without it); zeros without flexible links.
    """
    total = np.zeros((basis.shape[1], basis.shape[1]))
    for name, item in scene.links.items():
        if not item.flexible:
            continue
        residual = scene.reduced[name].residual_mass
        if residual.size == 0:
            return None
        frame, modal = (scene.mbs.GetNodeODE2Index(node) for node in item.nodes)
        n_modes = residual.shape[0] - 6
        jacobian = np.vstack([_frame_jacobian(scene, item.nodes[0], np.arange(frame, frame + 7), basis),
                              basis[modal:modal + n_modes]])
        total += jacobian.T @ residual @ jacobian
    return total


def truncation_error(model, excitation) -> np.ndarray:
    """Estimated relative truncation error of the pylon T per direction x, y, z.

    Parameters
    ----------
    model : workbook.solve.harmonic.HarmonicModel
        With its ``residual_mass`` (R_z).
    excitation : RotatingForce or HarmonicForce

    Returns
    -------
    ndarray, shape (3,)
        ``|T_corrected - T| / T``, dimensionless (nan where T is 0).
    """
    omega = 2 * np.pi * excitation.frequency
    load = model.excitation_input(excitation)
    kept = model.respond_generalised(excitation.frequency, load).pylon_force
    corrected = model.respond_generalised(excitation.frequency, load, -omega ** 4 * model.residual_mass).pylon_force
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.abs(np.abs(corrected) - np.abs(kept)) / np.abs(kept)


def describe_truncation(error: np.ndarray | None) -> str:
    """The model card's line of an estimate (:func:`truncation_error`) per direction."""
    if error is None:
        return ("not estimated: a link's reduction was made without the residual mass of its omitted modes "
                "(mountwb cache clear)")
    values = ", ".join(f"{axis} {100 * value:.3g} %" for axis, value in zip("xyz", error, strict=True))
    return (f"estimated {values} of T: the change of T when the residual mass of the fixed-interface modes the "
            f"links omit is added (-w^4 R, leading order in (f / f_omitted)^2; links only)")



#: Fixed-interface modes per link of the complete model (``--compare complete``): the seed study's
#: complete MNF; the estimate of the reference's answers is below 0.03 % with them.
COMPLETE_MODES = 20


#: Fixed-interface modes per link that :func:`run_to_accuracy` tries in turn after the case's own.
MODE_LADDER = (6, 12, COMPLETE_MODES)


def with_modes(case, modes: int, *, automatic_only: bool = False):
    """*case* with every flexible link (or only those whose mode rule is ``auto``) keeping *modes*
    fixed-interface modes."""
    import dataclasses

    return dataclasses.replace(case, links=tuple(
        dataclasses.replace(link, modes=modes)
        if case.link_is_flexible(link.name) and (link.modes == "auto" or not automatic_only) else link
        for link in case.links))


def complete_model(case):
    """*case* with every flexible link keeping :data:`COMPLETE_MODES` fixed-interface modes."""
    return with_modes(case, COMPLETE_MODES)


@dataclass(frozen=True)
class AccuracyStep:
    """One model :func:`run_to_accuracy` ran.

    Attributes
    ----------
    modes : str
        The links' modes (``"as the case says"`` or ``"N per link"``).
    estimate : float
        The largest estimated truncation error of T over runs and directions (fraction).
    seconds : float
        Wall time of the run, s.
    """

    modes: str
    estimate: float
    seconds: float


def run_to_accuracy(case, target: float, *, progress=None, ladder: tuple = MODE_LADDER):
    """Run *case*, then again with more fixed-interface modes on the links whose mode rule is ``auto``
    (:data:`MODE_LADDER`), until every run's estimated truncation error of T is at most *target*.

    Parameters
    ----------
    case : Case
    target : float
        Largest estimated relative error of T (fraction, e.g. 0.005).
    progress : callable, optional
        As :func:`workbook.run_case`.
    ladder : tuple of int
        Fixed-interface modes per link to try in turn.

    Returns
    -------
    result : MountResult
        The first answer within *target*, or the last tried; if that misses
        *target*, each of its runs carries a warning saying by how much.
    steps : list of AccuracyStep

    Raises
    ------
    UsageError
        A run without an estimate (time domain, a flexible pylon).
    """
    import time

    from workbook.errors import UsageError
    from workbook.solve.pipeline import run_case

    models = [("as the case says", case)]
    if any(case.link_is_flexible(link.name) and link.modes == "auto" for link in case.links):
        models += [(f"{modes} per link", with_modes(case, modes, automatic_only=True)) for modes in ladder]
    steps: list[AccuracyStep] = []
    for label, candidate in models:
        start = time.perf_counter()
        result = run_case(candidate, progress=progress)
        estimates = [run.truncation_error for run in result.runs]
        if any(estimate is None for estimate in estimates):
            raise UsageError(f"--accuracy: {case.name} has runs without a truncation-error estimate (time-domain "
                             "or flexible-pylon answers, or reductions cached without residual mass)")
        worst = float(max(np.nanmax(estimate) for estimate in estimates))
        steps.append(AccuracyStep(label, worst, time.perf_counter() - start))
        if worst <= target:
            return result, steps
    for run in result.runs:
        run.warnings.append(f"the estimated truncation error {100 * steps[-1].estimate:.3g} % of T stays above the "
                            f"target {100 * target:.3g} % with the links' modes {steps[-1].modes}")
    return result, steps
