"""Radial clearance of a ball hinge as a spring law.

With relative displacement ``u = p1 - p0`` (m) and gap g, the hinge force is

    F = (k_r + k_c * max(|u| - g, 0) / max(|u|, g)) * u + d * v + c K_t v

i.e. zero contact force inside the gap and a spring of stiffness k_c on the
penetration beyond it, along u. A small residual stiffness ``k_r`` inside the
gap keeps the static solve regular (a zero-stiffness dead zone was measured to
break it; 1e-4 k_c fixed it). ``d`` is the hinge's viscous damping. ``c K_t v``
is the viscous equivalent of the hinge's loss factor in a time integration
(``c = eta / omega``, :mod:`workbook.scene.structural_damping`): the loss
factor acts on the law's tangent stiffness ``K_t``, as in the frequency
domain, so across an open gap it damps only with the residual stiffness,
and in contact with the contact's. Its part along the contact normal grows
with the penetration over the first gap width (the full tangent beyond):
a damper that switches on at full strength at impact made the contact force
jump and Newton fail on rattling gaps. The law is recorded as an Exudyn symbolic
user function and runs at C++ speed (plain Python user functions were
measured about 2x slower per run).

:data:`CLEARANCE` is the law as a :class:`~workbook.scene.hinge_law_base.HingeLaw`:
it takes every hinge with a gap while ``Effects.clearance`` is on.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from workbook.model.case import Case, Hinge
from workbook.scene.hinge_law_base import Connector, HingeLaw

__all__ = ["RESIDUAL_STIFFNESS_RATIO", "clearance_force", "tangent_stiffness", "exudyn_clearance_function",
           "linearised_gap_warnings", "ignored_contact_stiffness", "ClearanceLaw", "CLEARANCE"]

#: Stiffness inside the gap relative to the contact stiffness.
RESIDUAL_STIFFNESS_RATIO = 1e-4


def tangent_stiffness(displacement, gap: float, contact_stiffness: float, *, onset: bool = False) -> np.ndarray:
    """The law's tangent stiffness ``K_t = dF/du`` (the spring part), N/m.

    Inside the gap ``k_r I``; in contact ``(k_r + k_c (1 - g/|u|)) I + k_c
    (g/|u|) n n^T`` with ``n = u/|u|``: the full contact stiffness along u
    and, across it, only what the penetration turns (a ball rolls round its
    socket).

    Parameters
    ----------
    displacement : array_like, shape (3,)
        ``p1 - p0``, m.
    gap : float
        m.
    contact_stiffness : float
        N/m.
    onset : bool
        True: the normal part ``k_c (g/|u|) n n^T`` times ``min(penetration
        / g, 1)``, what the loss factor damps (module text).

    Returns
    -------
    ndarray, shape (3, 3)
    """
    u = np.asarray(displacement, dtype=float)
    distance = np.linalg.norm(u)
    factor = RESIDUAL_STIFFNESS_RATIO * contact_stiffness \
        + contact_stiffness * max(distance - gap, 0.0) / max(distance, gap)
    radial = contact_stiffness * gap / distance if distance > gap else 0.0
    if onset:
        radial *= min(max(distance - gap, 0.0) / gap, 1.0)
    normal = u / distance if distance > 0 else np.zeros(3)
    return factor * np.eye(3) + radial * np.outer(normal, normal)


def clearance_force(displacement, velocity, gap: float, contact_stiffness: float,
                    damping: float, loss_time=0.0) -> np.ndarray:
    """The clearance law evaluated with numpy (reference for tests and plots).

    Parameters
    ----------
    displacement, velocity : array_like, shape (3,)
        ``p1 - p0`` in m and its rate in m/s.
    gap : float
        Radial clearance, m (> 0).
    contact_stiffness : float
        N/m.
    damping : float
        Viscous damping d, N s/m.
    loss_time : float or array_like, shape (3,)
        ``c = eta / omega`` of the loss factor's viscous equivalent per
        direction, s (0: none); it damps ``tangent_stiffness(..., onset=True)``.

    Returns
    -------
    ndarray, shape (3,)
        Spring-damper force F, N (on marker 0; marker 1 gets -F).
    """
    u = np.asarray(displacement, dtype=float)
    v = np.asarray(velocity, dtype=float)
    distance = np.linalg.norm(u)
    factor = RESIDUAL_STIFFNESS_RATIO * contact_stiffness \
        + contact_stiffness * max(distance - gap, 0.0) / max(distance, gap)
    loss = np.asarray(loss_time, dtype=float) * (tangent_stiffness(u, gap, contact_stiffness, onset=True) @ v)
    return factor * u + damping * v + loss


def exudyn_clearance_function(gap: float, loss_time=(0.0, 0.0, 0.0)):
    """A ``springForceUserFunction`` for ``ObjectConnectorCartesianSpringDamper``.

    The contact stiffness and the viscous damping come from the connector's
    ``stiffness`` (first component) and ``damping`` parameters, so one
    recorded function serves every hinge with the same gap and loss.

    Parameters
    ----------
    gap : float
        m.
    loss_time : 3 floats
        ``c = eta / omega`` per direction, s (:func:`clearance_force`).
    """
    import exudyn as exu

    esym = exu.symbolic  # type: ignore[attr-defined]  # the stubs omit the submodule
    loss_time = tuple(float(c) for c in loss_time)

    def spring_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        u = [displacement[i] for i in range(3)]
        v = [velocity[i] for i in range(3)]
        distance = esym.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
        contact = stiffness[0] * esym.max(distance - gap, esym.Real(0.0)) / esym.max(distance, esym.Real(gap))
        factor = RESIDUAL_STIFFNESS_RATIO * stiffness[0] + contact
        force = [factor * u[i] + damping[i] * v[i] for i in range(3)]
        if not any(loss_time):
            return force
        # K_t v (tangent_stiffness with onset): the normal part grows over the first gap width of penetration
        onset = esym.min(esym.max(distance - gap, esym.Real(0.0)) / gap, esym.Real(1.0))
        radial = onset * stiffness[0] * gap / esym.max(distance, esym.Real(gap)) \
            * (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / esym.max(distance * distance, esym.Real(gap * gap))
        return [force[i] + loss_time[i] * (factor * v[i] + radial * u[i]) for i in range(3)]

    return spring_force


def linearised_gap_warnings(hinges, static_forces: dict, dynamic_amplitudes: dict) -> list[str]:
    """Where a linearisation about the preload misrepresents a clearance.

    The frequency domain freezes every gap as it is at the preload. That
    holds for a hinge whose gap the preload closes and whose dynamic force
    stays below its static force (the contact never lifts off); it fails
    where the gap is open at the preload (the hinge is linearised with the
    residual stiffness inside the gap) or where the dynamic force could
    reverse the static one (impacts).

    Parameters
    ----------
    hinges : iterable of workbook.model.case.Hinge
        The hinges whose clearance law is built.
    static_forces : dict of str to array_like, shape (3,)
        Preloaded force of each hinge, N.
    dynamic_amplitudes : dict of str to array_like, shape (3,)
        Amplitude of each hinge force component at the excitation frequency, N.

    Returns
    -------
    list of str
        One warning per hinge concerned (empty when the linearisation holds).
    """
    warnings = []
    for hinge in hinges:
        static = float(np.linalg.norm(static_forces[hinge.name]))
        inside = RESIDUAL_STIFFNESS_RATIO * hinge.gap_contact_stiffness * hinge.radial_clearance
        dynamic = float(np.linalg.norm(dynamic_amplitudes[hinge.name]))
        if static <= inside * (1 + 1e-9):
            warnings.append(f"hinge {hinge.name!r}: the clearance is open at the preload (static force "
                            f"{static:.3g} N); the frequency domain sees only the residual stiffness inside the "
                            f"gap, so contact and impacts need the time domain")
        elif dynamic >= static - inside:
            warnings.append(f"hinge {hinge.name!r}: the dynamic force amplitude {dynamic:.4g} N reaches the static "
                            f"force {static:.4g} N, so the contact can lift off and the gap open; the frequency "
                            f"domain assumes it stays closed: use the time domain")
    return warnings


def ignored_contact_stiffness(case: Case) -> list[Hinge]:
    """Hinges that give a contact stiffness (other than their stiffness) but
    no gap: no clearance law is built, so the contact stiffness never acts."""
    return [h for h in case.hinges if h.contact_stiffness is not None and h.radial_clearance == 0
            and np.any(h.values("stiffness") != h.contact_stiffness)]


class ClearanceLaw(HingeLaw):
    """The clearance law (module text) on every hinge with a gap, while ``Effects.clearance`` is on."""

    name = "hinge clearance"
    nonlinear = True
    linearised = "the clearance laws are linearised about the preloaded state (gaps frozen as they are there)"
    time_domain_note = "the time domain resolves the contact"

    def applies(self, case: Case, hinge: Hinge) -> bool:
        return case.effects.clearance and hinge.radial_clearance > 0

    def connector(self, case: Case, hinge: Hinge, stiffness: np.ndarray, damping: np.ndarray,
                  loss_time: np.ndarray) -> Connector:
        """The contact stiffness on the connector; the law damps its loss factor on its own tangent stiffness."""
        return Connector(np.full(3, hinge.gap_contact_stiffness), damping,
                         exudyn_clearance_function(hinge.radial_clearance, loss_time))

    def force(self, case: Case, hinge: Hinge, displacement, velocity, loss_time=0.0) -> np.ndarray:
        return clearance_force(displacement, velocity, hinge.radial_clearance, hinge.gap_contact_stiffness,
                               float(hinge.values("damping")[0]), loss_time)   # isotropic (Hinge checks)

    def card_entry(self, case: Case) -> tuple[bool, str]:
        switched = case.effects.clearance
        gaps = [h.name for h in case.hinges if h.radial_clearance > 0]
        if switched and gaps:
            return True, f"clearance law (symbolic user function) on {', '.join(gaps)}"
        ignored = [h.name for h in ignored_contact_stiffness(case)]
        return False, (("switched off: gaps ignored" if not switched else "no hinge has a gap > 0")
                       + (f"; contact_stiffness ignored on {', '.join(ignored)} (no gap)" if ignored else ""))

    def warnings(self, case: Case) -> list[str]:
        return [f"hinge {h.name!r}: contact_stiffness {h.contact_stiffness:g} N/m is ignored: the hinge has no gap "
                f"(radial_clearance 0), so its stiffness "
                f"{' / '.join(f'{k:g}' for k in h.values('stiffness'))} N/m acts"
                for h in ignored_contact_stiffness(case)]

    def refusal(self, hinge: Hinge) -> tuple[str, Any, str]:
        return ("radial_clearance", hinge.radial_clearance,
                "0 for the four-pole parameters of a linear mount (or the clearance effect off)")

    def linearised_warnings(self, hinges: list[Hinge], static_forces: dict,
                            dynamic_amplitudes: dict) -> list[str]:
        return linearised_gap_warnings(hinges, static_forces, dynamic_amplitudes)


#: The clearance law.
CLEARANCE = ClearanceLaw()
