"""The box-beam pylon's compliance at its pins, from a beam finite-element model.

Euler-Bernoulli beam elements (two nodes, six DOF each: three translations,
three rotations) with the box's section constants
(:meth:`workbook.model.pylon_beam.BoxBeamPylon.section`), consistent mass
(translation and the section's polar inertia), clamped at the root.
Stations are placed at each pin's foot on the axis and at least
``elements`` intervals over the length; a pin moves with its station's
cross-section through a rigid offset r, ``x_pin = u + theta x r``. The
compliance at the pins follows
(:class:`workbook.solve.pylon_structure.PylonStructure`). Pins at one
station are rigidly joined by their fitting, so G need not be invertible: the four-pole set closes it in its compliance form
(:meth:`workbook.solve.four_pole.FourPole.respond`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbook.errors import CaseError
from workbook.model.pylon_beam import BoxBeamPylon
from workbook.solve.pylon_structure import PylonStructure

__all__ = ["BeamModel", "beam_model"]

#: Relative distance (of the length) within which a pin's foot counts as on the beam.
STATION_TOLERANCE = 1e-9


def _element(beam: BoxBeamPylon, length: float) -> tuple[np.ndarray, np.ndarray]:
    """Local stiffness and consistent mass of one element, (12, 12), DOF order per node
    u (axial), v (width), w (height), rx, ry, rz."""
    section, material = beam.section(), beam.material
    e, rho = material.youngs_modulus, material.density
    g = e / (2 * (1 + material.poisson_ratio))
    k, m = np.zeros((12, 12)), np.zeros((12, 12))
    a, L = section.area, length

    def put(target, dofs, block):
        target[np.ix_(dofs, dofs)] += block

    bar = np.array([[1.0, -1.0], [-1.0, 1.0]])
    pair = np.array([[2.0, 1.0], [1.0, 2.0]])
    put(k, [0, 6], e * a / L * bar)
    put(m, [0, 6], rho * a * L / 6 * pair)
    put(k, [3, 9], g * section.torsion_constant / L * bar)
    put(m, [3, 9], rho * (section.second_moment_2 + section.second_moment_3) * L / 6 * pair)
    bending = np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L ** 2, -6 * L, 2 * L ** 2],
                        [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L ** 2, -6 * L, 4 * L ** 2]]) / L ** 3
    inertia = rho * a * L / 420 * np.array([[156, 22 * L, 54, -13 * L], [22 * L, 4 * L ** 2, 13 * L, -3 * L ** 2],
                                            [54, 13 * L, 156, -22 * L], [-13 * L, -3 * L ** 2, -22 * L, 4 * L ** 2]])
    flip = np.diag([1.0, -1.0, 1.0, -1.0])         # rotation about the width axis is -dw/dx
    put(k, [1, 5, 7, 11], e * section.second_moment_3 * bending)
    put(m, [1, 5, 7, 11], inertia)
    put(k, [2, 4, 8, 10], e * section.second_moment_2 * flip @ bending @ flip)
    put(m, [2, 4, 8, 10], flip @ inertia @ flip)
    return k, m


@dataclass(frozen=True)
class BeamModel(PylonStructure):
    """The clamped beam's matrices and its pin map (:class:`PylonStructure`) and its stations.

    Attributes
    ----------
    stations : ndarray
        Node positions along the axis from the root, m.
    """

    stations: np.ndarray


def beam_model(beam: BoxBeamPylon, pins) -> BeamModel:
    """The finite-element model of *beam* carrying *pins*.

    Parameters
    ----------
    beam : BoxBeamPylon
    pins : sequence of 3 floats
        Pin positions, m (``Case.pylon_pins()`` order).

    Raises
    ------
    workbook.errors.CaseError
        A pin whose foot on the axis lies beyond the root or the tip.
    """
    frame = beam.frame()
    axis, root, length = frame[0], np.asarray(beam.root), beam.length
    feet = []
    for position in pins:
        station = float((np.asarray(position) - root) @ axis)
        if not -STATION_TOLERANCE * length <= station <= (1 + STATION_TOLERANCE) * length:
            raise CaseError(f"pylon beam {beam.name!r}", "tip", beam.tip,
                            f"a beam whose axis reaches the foot of the pin at {tuple(position)} "
                            f"({station:.4g} m from the root; the beam is {length:.4g} m long)")
        feet.append(min(max(station, 0.0), length))
    grid = np.linspace(0.0, length, beam.elements + 1)
    stations = np.unique(np.concatenate([grid, feet]))
    stations = stations[np.concatenate([[True], np.diff(stations) > STATION_TOLERANCE * length])]
    nodes = len(stations)
    rotate = np.kron(np.eye(4), frame)              # local = rotate @ global, per element
    stiffness, mass = np.zeros((6 * nodes, 6 * nodes)), np.zeros((6 * nodes, 6 * nodes))
    for n in range(nodes - 1):
        k, m = _element(beam, stations[n + 1] - stations[n])
        dofs = slice(6 * n, 6 * n + 12)
        stiffness[dofs, dofs] += rotate.T @ k @ rotate
        mass[dofs, dofs] += rotate.T @ m @ rotate
    pin_map = np.zeros((3 * len(feet), 6 * nodes))
    for p, (position, foot) in enumerate(zip(pins, feet, strict=True)):
        node = int(np.argmin(np.abs(stations - foot)))
        offset = np.asarray(position) - (root + stations[node] * axis)
        cross = np.array([[0, -offset[2], offset[1]], [offset[2], 0, -offset[0]], [-offset[1], offset[0], 0]])
        pin_map[3 * p:3 * p + 3, 6 * node:6 * node + 3] = np.eye(3)
        pin_map[3 * p:3 * p + 3, 6 * node + 3:6 * node + 6] = -cross      # theta x r = -r x theta
    free = slice(6, None)                           # the root clamped
    return BeamModel(stiffness[free, free], mass[free, free], pin_map[:, free], beam.loss_factor, stations)
