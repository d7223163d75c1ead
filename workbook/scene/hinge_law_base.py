"""What every hinge law gives: the interface of a law and the default law.

A hinge is an Exudyn ``ObjectConnectorCartesianSpringDamper``. Its default
law is the plain diagonal spring-damper ``F = diag(k) u + diag(d + c k) v``
(``c = eta / omega``, the viscous equivalent of the loss factor), built
without a user function. Any other law (one module, registered in
:data:`workbook.scene.hinge_laws.HINGE_LAWS`) subclasses :class:`HingeLaw`:
it says which hinges it takes, gives the connector's stiffness, damping and
recorded symbolic ``springForceUserFunction``, the same force with NumPy
(the reference for tests and plots), its matrices as the frequency domain's
linear models take them (:meth:`HingeLaw.matrices`: the harmonic model, the
four-pole set and the linear mount ask the law, never the hinge's fields)
and its model-card entry. A hinge's per-direction quantities act in global
coordinates as ``R^T diag(values) R`` of its frame (:func:`hinge_frame`,
:func:`hinge_matrix`; :mod:`workbook.scene.bearing`).

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

from workbook.model.case import ENGINE, PYLON, Case, Hinge

__all__ = ["Connector", "HingeLaw", "SpringDamper", "SPRING_DAMPER", "hinge_frame", "hinge_matrix"]


def hinge_frame(case: Case, hinge: Hinge) -> np.ndarray:
    """The hinge's directions radial 1, radial 2, axial as rows, global coordinates.

    The hinge's own ``frame`` when given; else the frame of the link it sits
    on (radial 1 along the link towards eye B, axial along the link's bore
    axis, see :func:`flexbodies.exudyn_body.link_rotation`); else (a hinge
    between the pylon and the engine) the global axes.
    """
    from flexbodies.exudyn_body import link_rotation

    if hinge.frame is not None:
        return np.array(hinge.frame, dtype=float)
    links = [body for body in hinge.bodies if body not in (PYLON, ENGINE)]
    if not links:
        return np.eye(3)
    link = case.link_map[links[0]]
    return link_rotation(link.end_a, link.end_b, link.bore_axis).T


def hinge_matrix(case: Case, hinge: Hinge, name: str, values=None) -> np.ndarray:
    """``R^T diag(values) R``: a per-direction quantity of *hinge* in global coordinates, shape (3, 3).

    Parameters
    ----------
    case : Case
    hinge : Hinge
    name : {"stiffness", "damping", "loss_factor"}
        The quantity (N/m, N s/m or dimensionless).
    values : array_like, shape (3,), optional
        Values to use instead of the hinge's own *name*.
    """
    values = hinge.values(name) if values is None else np.broadcast_to(np.asarray(values, dtype=float), (3,))
    if np.ptp(values) == 0:
        return values[0] * np.eye(3)
    frame = hinge_frame(case, hinge)
    return frame.T @ np.diag(values) @ frame


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

    def matrices(self, case: Case, hinge: Hinge, frame: np.ndarray | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The law as the frequency domain's linear models take it, global coordinates, shape (3, 3) each
        (*frame*: the hinge's :func:`hinge_frame`, found here when not given).

        Returns
        -------
        stiffness : ndarray
            S, N/m.
        damping : ndarray
            S_d, N s/m (the hinge's own, whether hinge damping is on or not).
        loss : ndarray
            E of the loss factors: the hysteretic force is ``i E S u``, dimensionless.
        """
        values = [hinge.values(name) for name in ("stiffness", "damping", "loss_factor")]
        if hinge.isotropic:
            return values[0][0] * np.eye(3), values[1][0] * np.eye(3), values[2][0] * np.eye(3)
        frame = hinge_frame(case, hinge) if frame is None else frame
        return (frame.T * values[0]) @ frame, (frame.T * values[1]) @ frame, (frame.T * values[2]) @ frame

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
