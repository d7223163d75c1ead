"""Exact positions of scene points, with their first and second derivatives.

A point of the scene moves with the coordinates of its body as

    p = x + A(r) (w + Phi q_f),

with x the body's reference position, A its rotation (Euler parameters of
a link's node, Tait-Bryan angles of the engine's node, none for a point
mass), w the point's local position and Phi its rows of the body's modal
shapes (flexible links). The local data are identified from Exudyn's own
positions at the prepared state and checked against its derivatives
there (:func:`identify`), so that a design evaluation follows the mount's
geometry exactly however far it moves.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PointKinematics", "identify", "rotation_of"]

# A(e)_ab = delta_ab + sum_ij e_i e_j EULER[a, b, i, j]: Exudyn's rotation of Euler parameters, whose
# diagonal is written 1 - 2 (e_j^2 + e_k^2) (the same on unit parameters, not off them)


def _euler_rotation(e: np.ndarray) -> np.ndarray:
    e0, e1, e2, e3 = e
    return np.array([[1 - 2 * (e2 ** 2 + e3 ** 2), 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2)],
                     [2 * (e1 * e2 + e0 * e3), 1 - 2 * (e1 ** 2 + e3 ** 2), 2 * (e2 * e3 - e0 * e1)],
                     [2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), 1 - 2 * (e1 ** 2 + e2 ** 2)]])


def _quadratic_form() -> np.ndarray:
    unit = np.eye(4)

    def part(e: np.ndarray) -> np.ndarray:
        return _euler_rotation(e) - np.eye(3)

    form = np.zeros((3, 3, 4, 4))
    for i in range(4):
        form[:, :, i, i] = part(unit[i])
        for j in range(i + 1, 4):
            form[:, :, i, j] = form[:, :, j, i] = 0.5 * (part(unit[i] + unit[j]) - part(unit[i]) - part(unit[j]))
    return form


EULER = _quadratic_form()


def _axis(angle: float, axis: int, order: int) -> np.ndarray:
    """The *order*-th derivative (0 to 2) of the rotation by *angle* about *axis* (0, 1, 2: x, y, z)."""
    c, s = [(np.cos(angle), np.sin(angle)), (-np.sin(angle), np.cos(angle)),
            (-np.cos(angle), -np.sin(angle))][order]
    one = 1.0 if order == 0 else 0.0
    if axis == 0:
        return np.array([[one, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    if axis == 1:
        return np.array([[c, 0.0, s], [0.0, one, 0.0], [-s, 0.0, c]])
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, one]])


def _tait_bryan(angles: np.ndarray, orders=(0, 0, 0)) -> np.ndarray:
    """``d^k A / d angles`` of Exudyn's Rxyz rotation ``A = R_x R_y R_z``, derivative orders per angle."""
    return _axis(angles[0], 0, orders[0]) @ _axis(angles[1], 1, orders[1]) @ _axis(angles[2], 2, orders[2])


def rotation_of(kind: str, rotation: np.ndarray) -> np.ndarray:
    """The rotation matrix of a node's rotation coordinates (``"euler"``, ``"rxyz"`` or ``"none"``)."""
    if kind == "euler":
        return _euler_rotation(rotation)
    if kind == "rxyz":
        return _tait_bryan(rotation)
    return np.eye(3)


@dataclass(frozen=True)
class PointKinematics:
    """A point moving with its body's coordinates (module text).

    Attributes
    ----------
    coordinates : ndarray of int, shape (m,)
        Full ODE2 coordinates: position (3), rotation (0, 3 or 4), modal (k).
    kind : {"none", "rxyz", "euler"}
    local : ndarray, shape (3,)
        w, m.
    modal : ndarray, shape (3, k)
        Phi.
    """

    coordinates: np.ndarray
    kind: str
    local: np.ndarray
    modal: np.ndarray

    @property
    def rotations(self) -> int:
        return {"none": 0, "rxyz": 3, "euler": 4}[self.kind]

    def expand(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position (3,), Jacobian (3, m) and Hessian (3, m, m) at the body's total coordinates *q* (m,)."""
        m = len(self.coordinates)
        nr = self.rotations
        rotation = q[3:3 + nr]
        modal = q[3 + nr:]
        w = self.local + self.modal @ modal
        jacobian = np.zeros((3, m))
        hessian = np.zeros((3, m, m))
        if m == 0:                               # on the ground
            return self.local.copy(), jacobian, hessian
        jacobian[:, :3] = np.eye(3)
        if self.kind == "none":
            return q[:3] + w, jacobian, hessian
        r = slice(3, 3 + nr)
        f = slice(3 + nr, m)
        if self.kind == "euler":
            a = np.einsum("abij,j->abi", EULER, rotation)          # A = I + a . e
            matrix = np.eye(3) + a @ rotation
            jacobian[:, r] = 2 * np.einsum("abi,b->ai", a, w)
            hessian[:, r, r] = 2 * np.einsum("abij,b->aij", EULER, w)
            mixed = 2 * np.einsum("abi,bk->aik", a, self.modal)
        else:
            matrix = _tait_bryan(rotation)
            firsts = [_tait_bryan(rotation, tuple(int(k == i) for k in range(3))) for i in range(3)]
            jacobian[:, r] = np.stack([d @ w for d in firsts], axis=1)
            for i in range(3):
                for j in range(3):
                    orders = tuple(int(k == i) + int(k == j) for k in range(3))
                    hessian[:, 3 + i, 3 + j] = _tait_bryan(rotation, orders) @ w
            mixed = np.stack([d @ self.modal for d in firsts], axis=1)
        jacobian[:, f] = matrix @ self.modal
        hessian[:, r, f] = mixed
        hessian[:, f, r] = mixed.transpose(0, 2, 1)
        return q[:3] + matrix @ w, jacobian, hessian


def identify(coordinates: np.ndarray, q: np.ndarray, position: np.ndarray, jacobian: np.ndarray,
             hessian: np.ndarray) -> PointKinematics:
    """The kinematics of a point from its position and derivatives at the body's total coordinates *q*.

    Returns
    -------
    PointKinematics

    Raises
    ------
    ValueError
        The point does not move as any of the known kinds (the derivatives
        disagree beyond the accuracy of the differences).
    """
    m = len(coordinates)
    if m == 0:
        return PointKinematics(coordinates, "none", np.asarray(position, dtype=float), np.zeros((3, 0)))
    candidates = [kind for kind, nr in (("none", 0), ("rxyz", 3), ("euler", 4)) if m >= 3 + nr]
    scale = max(1.0, float(np.abs(jacobian).max()))
    for kind in reversed(candidates):
        nr = {"none": 0, "rxyz": 3, "euler": 4}[kind]
        if kind == "none" and m > 3:
            continue
        matrix = rotation_of(kind, q[3:3 + nr])
        modal = np.linalg.solve(matrix, jacobian[:, 3 + nr:])
        local = np.linalg.solve(matrix, position - q[:3]) - modal @ q[3 + nr:]
        point = PointKinematics(coordinates, kind, local, modal)
        p, j, h = point.expand(q)
        if (np.abs(p - position).max() <= 1e-9 * max(1.0, np.abs(position).max())
                and np.abs(j - jacobian).max() <= 1e-6 * scale
                and np.abs(h - hessian).max() <= 1e-4 * max(1.0, np.abs(hessian).max())):
            return point
    raise ValueError(f"a point moving with {m} coordinates as no known body moves")
