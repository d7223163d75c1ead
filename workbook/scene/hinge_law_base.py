"""What every hinge law gives: the interface of a law and the default law.

A hinge is an Exudyn ``ObjectConnectorCartesianSpringDamper``. Its default
law is the plain diagonal spring-damper ``F = diag(k) u + diag(d + c k) v``
(``c = eta / omega``, the viscous equivalent of the loss factor), built
without a user function. Any other law (one module, registered in
:data:`workbook.scene.hinge_laws.HINGE_LAWS`) subclasses :class:`HingeLaw`:
it says which hinges it takes, gives the connector's stiffness, damping and
recorded symbolic ``springForceUserFunction``, the same force with NumPy
(the reference for tests and plots), and its model-card entry.

A *nonlinear* law makes the scene nonlinear: the time domain resolves it;
the frequency domain linearises it about the preloaded state (Exudyn's
tangent of the law there), an approximation the method's reason states and
:meth:`HingeLaw.linearised_warnings` checks; the four-pole set and the
linear mount refuse it.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from workbook.model.case import Case, Hinge

__all__ = ["Connector", "HingeLaw", "SpringDamper", "SPRING_DAMPER"]


@dataclass(frozen=True)
class Connector:
    """What a law sets on its hinge's connector.

    Attributes
    ----------
    stiffness : ndarray, shape (3,)
        The connector's ``stiffness``, N/m.
    damping : ndarray, shape (3,)
        The connector's ``damping``, N s/m.
    spring_force : callable or None
        A ``springForceUserFunction`` to record (None: the plain diagonal
        spring-damper acts).
    """

    stiffness: np.ndarray
    damping: np.ndarray
    spring_force: Callable[..., Any] | None = None


class HingeLaw:
    """A hinge's force law; this base is the plain diagonal spring-damper.

    Attributes
    ----------
    name : str
        The law's effect on the model card and its noun in the method's
        reasons (``"hinge clearance"``).
    nonlinear : bool
        The law makes the scene nonlinear (time domain; the frequency
        domain linearises it about the preload).
    linearised : str
        Nonlinear law: what the frequency domain makes of it.
    time_domain_note : str
        Nonlinear law: what the time domain resolves.
    """

    name: ClassVar[str] = "hinge spring-damper"
    nonlinear: ClassVar[bool] = False
    linearised: ClassVar[str] = ""
    time_domain_note: ClassVar[str] = ""

    def applies(self, case: Case, hinge: Hinge) -> bool:
        """True if *hinge* of *case* is built with this law."""
        return True

    def connector(self, case: Case, hinge: Hinge, stiffness: np.ndarray, damping: np.ndarray,
                  loss_time: np.ndarray) -> Connector:
        """The connector of *hinge*.

        Parameters
        ----------
        case : Case
        hinge : Hinge
        stiffness : ndarray, shape (3,)
            The hinge's stiffness per direction, N/m.
        damping : ndarray, shape (3,)
            Its viscous damping per direction as built (0 with hinge damping
            switched off), N s/m.
        loss_time : ndarray, shape (3,)
            ``c = eta / omega`` of its loss factor per direction, s (0: none built).
        """
        return Connector(stiffness, damping + loss_time * stiffness)

    def force(self, case: Case, hinge: Hinge, displacement, velocity, loss_time=0.0) -> np.ndarray:
        """The law with NumPy: force on marker 0 at ``u = p1 - p0`` (m) and its rate (m/s), N, shape (3,).

        *loss_time* as in :meth:`connector` (scalar or shape (3,), s).
        """
        stiffness, damping = hinge.values("stiffness"), hinge.values("damping")
        return stiffness * np.asarray(displacement, dtype=float) \
            + (damping + np.asarray(loss_time, dtype=float) * stiffness) * np.asarray(velocity, dtype=float)

    def card_entry(self, case: Case) -> tuple[bool, str] | None:
        """The law's model-card entry (on, detail), None for none."""
        return None

    def warnings(self, case: Case) -> list[str]:
        """What *case* gives for this law that the scene does not build, in words."""
        return []

    def refusal(self, hinge: Hinge) -> tuple[str, Any, str]:
        """Why the four-pole set (a linear mount's) refuses *hinge* built with a
        nonlinear law: the field, what was found and what is expected."""
        return "law", self.name, "a linear hinge law for the four-pole parameters of a linear mount"

    def linearised_warnings(self, hinges: list[Hinge], static_forces: dict,
                            dynamic_amplitudes: dict) -> list[str]:
        """Nonlinear law: where the frequency domain's linearisation about the preload fails.

        Parameters
        ----------
        hinges : list of Hinge
            The hinges built with this law.
        static_forces, dynamic_amplitudes : dict of str to array_like, shape (3,)
            Preloaded force and force amplitude of each hinge, N.
        """
        return []


class SpringDamper(HingeLaw):
    """The default law: the plain diagonal spring-damper (no user function)."""


#: The default law, for every hinge no registered law takes.
SPRING_DAMPER = SpringDamper()
