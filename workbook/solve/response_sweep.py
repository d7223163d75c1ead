"""Harmonic responses at many frequencies at once: one eigen-decomposition, then products.

A sweep asks the same linearised scene (:class:`~workbook.solve.harmonic.HarmonicModel`)
for ``z_hat = (K + i H - w^2 M + i w D)^-1 B f_hat`` at hundreds of frequencies
(H the structural damping of the loss factors, frequency-independent, so
``K + i H`` is one complex stiffness). In first-order form ``y = [z, z']`` the system matrix
``A = [[0, I], [-M^-1 (K + i H), -M^-1 D]]`` is decomposed once, ``A = V diag(lambda) V^-1``,
and then every frequency costs a division and a product:
``z_hat(w) = V_z diag(1 / (i w - lambda)) V^-1 [0; M^-1 B f_hat]``.

Exact, not approximate: the residual of every frequency is computed in the
second-order form and corrected once by the same map (iterative
refinement); a frequency whose residual stays above round-off (an
ill-conditioned eigenbasis, e.g. a defective eigenvalue) is solved directly,
as :meth:`HarmonicModel.respond` does.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbook.answers.isolation import pylon_sum
from workbook.solve.harmonic import FrequencyResponse, HarmonicModel

__all__ = ["respond_many", "modal_motions", "SweepResponse", "ROUND_OFF"]

#: Backward error accepted as exact: residual of ``(K + i H - w^2 M + i w D) z = b`` over
#: ``|K + i H| |z| + w^2 |M| |z| + w |D| |z| + |b|`` (a direct solve reaches about 1e-16).
ROUND_OFF = 1e-13


def _complex_stiffness(model: HarmonicModel) -> np.ndarray:
    """``K + i H``: the stiffness with the structural damping of the loss factors (real K without any)."""
    lin = model.linearization
    return lin.stiffness if lin.structural is None else lin.stiffness + 1j * lin.structural


class _Modal:
    """The eigen-decomposition of a linearisation in first-order form, and the map it gives."""

    def __init__(self, model: HarmonicModel):
        lin = model.linearization
        n = lin.mass.shape[0]
        mass_inverse = np.linalg.inv(lin.mass)
        system = np.block([[np.zeros((n, n)), np.eye(n)],
                           [-mass_inverse @ _complex_stiffness(model), -mass_inverse @ lin.damping]])
        self.eigenvalues, vectors = np.linalg.eig(system)
        self.displacement = vectors[:n]              # V_z, shape (n, 2n)
        self.load = np.linalg.solve(vectors, np.vstack([np.zeros((n, n)), mass_inverse]))  # V^-1 [0; M^-1]
        self.n = n

    def solve(self, omegas: np.ndarray, loads: np.ndarray) -> np.ndarray:
        """``(K - w^2 M + i w D)^-1 b`` for each w and its load column (or one load for all), shape (n, frequencies)."""
        modal = self.load @ loads
        modal = (modal[:, None] if modal.ndim == 1 else modal) / (1j * omegas[None, :] - self.eigenvalues[:, None])
        return self.displacement @ modal


def _times(matrix: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``matrix @ values`` for a real matrix and complex values, in real arithmetic (half the work)."""
    columns = values.shape[1]
    both = matrix @ np.hstack([values.real, values.imag])
    return both[:, :columns] + 1j * both[:, columns:]


def _residual(model: HarmonicModel, omegas, motion, loads):
    """``b - (K + i H - w^2 M + i w D) z`` for every frequency, shape (n, f)."""
    lin = model.linearization
    n = lin.mass.shape[0]
    products = _times(np.vstack([lin.mass, lin.damping]), motion)
    return loads - (_complex_stiffness(model) @ motion - omegas ** 2 * products[:n] + 1j * omegas * products[n:])


def _backward_errors(model: HarmonicModel, omegas, motion, loads) -> np.ndarray:
    """Normwise backward error of each frequency's solution (Frobenius norms of the matrices)."""
    lin = model.linearization
    size = (np.linalg.norm(_complex_stiffness(model)) + omegas ** 2 * np.linalg.norm(lin.mass)
            + omegas * np.linalg.norm(lin.damping))
    residual = np.linalg.norm(_residual(model, omegas, motion, loads), axis=0)
    return residual / (size * np.linalg.norm(motion, axis=0) + np.linalg.norm(loads, axis=0))


def modal_motions(model: HarmonicModel, omegas: np.ndarray, load: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coordinates' phasors from the eigen-decomposition, refined once, and their backward errors.

    Parameters
    ----------
    model : HarmonicModel
    omegas : ndarray, shape (f,)
        rad/s.
    load : ndarray, shape (n,)
        Generalised force phasor ``B f_hat``.

    Returns
    -------
    motion : ndarray, complex, shape (n, f)
    backward_errors : ndarray, shape (f,)
    """
    modal = _Modal(model)
    loads = np.broadcast_to(load[:, None], (len(load), len(omegas)))
    motion = modal.solve(omegas, load)
    motion += modal.solve(omegas, _residual(model, omegas, motion, loads))  # one step of iterative refinement
    return motion, _backward_errors(model, omegas, motion, loads)


@dataclass(frozen=True)
class SweepResponse:
    """Complex force amplitudes of one harmonic excitation at many frequencies.

    Attributes
    ----------
    frequencies_hz : ndarray, shape (f,)
    hinge_names : list of str
        The force channels, in the order of ``hinge_forces``' second axis.
    hinge_forces : ndarray, complex, shape (f, h, 3)
        ``F_hat`` of each channel (force on its marker-0 body), N.
    pylon_force : ndarray, complex, shape (f, 3)
        Sum over the pylon channels, N.
    """

    frequencies_hz: np.ndarray
    hinge_names: list
    hinge_forces: np.ndarray
    pylon_force: np.ndarray

    def response(self, index: int) -> FrequencyResponse:
        """The answer at one frequency, as :meth:`HarmonicModel.respond` gives it."""
        return FrequencyResponse(float(self.frequencies_hz[index]), dict(zip(self.hinge_names, self.hinge_forces[index], strict=True)),
                                 self.pylon_force[index])


def respond_many(model: HarmonicModel, frequencies_hz, force, point) -> SweepResponse:
    """Steady-state hinge forces at every frequency of a sweep, equal to :meth:`HarmonicModel.respond`'s.

    Parameters
    ----------
    model : HarmonicModel
    frequencies_hz : array_like, shape (f,)
        Hz.
    force : array_like, shape (3,)
        Force phasor, N (complex for a rotating force).
    point : array_like, shape (3,)
        Where on the engine the force acts, m.

    Returns
    -------
    SweepResponse
    """
    frequencies_hz = np.asarray(frequencies_hz, dtype=float)
    omegas = 2 * np.pi * frequencies_hz
    load = model.input_matrix(point) @ np.asarray(force, dtype=complex)
    motion, errors = modal_motions(model, omegas, load)
    for j in np.flatnonzero(errors > ROUND_OFF):
        motion[:, j] = model.motion(frequencies_hz[j], load)
    outputs = _times(np.vstack([model.stiffness_output, model.structural_output, model.damping_output]), motion)
    third = len(outputs) // 3
    forces = (outputs[:third] + 1j * (outputs[third:2 * third] + omegas * outputs[2 * third:]))
    forces = forces.T.reshape(len(omegas), -1, 3)  # (f, h, 3)
    hinges = dict(zip(model.hinge_names, np.moveaxis(forces, 1, 0), strict=True))
    return SweepResponse(frequencies_hz, list(model.hinge_names), forces, pylon_sum(hinges, model.pylon_hinges))
