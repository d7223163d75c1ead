"""The static axial stiffness of a reduced link between its eye centres."""
from __future__ import annotations

import numpy as np

__all__ = ["axial_stiffness"]


def axial_stiffness(link) -> float:
    """Axial stiffness of a reduced link between its two eye centres, N/m.

    Equal and opposite unit forces along the eye-to-eye line at the two
    master nodes (the bore couplings) load the reduced body; its static
    compliance is ``g^T K_r^-1 g`` with ``g = Phi^T e`` the generalised
    force of that pair (``Phi`` the elastic mode basis, ``K_r`` the reduced
    stiffness). The Craig-Bampton basis holds the static constraint modes of
    the interfaces, so this is the full FE model's stiffness between them.

    Parameters
    ----------
    link : flexbodies.ReducedBody

    Returns
    -------
    float
        N/m.
    """
    a, b = link.master_nodes[:2]
    axis = link.nodes[b] - link.nodes[a]
    axis = axis / np.linalg.norm(axis)
    pair = np.zeros(link.mode_basis.shape[0])
    pair[3 * b:3 * b + 3], pair[3 * a:3 * a + 3] = axis, -axis
    force = link.mode_basis.T @ pair
    compliance = force @ np.linalg.solve(np.asarray(link.ffrf["stiffnessMatrixReduced"], dtype=float), force)
    return float(1.0 / compliance)
