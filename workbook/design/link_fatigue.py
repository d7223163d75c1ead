"""Fatigue safety factors of a design's links on the fast path, with their derivatives.

The linear mount gives each flexible link's modal coordinates: their static
value q_0 under the preload (the item's state) and their harmonic phasor
q_hat at each excitation (the projected motion: a link's modal coordinates
are free coordinates, kept as they are by the projection). The stresses are
the link's stress shapes times them (``sigma_m = S q_0``, ``S q_hat``), the
factors those of :mod:`workbook.solve.fatigue`: the lowest modified-Goodman
factor over the link's nodes, from the alternating von Mises stress of the
cycle and the signed von Mises stress of the mean. Its derivative is that
of the factor at the node (and excitation) of the lowest one, from the
coordinates' derivatives (``dq_0``, ``dq_hat``) through the von Mises
bilinear form.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flexbodies.stress import alternating_von_mises, goodman_factor, signed_von_mises, state_stress
from workbook.design.linear_mount import ItemSolution, StressedLink

__all__ = ["FatigueFactor", "link_fatigue_factors", "VON_MISES_FORM"]

#: Nodes of the largest bound on their load whose factors are found first; a node whose bound is below the
#: largest load among them cannot hold the lowest factor, and is left out.
CANDIDATES = 64
#: ``a @ VON_MISES_FORM @ b`` is the von Mises bilinear form of two Voigt stresses (its square for a == b), Pa^2.
VON_MISES_FORM = np.block([[np.full((3, 3), -0.5) + 1.5 * np.eye(3), np.zeros((3, 3))],
                           [np.zeros((3, 3)), 3 * np.eye(3)]])


@dataclass(frozen=True)
class FatigueFactor:
    """The lowest Goodman factor of one link over its nodes and a set of excitations, and its gradient.

    Attributes
    ----------
    link : str
    goodman : float
    gradient : ndarray, shape (P,)
        d goodman / dp per parameter of the motions' derivatives.
    excitation : int
        Position, among the motions given, of the excitation of the lowest factor.
    """

    link: str
    goodman: float
    gradient: np.ndarray
    excitation: int


def _goodman(stressed: StressedLink, nodes: np.ndarray, phasors: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """The Goodman factors at *nodes* of the link's modal phasors (modes, K) on its signed mean stress (n,),
    shape (nodes, K)."""
    material = stressed.link.model.material
    amplitudes = (stressed.component_shapes[:, nodes] @ phasors).reshape(6, -1).T
    alternating = alternating_von_mises(amplitudes).reshape(len(nodes), -1)
    return goodman_factor(alternating, mean[nodes, None], material.endurance_strength, material.ultimate_strength)


def _coordinates(solution: ItemSolution, stressed: StressedLink) -> np.ndarray:
    """The link's modal coordinates' positions in the projected motion."""
    return np.searchsorted(solution.model.basis.free, stressed.coordinates)


def _factor_change(stressed: StressedLink, node: int, mean_q, d_mean_q, amplitude_q, d_amplitude_q) -> np.ndarray:
    """d Goodman / dp at one node (P,)."""
    material = stressed.link.model.material
    shapes = stressed.reduced.stress_modes[node]                       # (6, modes)
    a_vec, b_vec = (shapes @ amplitude_q).real, (shapes @ amplitude_q).imag
    d_amplitude = shapes @ d_amplitude_q                               # (6, P)
    da_vec, db_vec = d_amplitude.real, d_amplitude.imag
    form = VON_MISES_FORM
    a, b, c = a_vec @ form @ a_vec, b_vec @ form @ b_vec, a_vec @ form @ b_vec
    da, db, dc = 2 * a_vec @ form @ da_vec, 2 * b_vec @ form @ db_vec, a_vec @ form @ db_vec + b_vec @ form @ da_vec
    root = np.sqrt(0.25 * (a - b) ** 2 + c ** 2)
    d_root = (0.25 * (a - b) * (da - db) + c * dc) / root if root > 0 else np.zeros_like(da)
    alternating = np.sqrt(max(0.5 * (a + b) + root, 0.0))
    d_alternating = (0.5 * (da + db) + d_root) / (2 * alternating) if alternating > 0 else np.zeros_like(da)
    mean = shapes @ mean_q
    d_mean = shapes @ d_mean_q
    von_mises = np.sqrt(mean @ form @ mean)
    sign = -1.0 if mean[:3].sum() < 0 else 1.0
    load = alternating / material.endurance_strength
    d_load = d_alternating / material.endurance_strength
    if sign > 0 and von_mises > 0:
        load += von_mises / material.ultimate_strength
        d_load = d_load + (mean @ form @ d_mean) / von_mises / material.ultimate_strength
    return -d_load / load ** 2


def link_fatigue_factors(solution: ItemSolution, d_state: np.ndarray, motions: list) -> list[FatigueFactor]:
    """The lowest Goodman factor of each link with stress shapes over the excitations *motions* of one item.

    Parameters
    ----------
    solution : ItemSolution
    d_state : ndarray, shape (N, P)
        The derivatives of the item's state change (full coordinates).
    motions : list of (ndarray, ndarray)
        Per excitation, the projected motion phasor (n,) and its derivative (n, P).

    Returns
    -------
    list of FatigueFactor
        In the case's order of the links.
    """
    state = solution.prepared.expansion.state + solution.state.dq
    factors = []
    for name, stressed in solution.prepared.stressed.items():
        material = stressed.link.model.material
        rows = _coordinates(solution, stressed)
        mean_q = state[stressed.coordinates]
        mean = signed_von_mises(state_stress(stressed.reduced, mean_q))
        phasors = np.array([motion[rows] for motion, _ in motions]).T                  # (modes, excitations)
        tensile = np.maximum(mean, 0.0) / material.ultimate_strength

        # the largest load sigma_a / S_e + sigma_m / S_u a node can have: sigma_a <= sqrt(3) |S_i q_hat|
        bound = (np.sqrt(3) * stressed.node_norms * np.linalg.norm(phasors, axis=0).max()
                 / material.endurance_strength + tensile)
        likely = np.argsort(bound)[-min(len(bound), CANDIDATES):]
        lowest = _goodman(stressed, likely, phasors, mean).min()
        nodes = np.flatnonzero(bound >= 1 / lowest * (1 - 1e-12))          # only these can reach it
        factors_at = _goodman(stressed, nodes, phasors, mean)
        at, k = np.unravel_index(int(np.argmin(factors_at)), factors_at.shape)
        node = nodes[at]
        motion, d_motion = motions[k]
        gradient = _factor_change(stressed, int(node), mean_q, d_state[stressed.coordinates], motion[rows],
                                  d_motion[rows])
        factors.append(FatigueFactor(name, float(factors_at[at, k]), gradient, int(k)))
    return factors
