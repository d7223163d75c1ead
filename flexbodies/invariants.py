"""Floating-frame inertia invariants of a reduced body, with NumPy.

The invariants are those Exudyn's ``ObjectFFRFreducedOrderInterface``
computes for ``ObjectFFRFreducedOrder`` (Zwölfer and Gerstmayr's nodal-based
floating frame of reference with modal reduction), under the same names and
with the same rounding of the reduced matrices. Exudyn builds the skew
matrices node by node in Python; here they are built at once and every
product with the mass matrix comes from one sparse product ``M X`` with all
the bases side by side.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["ffrf_invariants", "skew_columns"]

#: Entries of the reduced mass and stiffness matrices below this fraction of their largest are set to 0,
#: as Exudyn does (its ``roundMassMatrix`` and ``roundStiffnessMatrix``).
ROUND_RELATIVE = 1e-13


def skew_columns(vectors: np.ndarray) -> np.ndarray:
    """Node-wise skew (cross-product) matrices of node-major vectors.

    Parameters
    ----------
    vectors : ndarray, shape (3 n,) or (3 n, m)
        Node-major vectors (x, y, z of node 0, then node 1, ...).

    Returns
    -------
    ndarray, shape (3 n, 3) or (3 n, 3 m)
        Block ``(i, j)`` is the 3x3 matrix ``a~`` with ``a~ b = a x b`` of node
        ``i``'s part of column ``j``.
    """
    vectors = np.asarray(vectors, dtype=float)
    columns = vectors.reshape(vectors.shape[0], -1)
    n, m = columns.shape[0] // 3, columns.shape[1]
    x, y, z = columns.reshape(n, 3, m).transpose(1, 0, 2)
    zero = np.zeros_like(x)
    blocks = np.stack([
        np.stack([zero, -z, y], axis=-1),
        np.stack([z, zero, -x], axis=-1),
        np.stack([-y, x, zero], axis=-1),
    ], axis=1)  # (n, 3 rows, m, 3 columns)
    return blocks.reshape(3 * n, 3 * m)


def _rounded(matrix: np.ndarray) -> np.ndarray:
    matrix = np.array(matrix, dtype=float)
    matrix[np.abs(matrix) < ROUND_RELATIVE * np.abs(matrix).max(initial=0.0)] = 0.0
    return matrix


def ffrf_invariants(nodes, mass, stiffness, mode_basis) -> dict:
    """Floating-frame inertia invariants of a body with node-major mass and modes.

    Parameters
    ----------
    nodes : ndarray, shape (n, 3)
        Node positions in the body frame, m.
    mass, stiffness : scipy.sparse matrix, shape (3n, 3n)
        Node-major mass (kg) and stiffness (N/m).
    mode_basis : ndarray, shape (3n, m)
        Elastic modes, no rigid-body motion, m per modal unit.

    Returns
    -------
    dict
        The arrays of :data:`~flexbodies.reduced.FFRF_KEYS`: reduced mass and
        stiffness, ``xRef`` (m), ``inertiaLocal`` about the origin (kg m^2),
        ``Mtt`` and ``totalMass`` (kg), the centre of mass ``chiU`` (m) and
        its skew matrix, and the mass products of the translation, position
        and mode bases with the modes and their skew matrices.
    """
    mass = sp.csr_matrix(mass)
    psi = np.asarray(mode_basis, dtype=float)
    x_ref = np.asarray(nodes, dtype=float).ravel()
    n, m = len(x_ref) // 3, psi.shape[1]
    phi_t = np.tile(np.eye(3), (n, 1))
    x_tilde = skew_columns(x_ref)
    psi_tilde = skew_columns(psi)
    bases = np.hstack([phi_t, x_tilde, psi, psi_tilde])
    weighted = mass @ bases
    parts = np.cumsum([0, 3, 3, m, 3 * m])
    t, xt, p, pt = (slice(a, b) for a, b in zip(parts[:-1], parts[1:], strict=True))
    products = bases.T @ weighted
    mtt = products[t, t]
    total = mtt[0, 0]
    chi_u = (weighted[:, t].T @ x_ref) / total
    return {
        "massMatrixReduced": _rounded(products[p, p]),
        "stiffnessMatrixReduced": _rounded(psi.T @ (sp.csr_matrix(stiffness) @ psi)),
        "xRef": x_ref,
        "inertiaLocal": products[xt, xt],
        "Mtt": mtt,
        "totalMass": np.asarray(total),
        "chiU": chi_u,
        "chiUtilde": skew_columns(chi_u),
        "mPsiTildePsi": products[pt, p],
        "mPsiTildePsiTilde": products[pt, pt],
        "mPhitTPsi": products[t, p],
        "mPhitTPsiTilde": products[t, pt],
        "mXRefTildePsi": products[xt, p],
        "mXRefTildePsiTilde": products[xt, pt],
    }
