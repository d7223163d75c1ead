"""A hinge's stiffness, damping and loss factor per direction of its frame.

A spherical bearing in a link eye is stiffer radially than along its pin.
A hinge may give three values in its frame (rows ``n_1, n_2, n_3``: radial
1, radial 2, axial; :attr:`workbook.model.case.Hinge.frame`), which act in
global coordinates as the matrix

    S = R^T diag(s_1, s_2, s_3) R,        R = [n_1; n_2; n_3],

so a displacement along ``n_i`` meets ``s_i`` alone. Exudyn's Cartesian
spring-damper takes one diagonal in global axes; an anisotropic hinge gets
a symbolic ``springForceUserFunction`` ``F = S_k u + S_d v`` (recorded, it
runs at C++ speed), an isotropic hinge stays the plain spring-damper.
:data:`PER_DIRECTION` is this law as a
:class:`~workbook.scene.hinge_law_base.HingeLaw`.
"""
from __future__ import annotations

import numpy as np

from workbook.model.case import Case, Hinge
from workbook.scene.hinge_law_base import Connector, HingeLaw, hinge_matrix

__all__ = ["exudyn_bearing_function", "PerDirectionLaw", "PER_DIRECTION"]


def exudyn_bearing_function(stiffness: np.ndarray, damping: np.ndarray):
    """A ``springForceUserFunction`` for ``ObjectConnectorCartesianSpringDamper``:
    ``F = S_k u + S_d v`` with constant 3x3 matrices (global coordinates).

    Parameters
    ----------
    stiffness : ndarray, shape (3, 3)
        N/m.
    damping : ndarray, shape (3, 3)
        N s/m.
    """
    k = [[float(v) for v in row] for row in np.asarray(stiffness)]
    d = [[float(v) for v in row] for row in np.asarray(damping)]

    def spring_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        return [k[i][0] * displacement[0] + k[i][1] * displacement[1] + k[i][2] * displacement[2]
                + d[i][0] * velocity[0] + d[i][1] * velocity[1] + d[i][2] * velocity[2] for i in range(3)]

    return spring_force


class PerDirectionLaw(HingeLaw):
    """Stiffness, damping and loss factor per direction of the hinge frame (module text), on every anisotropic hinge."""

    name = "hinge properties per direction"

    def applies(self, case: Case, hinge: Hinge) -> bool:
        return not hinge.isotropic

    def connector(self, case: Case, hinge: Hinge, stiffness: np.ndarray, damping: np.ndarray,
                  loss_time: np.ndarray) -> Connector:
        """``F = S_k u + S_d v`` as a user function, unless what is built is the same in every direction."""
        damping = damping + loss_time * stiffness
        if np.ptp(stiffness) == 0 and np.ptp(damping) == 0:
            return Connector(stiffness, damping)
        return Connector(stiffness, damping, exudyn_bearing_function(hinge_matrix(case, hinge, "stiffness", stiffness),
                                                                     hinge_matrix(case, hinge, "damping", damping)))

    def force(self, case: Case, hinge: Hinge, displacement, velocity, loss_time=0.0) -> np.ndarray:
        stiffness = hinge.values("stiffness")
        damping = hinge.values("damping") + np.asarray(loss_time, dtype=float) * stiffness
        return hinge_matrix(case, hinge, "stiffness") @ np.asarray(displacement, dtype=float) \
            + hinge_matrix(case, hinge, "damping", damping) @ np.asarray(velocity, dtype=float)

    def card_entry(self, case: Case) -> tuple[bool, str]:
        anisotropic = [h.name for h in case.hinges if self.applies(case, h)]
        if not anisotropic:
            return False, "every hinge isotropic (one value in every direction)"
        return True, (f"stiffness, damping or loss factor per direction of the hinge frame (radial 1, radial 2, "
                      f"axial) on {', '.join(anisotropic)}: R^T diag(k) R in global axes (symbolic spring law)")


#: The law per direction of the hinge frame.
PER_DIRECTION = PerDirectionLaw()
