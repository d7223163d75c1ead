"""Every error the package raises on purpose, and the exit code of each.

Every such error derives from one root, :class:`MountwbError`, and carries
its command-line exit code as the class attribute ``exit_code``
(:func:`exit_code`). Two kinds:

- **bad input** (exit 2, :class:`InputError` and its subclasses): the case,
  a workbook, a rig record, a link model or a unit cannot be used. The
  message names the file, sheet, cell, row or field, what was found and
  what was expected. Nothing was written. An :class:`OSError` (a file that
  cannot be read or written) is bad input too.
- **numerical trouble** (exit 1, :class:`SimulationError` and its
  subclasses): a mechanism, a failed equilibrium, a resonance without
  damping, a failed or diverging integration, an exhausted time budget. The
  message says when and why, in plain words.

Any other exception is a defect of the package, not of the input: the
command line exits with 1, says "internal error" and writes the traceback
to a log file. An interrupt exits with 130 (Ctrl-C, SIGINT) or 143
(SIGTERM, :class:`Terminated`); a parameter study whose every row ran but
some failed exits with 3 (:data:`EXIT_FAILED_ROWS`). The errors of
:mod:`flexbodies` (``flexbodies.errors``) derive from :class:`InputError`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

__all__ = ["MountwbError", "InputError", "CaseFileError", "UnwritableCase",
           "CaseError", "UnitProblem", "Problem", "WorkbookError", "TableError", "RecordError", "SimulationError",
           "NewtonFailure", "DivergenceError", "TimeBudgetExceeded", "ResonanceError", "RunTooLong",
           "MechanismError", "EquilibriumError", "RoundOffError",
           "FourPoleError", "OutsideDesignModel", "UnstablePreloadError", "BucklingError", "UsageError",
           "InfeasibleProblem",
           "BAD_INPUT",
           "EXIT_OK", "EXIT_TROUBLE", "EXIT_BAD_INPUT",
           "EXIT_INTERRUPTED", "EXIT_TERMINATED", "EXIT_FAILED_ROWS", "Terminated", "interruption", "exit_code"]

#: Exit codes of the command line.
EXIT_OK, EXIT_TROUBLE, EXIT_BAD_INPUT, EXIT_FAILED_ROWS, EXIT_INTERRUPTED, EXIT_TERMINATED = 0, 1, 2, 3, 130, 143


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C's KeyboardInterrupt so that everything
    that cleans up after Ctrl-C cleans up after it too."""


class MountwbError(Exception):
    """The root of every error the package raises on purpose.

    Attributes
    ----------
    exit_code : int
        Exit code of the command line for this error (a class attribute).
    """

    exit_code = EXIT_TROUBLE


class InputError(MountwbError, ValueError):
    """Bad input (exit 2): something the user gave that cannot be used; the
    message says what was found and what was expected."""

    exit_code = EXIT_BAD_INPUT


class CaseFileError(InputError):
    """A JSON case whose content is not a case: an unknown item type, unknown
    or missing fields, or a value of the wrong kind."""


class UnwritableCase(InputError):
    """A case that a case workbook cannot hold (a mesh link or casing, a
    simultaneous excitation, ...): it is given in Python or JSON."""


class CaseError(InputError):
    """An invalid case.

    Attributes
    ----------
    item : str
        Name (or kind) of the item at fault, e.g. ``"hinge 'front-up-left'"``.
    field : str
        Field of that item, e.g. ``"stiffness"``.
    value : object
        The value found.
    expected : str
        What was expected instead.
    """

    def __init__(self, item: str, field: str, value: Any, expected: str):
        self.item, self.field, self.value, self.expected = item, field, value, expected
        super().__init__(f"{item}, field '{field}': found {value!r}, expected {expected}")


class UnitProblem(InputError):
    """A unit text that cannot be used in its column.

    Attributes
    ----------
    expected : str
        Plain words: what the column takes.
    """

    def __init__(self, expected: str):
        self.expected = expected
        super().__init__(expected)


@dataclass(frozen=True)
class Problem:
    """One input problem.

    Attributes
    ----------
    file : str
    sheet : str or None
    cell : str or None
        Cell or range (``"C4"``, ``"B4:D4"``); None for a whole sheet or file.
    column : str or None
        Column header.
    value : object
        The value found.
    expected : str
        What was expected, in plain words.
    """

    file: str
    sheet: str | None
    cell: str | None
    column: str | None
    value: Any
    expected: str

    def __str__(self) -> str:
        where = [self.file]
        if self.sheet is not None:
            where.append(f"sheet '{self.sheet}'")
        if self.cell is not None:
            where.append(self.cell if self.cell.startswith("row") else f"cell {self.cell}")
        if self.column is not None:
            where.append(f"column '{self.column}'")
        found = "empty" if self.value is None or self.value == "" else repr(self.value)
        return f"{', '.join(where)}: found {found}, expected {self.expected}"


class WorkbookError(InputError):
    """A workbook that cannot be used; :attr:`problems` lists every problem found."""

    def __init__(self, problems: list[Problem]):
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


class TableError(WorkbookError):
    """A table file (CSV) or table sheet that cannot be used; :attr:`problems`
    names the file, sheet, row and column of each problem."""


class RecordError(InputError):
    """A rig record that cannot be used.

    Attributes
    ----------
    path : str
        The file.
    line : int or None
        1-based line of the file (None: the file as a whole).
    column : str or None
        Column header at fault.
    """

    def __init__(self, path, message: str, *, line: int | None = None, column: str | None = None):
        self.path, self.line, self.column = str(path), line, column
        where = "".join((f", line {line}" if line is not None else "",
                         f", column {column!r}" if column is not None else ""))
        super().__init__(f"{path}{where}: {message}")


class SimulationError(MountwbError, RuntimeError):
    """A run stopped for a numerical or physical reason given in the message (exit 1)."""

    exit_code = EXIT_TROUBLE


class NewtonFailure(SimulationError):
    """Newton's method did not converge at the smallest step allowed.

    Attributes
    ----------
    time : float
        Simulated time at which the failing segment started, s.
    step : float
        Smallest step tried, s.
    cause : str
        The likely cause, in plain words.
    """

    def __init__(self, where: str, time: float, end_time: float, step: float, halvings: int, cause: str):
        self.time, self.step, self.cause = time, step, cause
        super().__init__(
            f"{where}: the time integration failed between t = {time:.6g} s and t = {end_time:.6g} s: Newton's "
            f"method did not converge even with the step halved {halvings} time(s), to {step:.3g} s. "
            f"Likely cause: {cause}.")


class DivergenceError(SimulationError):
    """The solution diverged: the engine moved too far, or a value became NaN or infinite."""


class TimeBudgetExceeded(SimulationError):
    """A run used up its wall-time budget.

    Attributes
    ----------
    simulated : float
        Simulated time reached, s.
    estimated_wall_time : float
        Wall time the whole run would have needed at the rate so far, s.
    """

    def __init__(self, where: str, budget: float, elapsed: float, simulated: float, end_time: float):
        self.simulated = simulated
        self.estimated_wall_time = elapsed * end_time / simulated if simulated > 0 else math.inf
        super().__init__(
            f"{where}: stopped after {elapsed:.3g} s of wall time (time budget {budget:g} s) at t = "
            f"{simulated:.4g} s of {end_time:.4g} s simulated; the whole run would need about "
            f"{self.estimated_wall_time:.3g} s. Raise the time budget, shorten the run (settle time, measured "
            f"periods, steps per period) or answer it in the frequency domain.")


class ResonanceError(SimulationError):
    """The excitation frequency coincides with an undamped mounted mode."""


class RoundOffError(SimulationError):
    """An answer the round-off of the computation could have changed by a
    large share of itself: a stiffness so large against the rest of the
    mount that double precision cannot resolve its small motions."""


class RunTooLong(SimulationError):
    """The planned run has more steps than any meant run (:data:`MAX_STEPS`)."""


class MechanismError(SimulationError):
    """The mount is an unrestrained mechanism.

    Attributes
    ----------
    motions : list of str
        Description of each free motion.
    """

    #: Free motions the message lists; the rest are counted.
    LISTED = 12

    def __init__(self, case_name: str, motions: list[str], loose_eyes: list[str] | tuple[str, ...] = (),
                 soft_hinges: list[str] | tuple[str, ...] = ()):
        self.motions = motions
        listing = "; ".join(f"({i + 1}) {m}" for i, m in enumerate(motions[:self.LISTED]))
        if len(motions) > self.LISTED:
            listing += f"; and {len(motions) - self.LISTED} more"
        hint = f" Eyes without a hinge: {', '.join(loose_eyes)}." if loose_eyes else ""
        if soft_hinges:
            hint += (f" Hinges too soft to hold the lighter body they join (it alone would move on them below the "
                     f"free-motion limit): {', '.join(soft_hinges)}; check their stiffness and its unit.")
        super().__init__(f"case {case_name!r} is a mechanism: {len(motions)} free motion(s) without "
                         f"stiffness: {listing}.{hint} Add or restore the link or hinge that restrains it.")


class EquilibriumError(SimulationError):
    """The static solve failed or its hinge forces do not balance the loads.

    Attributes
    ----------
    detail : str
        What the solver itself reported (its console output), for the log.
    """

    def __init__(self, message: str, detail: str = ""):
        self.detail = detail
        super().__init__(message)


class UnstablePreloadError(SimulationError):
    """The preloaded equilibrium is unstable: its stiffness is negative in
    some direction (the preload buckles a link or tips the mount).

    Attributes
    ----------
    omega_squared : list of float
        The negative squared circular frequencies, rad^2/s^2.
    """

    def __init__(self, message: str, omega_squared: list[float]):
        self.omega_squared = list(omega_squared)
        super().__init__(message)


class BucklingError(SimulationError):
    """A flexible link carries more compression at the preload than its
    buckling load (the compression at which its first pinned-pinned bending
    mode vanishes).

    Attributes
    ----------
    link : str
    compression : float
        Axial compression at the preload, N.
    buckling_load : float
        N.
    """

    def __init__(self, case_name: str, link: str, compression: float, buckling_load: float, unloaded_hz: float):
        self.link, self.compression, self.buckling_load = link, compression, buckling_load
        super().__init__(
            f"case {case_name!r}: link {link!r} buckles: the preload pushes it with {compression / 1e3:.4g} kN of "
            f"compression, {compression / buckling_load:.3g} times its buckling load of {buckling_load / 1e3:.4g} kN "
            f"(the compression at which its first bending mode between the two pinned eyes, {unloaded_hz:.4g} Hz "
            f"unloaded, falls to zero). No equilibrium exists with the link straight. Reduce or redirect the "
            f"static loads, or make the link stiffer in bending (a larger shank section, a stiffer material or a "
            f"shorter link).")


class UsageError(InputError):
    """A command-line option or argument that cannot be used, with what it takes."""


class InfeasibleProblem(InputError):
    """An optimisation problem without a design that meets its constraints within the variables' ranges.

    Attributes
    ----------
    violated : list of str
        The constraints still violated at the design closest to meeting them
        all, with their values there.
    bounds : list of str
        The variables held at an end of their range there.
    """

    def __init__(self, violated: list[str], bounds: list[str]):
        self.violated, self.bounds = list(violated), list(bounds)
        held = f"; with {', '.join(self.bounds)}" if self.bounds else ""
        super().__init__(f"no design within the variables' ranges meets the constraints: the constraints "
                         f"{'; '.join(self.violated)} conflict{held} (the design closest to meeting them all). "
                         "Widen the ranges or relax these limits")


#: The errors that are the user's input, not the solution (exit 2).
BAD_INPUT = (InputError,)


def interruption(error: BaseException | None) -> KeyboardInterrupt | None:
    """The interrupt behind *error*, if any.

    Exudyn turns a KeyboardInterrupt raised while it solves into an error of
    its own (``SystemError`` "returned a result with an exception set", or
    ``ModelError`` from a Python user function) whose cause or context is
    the interrupt; this finds it.

    Returns
    -------
    KeyboardInterrupt or None
        *error* itself, the interrupt in its chain of causes, or None.
    """
    seen = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, KeyboardInterrupt):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return None


def exit_code(error: BaseException) -> int:
    """The command-line exit code of *error*: its ``exit_code`` for an error
    of the package (:class:`MountwbError`: 1 numerical trouble, 2 bad input),
    2 for a file that cannot be read or written (:class:`OSError`), 130
    interrupted, 143 terminated (also when Exudyn wrapped the interrupt,
    :func:`interruption`), and 1 for any other exception: a defect of the
    package, not of the input.
    """
    interrupt = interruption(error)
    if interrupt is not None:
        return EXIT_TERMINATED if isinstance(interrupt, Terminated) else EXIT_INTERRUPTED
    if isinstance(error, MountwbError):
        return error.exit_code
    if isinstance(error, OSError):
        return EXIT_BAD_INPUT
    return EXIT_TROUBLE


class OutsideDesignModel(SimulationError):
    """A design the prepared linear mount cannot answer without a new
    preparation (:mod:`workbook.design.linear_mount`): a limit of the fast
    method, not the user's bad input; the full pipeline answers it."""

    def __init__(self, case_name: str, change: str):
        self.change = change
        super().__init__(f"{case_name}: the design evaluation cannot follow {change}; it needs a new preparation "
                         "(the full pipeline)")


class FourPoleError(SimulationError):
    """A four-pole set that cannot be formed or used: a dynamic-stiffness
    matrix to invert is singular at a frequency (an undamped resonance of the
    mount with its terminals blocked, or of the mount on its engine and pylon)."""
