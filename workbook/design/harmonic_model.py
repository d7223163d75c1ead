"""The linear mount of designs at their preloads, as the harmonic models the evaluation solves.

:class:`BodyHarmonic` keeps the model body by body, as
:func:`workbook.design.linear_mount.linear_model` assembles it: designs
answered together are solved on it (:func:`workbook.design.blocks.channel_solve`).
:class:`Harmonic` is the same model in whole matrices, for one design's
derivatives and bands, and for a design the body-by-body solve does not
trust. Both answer :meth:`~Harmonic.respond` alike.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbook.design.assembly import ChannelSprings, Projection, solve_each
from workbook.design.blocks import BodyLayout, ChannelCoupling, channel_solve
from workbook.design.channel_set import ChannelSet, spring_matrix, spring_rows
from workbook.model.case import SingleFrequencyExcitation
from workbook.solve.harmonic import point_phasors

__all__ = ["Harmonic", "BodyHarmonic"]


def _point_key(point) -> tuple:
    return tuple(np.round(np.asarray(point, dtype=float), 12))


@dataclass(frozen=True)
class Harmonic:
    """The projected linear models at states: ``Z = K - w^2 M + i (w D + H)``, outputs ``C_k + i (C_h + w C_d)``;
    of one design, or of several (leading axis)."""

    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    structural: np.ndarray
    outputs: tuple              # C_k, C_d, C_h, shape (..., 3 c, n) each
    basis: Projection
    inputs: dict                # point -> (..., n, 3)

    def dynamic(self, omega) -> np.ndarray:
        """Z at the circular frequency *omega* (rad/s; one per design: shape (...)), shape (..., n, n)."""
        w = np.asarray(omega, dtype=float)[..., None, None]
        return self.stiffness - w ** 2 * self.mass + 1j * (w * self.damping + self.structural)

    def output(self, omega) -> np.ndarray:
        """The channel force phasors per motion phasor at *omega* (rad/s, as :meth:`dynamic`), shape (..., 3 C, n)."""
        stiffness_output, damping_output, structural_output = self.outputs
        return stiffness_output + 1j * (structural_output + np.asarray(omega, dtype=float)[..., None, None]
                                        * damping_output)

    def load(self, excitation: SingleFrequencyExcitation, design: int | None = None, phasors=None) -> np.ndarray:
        """The generalised force phasor of *excitation* (of the design *design* of several; *phasors*: its
        :func:`~workbook.solve.harmonic.point_phasors` when known), shape (n,)."""
        total_load = np.zeros(self.mass.shape[-1], dtype=complex)
        for p, phasor in point_phasors(excitation) if phasors is None else phasors:
            inputs = self.inputs[_point_key(p)]
            total_load += (inputs if design is None else inputs[design]) @ phasor
        return total_load

    def respond(self, omega: np.ndarray, loads: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The channel force phasors (B, C, 3) of designs (B) at *omega* (B,) under *loads* (B, n) (:meth:`load`),
        N, and which designs' Z is singular (their forces mean nothing)."""
        motion, singular = solve_each(self.dynamic(omega), loads)
        return (self.output(omega) @ motion[..., None])[..., 0].reshape(len(loads), -1, 3), singular

    def dense(self) -> "Harmonic":
        """The models in whole matrices: themselves."""
        return self

    def take(self, rows) -> "Harmonic":
        """The designs *rows* (an index: one design without its axis)."""
        return Harmonic(self.mass[rows], self.stiffness[rows], self.damping[rows], self.structural[rows],
                        tuple(o[rows] for o in self.outputs), self.basis.take(rows),
                        {key: value[rows] for key, value in self.inputs.items()})

    def stacked(self) -> "Harmonic":
        """One design's model as a batch of one."""
        return self.take(np.newaxis)


@dataclass(frozen=True)
class BodyHarmonic:
    """The projected linear models of designs (leading axis D), body by body.

    Attributes
    ----------
    layout : BodyLayout
    channels : ChannelSet
        The force channels' points.
    coupling : ChannelCoupling
        How they join the bodies.
    mass, stiffness, damping, structural : ndarray, shape (D, K, w, w)
        Each body's M, K (the tangent), D and H on its independent coordinates, without the channels.
    points : ndarray, shape (D, 2 C, 3, w)
        The channels' points' Jacobians on their bodies' independent coordinates, with the sign of d.
    springs : ChannelSprings
        Each design's channel springs, (D, C, 3, 3) each.
    sign : float
        Of Exudyn's ``Force`` output, ``sign S d``.
    basis : Projection
    inputs : dict
        Excitation point -> (its body, its Jacobian (D, 3, w) on that body's independent coordinates).
    """

    layout: BodyLayout
    channels: ChannelSet
    coupling: ChannelCoupling
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    structural: np.ndarray
    points: np.ndarray
    springs: ChannelSprings
    sign: float
    basis: Projection
    inputs: dict

    def load(self, excitation: SingleFrequencyExcitation, design: int, phasors=None) -> np.ndarray:
        """The generalised force phasor of *excitation* on each body of the design *design*, shape (K, w)."""
        out = np.zeros(self.mass.shape[1:3], dtype=complex)
        for p, phasor in point_phasors(excitation) if phasors is None else phasors:
            block, jacobian = self.inputs[_point_key(p)]
            out[block] += phasor @ jacobian[design]
        return out

    def respond(self, omega: np.ndarray, loads: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """As :meth:`Harmonic.respond`, *loads* (D, K, w) (:meth:`load`): body by body, and a design the
        body-by-body solve does not trust (:func:`~workbook.design.blocks.channel_solve`) in whole matrices."""
        w = np.asarray(omega, dtype=float)
        springs = self.springs
        frequency = w[:, None, None, None]
        # K - w^2 M + i (w D + H), its parts in place
        dynamic = np.empty(np.broadcast_shapes(frequency.shape, self.stiffness.shape), dtype=complex)
        np.multiply(-frequency ** 2, self.mass, out=dynamic.real)
        dynamic.real += self.stiffness
        dynamic.real += self.layout.padding
        np.multiply(frequency, self.damping, out=dynamic.imag)
        dynamic.imag += self.structural
        impedance = springs.stiffness + 1j * (frequency * springs.damping + self.sign * springs.structural)
        separation, trouble = channel_solve(self.coupling, dynamic, self.points, impedance, loads)
        output = springs.stiffness + 1j * (springs.structural + frequency * springs.damping)
        forces = self.sign * (output @ separation[..., None])[..., 0]
        singular = np.zeros(len(loads), dtype=bool)
        rows = np.flatnonzero(trouble)
        if len(rows):
            forces[rows], singular[rows] = self.take(rows).dense().respond(w[rows], self.layout.vector(loads[rows]))
        return forces, singular

    def dense(self) -> Harmonic:
        """The same models in whole matrices."""
        layout, springs = self.layout, self.springs
        jacobian = layout.channel_jacobian(self.channels, self.points)
        inputs = {}
        for key, (block, rows) in self.inputs.items():
            on_bodies = np.zeros(rows.shape[:-1] + self.mass.shape[-3:-2] + rows.shape[-1:])
            on_bodies[..., block, :] = rows
            inputs[key] = layout.vector(on_bodies).swapaxes(-1, -2)
        return Harmonic(
            layout.dense(self.mass),
            layout.dense(self.stiffness) + spring_matrix(springs.stiffness, jacobian),
            layout.dense(self.damping) + spring_matrix(springs.damping, jacobian),
            layout.dense(self.structural) + self.sign * spring_matrix(springs.structural, jacobian),
            tuple(self.sign * spring_rows(spring, jacobian)
                  for spring in (springs.stiffness, springs.damping, springs.structural)),
            self.basis, inputs)

    def take(self, rows) -> "BodyHarmonic":
        """The designs *rows* (an index: one design without its axis)."""
        return BodyHarmonic(self.layout, self.channels, self.coupling, self.mass[rows], self.stiffness[rows], self.damping[rows],
                            self.structural[rows], self.points[rows], self.springs.take(rows), self.sign,
                            self.basis.take(rows), {key: (block, rows_[rows])
                                                    for key, (block, rows_) in self.inputs.items()})
