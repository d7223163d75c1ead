"""Guards of the solver path: what stops a run, in plain words.

Every numerical trouble a run can meet ends in a :class:`SimulationError`
whose message says what happened, when (the simulated time) and what to
change, never in NaN or a silently wrong number:

- :class:`NewtonFailure`: Newton's method did not converge even after the
  step was halved the allowed number of times (:func:`newton_cause` turns
  Exudyn's convergence flags into the likely cause);
- :class:`DivergenceError`: the engine ran away from its preloaded position,
  or a coordinate became NaN or infinite;
- :class:`TimeBudgetExceeded`: the run used up its wall-time budget;
- :class:`ResonanceError`: the excitation sits on an undamped mode (of the
  engine on its mount or of a link),
  where no steady state exists;
- :class:`RunTooLong`: the planned run is too long to be meant (a mounted
  mode so lightly damped that its transient would take days to decay).

The mechanism and equilibrium errors of :mod:`workbook.solve.preload` are
:class:`SimulationError` too, so a caller catches one class.
"""
from __future__ import annotations

import contextlib
import io
import logging
import math
import warnings

import numpy as np

from workbook.errors import ResonanceError

__all__ = ["run_label", "newton_cause", "check_undamped_resonance", "undamped_mode_near", "singular_solve_guard", "checked_solve",
           "RoundOffWarning", "solver_output", "UNDAMPED_RATIO", "MAX_STEPS", "RESONANCE_BAND"]

log = logging.getLogger(__name__)

#: A mounted mode with a damping ratio below this counts as undamped (the
#: linearisation of a scene without damping gives ratios of about 1e-15).
UNDAMPED_RATIO = 1e-6
#: Relative distance from an undamped mode at which a harmonic solution
#: is refused (the dynamic matrix is singular on the mode).
RESONANCE_BAND = 1e-6
#: Planned time steps above which a run is refused as not meant (about a day
#: of wall time for the reference mount with flexible links).
MAX_STEPS = 50_000_000


class RoundOffWarning(RuntimeWarning):
    """A linear solve whose matrix is singular to round-off: its answer may be noise
    (:func:`checked_solve`; :func:`singular_solve_guard` turns it into a :class:`ResonanceError`)."""


def run_label(case_name: str, run_name: str) -> str:
    """How the messages name a run: ``case 'NAME', run 'NAME'``."""
    return f"case {case_name!r}, run {run_name!r}"


@contextlib.contextmanager
def solver_output():
    """Capture what Exudyn prints (its banners, "SOLVER FAILED" boxes and
    hints) instead of letting it reach stdout, where it would break
    ``mountwb run --json``; the text goes to the debug log.

    Yields
    ------
    io.StringIO
        The captured text (complete once the ``with`` block has ended), for
        an error's detail.
    """
    buffer = io.StringIO()
    try:
        with contextlib.redirect_stdout(buffer):
            yield buffer
    finally:
        if buffer.getvalue().strip():
            log.debug("Exudyn said:\n%s", buffer.getvalue().rstrip())


def newton_cause(convergence) -> str:
    """The likely cause of a Newton failure from Exudyn's convergence flags.

    Parameters
    ----------
    convergence : exudyn solver ``conv`` structure
        ``MainSolverImplicitSecondOrder().conv`` after the failure.

    Returns
    -------
    str
    """
    if convergence.linearSolverFailed:
        return ("the system matrix is singular: a body or link is not restrained (a mechanism), or a stiffness "
                "is zero")
    if convergence.massMatrixNotInvertible:
        return "the mass matrix is not invertible: a body without mass or inertia"
    if convergence.newtonSolutionDiverged:
        return ("Newton's iteration diverged: the forces change too much within one step (a very stiff hinge or "
                "contact, an impact in a clearance, or a run-away motion)")
    return (f"no convergence within the iteration limit (last residual {convergence.residual:.3g}): a very stiff "
            "hinge or contact, or an impact in a clearance")


def check_undamped_resonance(where: str, frequency_hz: float, modes, band: float, consequence: str) -> None:
    """Stop if *frequency_hz* lies on (or, within *band*, next to) an undamped mode.

    Without damping the response at a natural frequency grows without bound,
    and next to it the free vibration never decays: there is no steady state
    to report. Every mode counts, the engine's and the links' own alike: on
    an undamped link mode the harmonic matrix is singular to round-off and
    its solution is noise (measured: T of 1e5 to 1e11).

    Parameters
    ----------
    where : str
        Case and run, for the message.
    frequency_hz : float
        Excitation frequency, Hz.
    modes : list of workbook.solve.modes.Mode
        Every mode of the preloaded scene.
    band : float
        Relative distance ``|f / f_n - 1|`` within which the excitation counts
        as on the mode.
    consequence : str
        What this means for the analysis, for the message.

    Raises
    ------
    ResonanceError
    """
    mode = undamped_mode_near(frequency_hz, modes, band)
    if mode is not None:
        kind = "mounted mode" if mode.mounted else "mode"
        raise ResonanceError(
            f"{where}: the excitation at {frequency_hz:.6g} Hz is within {100 * band:.3g} % of the undamped "
            f"{kind} at {mode.frequency_hz:.6g} Hz ({mode.description}; damping ratio "
            f"{mode.damping_ratio:.1e}): {consequence}. Give the hinges or links damping, or move the "
            f"excitation frequency.")


def undamped_mode_near(frequency_hz: float, modes, band: float):
    """The first of *modes* that is undamped (damping ratio below :data:`UNDAMPED_RATIO`) and lies within
    *band* (relative, ``|f / f_n - 1|``) of *frequency_hz* (Hz), or None."""
    return next((mode for mode in modes if mode.frequency_hz > 0 and mode.damping_ratio < UNDAMPED_RATIO
                 and abs(frequency_hz / mode.frequency_hz - 1.0) < band), None)


def checked_solve(matrix: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``matrix^-1 rhs`` (LU), with a :class:`RoundOffWarning` when *matrix* is singular to round-off:
    its reciprocal condition number (1-norm) below the machine epsilon, as SciPy's ``solve`` warns.

    Raises
    ------
    numpy.linalg.LinAlgError
        *matrix* is exactly singular.
    """
    solution = np.linalg.solve(matrix, rhs)
    reciprocal = 1.0 / np.linalg.cond(matrix, 1)
    if not reciprocal >= np.finfo(float).eps:
        warnings.warn(f"ill-conditioned matrix (reciprocal condition number {reciprocal:.3g})", RoundOffWarning,
                      stacklevel=2)
    return solution


@contextlib.contextmanager
def singular_solve_guard(where: str, frequency_hz: float, modes):
    """Turn a harmonic solve that is singular to round-off (a :class:`RoundOffWarning`
    of :func:`checked_solve`) into a :class:`ResonanceError` naming the mode nearest
    to the excitation, instead of an answer that is noise.

    Parameters
    ----------
    where : str
        Case and run, for the message.
    frequency_hz : float
        Excitation frequency, Hz.
    modes : list of workbook.solve.modes.Mode
        Every mode of the preloaded scene.

    Raises
    ------
    ResonanceError
    """
    with warnings.catch_warnings():
        warnings.simplefilter("error", RoundOffWarning)
        try:
            yield
        except RoundOffWarning as warning:
            def distance(mode) -> float:
                return abs(frequency_hz / mode.frequency_hz - 1.0) if mode.frequency_hz > 0 else math.inf

            nearest = min(modes, key=distance)
            raise ResonanceError(
                f"{where}: the harmonic solve at {frequency_hz:.6g} Hz is singular to round-off ({warning}): the "
                f"excitation is {100 * distance(nearest):.2g} % from the mode at {nearest.frequency_hz:.6g} Hz "
                f"({nearest.description}; damping ratio {nearest.damping_ratio:.1e}), and the answer would be "
                f"noise. Give the hinges or links damping, or move the excitation frequency.") from None
