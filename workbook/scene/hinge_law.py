"""Radial clearance of a ball hinge as a spring law.

With relative displacement ``u = p1 - p0`` (m) and gap g, the hinge force is

    F = (k_r + k_c * max(|u| - g, 0) / max(|u|, g)) * u + d * v

i.e. zero contact force inside the gap and a spring of stiffness k_c on the
penetration beyond it, along u. A small residual stiffness ``k_r`` inside the
gap keeps the static solve regular (a zero-stiffness dead zone was measured to
break it; 1e-4 k_c fixed it). The law is recorded as an Exudyn symbolic user
function and runs at C++ speed (plain Python user functions were measured
about 2x slower per run).
"""
from __future__ import annotations

import numpy as np

__all__ = ["RESIDUAL_STIFFNESS_RATIO", "clearance_force", "exudyn_clearance_function", "linearised_gap_warnings"]

#: Stiffness inside the gap relative to the contact stiffness.
RESIDUAL_STIFFNESS_RATIO = 1e-4


def clearance_force(displacement, velocity, gap: float, contact_stiffness: float,
                    damping: float) -> np.ndarray:
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
        N s/m.

    Returns
    -------
    ndarray, shape (3,)
        Spring-damper force F, N (on marker 0; marker 1 gets -F).
    """
    u = np.asarray(displacement, dtype=float)
    distance = np.linalg.norm(u)
    factor = RESIDUAL_STIFFNESS_RATIO * contact_stiffness \
        + contact_stiffness * max(distance - gap, 0.0) / max(distance, gap)
    return factor * u + damping * np.asarray(velocity, dtype=float)


def exudyn_clearance_function(gap: float):
    """A ``springForceUserFunction`` for ``ObjectConnectorCartesianSpringDamper``.

    The contact stiffness and damping come from the connector's ``stiffness``
    and ``damping`` parameters (first component), so one recorded function
    serves every hinge with the same gap.
    """
    import exudyn as exu

    esym = exu.symbolic  # type: ignore[attr-defined]  # the stubs omit the submodule

    def spring_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        u = [displacement[i] for i in range(3)]
        distance = esym.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
        contact = stiffness[0] * esym.max(distance - gap, esym.Real(0.0)) / esym.max(distance, esym.Real(gap))
        factor = RESIDUAL_STIFFNESS_RATIO * stiffness[0] + contact
        return [factor * u[i] + damping[i] * velocity[i] for i in range(3)]

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
