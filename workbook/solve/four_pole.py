"""Four-pole (transfer) parameters of the whole mount, from the linearised scene.

The mount (links and hinges) joins two terminals: the engine, whose rigid
motion ``x1`` (6 coordinates: translations of its centre of gravity, m, and
its Tait-Bryan angles, rad) moves every engine-side hinge point, and the
pylon pins, whose motions ``x2`` (3 per pin, m; pylon-side hinges at one
point share a pin) move the pylon-side hinge points. With the forces
``F1`` (generalised, N and N m) and ``F2`` (N per pin) applied *to the
mount* at its terminals, harmonic at circular frequency w,

    F1 = K11 x1 + K12 x2,        F2 = K21 x1 + K22 x2.

K11 and K22 are the driving-point dynamic stiffnesses (the other terminal
blocked), K21 and K12 the blocked transfer dynamic stiffnesses; the force on
a blocked pylon is ``-K21 x1``. For a mass m on a spring-damper k, c they
are ``K11 = k + i w c - w^2 m``, ``K12 = K21 = -(k + i w c)``,
``K22 = k + i w c``.

They come from the harmonic model of the preloaded scene
(:mod:`workbook.solve.harmonic`): its dynamic stiffness
``S = K - w^2 M + i w D`` in independent coordinates, turned so that the
engine's six coordinates stand alone, less the engine's own inertia (and the
rotors' gyroscopic coupling, when built), is condensed onto the engine
coordinates. A pin motion enters through the pylon-side hinge laws
``F_h = (k + i w d)(J z - x2)`` (the hinge force on the pylon, J the
hinge point's motion per coordinate): the channel output ``C_h = (k + i w d) J``
of the harmonic model is also the input of a pin motion, ``C_h^T``. With
``e`` the engine coordinates and ``i`` the rest,

    K11 = S_ee - S_ei S_ii^-1 S_ie,     K12 = S_ei S_ii^-1 C_i^T - C_e^T,
    K21 = C_i S_ii^-1 S_ie - C_e,       K22 = (k + i w d) - C_i S_ii^-1 C_i^T.

What stays in K11 besides the links and hinges: the stiffness of the static
loads on the turned engine (the preload's load stiffness), which belongs to
the preloaded state and not to the engine's inertia.

Reciprocity. The condensation keeps the symmetry of what it is given: from
the symmetric part of S the set is reciprocal, ``K12 = K21^T``, to 1e-14 of
its largest entry. The linearisation itself is not quite symmetric: at the
preload, the derivative of Exudyn's equations in the bodies' Euler
parameters has a skew part (on the coarse reference mount with flexible
links 3.4e-6 of its largest entry, 0.5 % of one link's rotation entry;
1.6e-12 without the preload), which the set carries: K12 and K21^T
differ by 9.4e-8 of the largest entry (1.2e-6 with Exudyn's own Jacobian,
:mod:`workbook.solve.modes`), by an amount that follows the round-off of
the static solve and of the differences, machine to machine.

On a pylon of point dynamic stiffness ``Z_p`` (per pin, force on the pylon
per pin motion) the engine moves by
``(Z_e + K11 - K12 (K22 + Z_p)^-1 K21) x1 = B f`` for a force f at a point
of the engine (``Z_e = -w^2 M_e + i w G``, B its generalised force), the
pins by ``x2 = -(K22 + Z_p)^-1 K21 x1``, and the pylon is loaded with
``Z_p x2``; on a rigid pylon (``x2 = 0``) with ``-K21 x1``. The insertion
loss compares the pylon force with the engine bolted rigidly to the same
pins (the pins then move with the engine, ``x2 = T x1``).
"""
from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass

import numpy as np

from workbook._renamed import renamed
from workbook.errors import CaseError, FourPoleError
from workbook.model.case import DIRECTIONS, ENGINE, Case
from workbook.scene.hinge_laws import law_of, nonlinear_hinges
from workbook.solve.guards import RESONANCE_BAND, undamped_mode_near
from workbook.solve.harmonic import RoundOff

__all__ = ["FourPole", "PylonResponse", "checked_frequencies", "condense", "mount_case", "frequency_grid", "QUANTITIES",
           "REPORT_GRID"]

#: The per-direction quantities of :meth:`FourPole.direction_values` with their meaning.
QUANTITIES = {
    "K11": "engine driving-point dynamic stiffness (engine translates, rotations held, pins blocked)",
    "K21": "blocked transfer dynamic stiffness (force on the mount at the pins per engine translation)",
    "K22": "pylon driving-point dynamic stiffness (all pins translate together, engine blocked)",
}
#: Engine coordinates of the four-pole set: centre-of-gravity translations, then rotations.
ENGINE_COORDINATES = 6
#: The default frequencies of a four-pole table: from (Hz), to (Hz), log-spaced points.
REPORT_GRID = (10.0, 500.0, 41)
#: Smallest reciprocal condition number of a matrix the four-pole set inverts.
SINGULAR_RCOND = 1e-13


def frequency_grid(start_hz: float, stop_hz: float, points: int) -> np.ndarray:
    """Logarithmically spaced frequencies from *start_hz* to *stop_hz*, Hz.

    Raises
    ------
    workbook.errors.CaseError
        Frequencies not > 0, stop below start, or fewer than 1 point.
    """
    if not (np.isfinite(start_hz) and start_hz > 0):
        raise CaseError("four-pole frequencies", "from", start_hz, "a frequency > 0 Hz")
    if not (np.isfinite(stop_hz) and stop_hz >= start_hz):
        raise CaseError("four-pole frequencies", "to", stop_hz, f"a frequency >= {start_hz:g} Hz (the start)")
    if int(points) != points or points < 1:
        raise CaseError("four-pole frequencies", "points", points, "a whole number >= 1")
    return np.geomspace(start_hz, stop_hz, int(points)) if points > 1 else np.array([float(start_hz)])


def checked_frequencies(frequencies_hz) -> np.ndarray:
    """*frequencies_hz* as a flat array, Hz.

    Raises
    ------
    workbook.errors.CaseError
        No frequency, or one not > 0.
    """
    frequencies = np.asarray(frequencies_hz, dtype=float).reshape(-1)
    if frequencies.size == 0 or not np.all(np.isfinite(frequencies)) or frequencies.min() <= 0:
        raise CaseError("four-pole frequencies", "frequencies", list(frequencies), "one or more frequencies > 0 Hz")
    return frequencies


def _solve(matrix: np.ndarray, rhs: np.ndarray, what: str, frequency_hz: float, modes=()) -> np.ndarray:
    """``matrix^-1 rhs``, or a FourPoleError naming *what* is singular at *frequency_hz*: its pivots
    vanish, or *frequency_hz* lies on one of *modes* (*what*'s own) that is undamped
    (:func:`~workbook.solve.guards.undamped_mode_near`, :data:`~workbook.solve.guards.RESONANCE_BAND`),
    where round-off alone keeps the pivots apart from zero (T of 3e11 on the reference mount)."""
    import scipy.linalg as sla  # here: the command line's parser takes this module's defaults
    if matrix.size == 0:
        return np.zeros((0, rhs.shape[1]), dtype=complex)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sla.LinAlgWarning)   # judged below, in plain words
        lu, pivots = sla.lu_factor(matrix, check_finite=False)
    norm = np.abs(matrix).sum(axis=0).max()
    diagonal = np.abs(np.diag(lu))
    mode = undamped_mode_near(frequency_hz, modes, RESONANCE_BAND)
    if (mode is not None or not np.all(np.isfinite(lu))
            or diagonal.min() <= SINGULAR_RCOND * max(norm, np.finfo(float).tiny)):
        which = "" if mode is None else f", the mode at {mode.frequency_hz:.6g} Hz ({mode.description})"
        raise FourPoleError(f"the four-pole set is singular at {frequency_hz:g} Hz: {what} has no inverse "
                            f"(an undamped resonance exactly at this frequency{which}); move the frequency or add "
                            "damping")
    return sla.lu_solve((lu, pivots), rhs, check_finite=False)


@dataclass(frozen=True)
class PylonResponse:
    """The mount's response to a force at the engine at one frequency.

    Attributes
    ----------
    frequency_hz : float
    engine_motion : ndarray, complex, shape (6,)
        ``x1``: centre-of-gravity translation (m) and rotations (rad).
    pin_motions : ndarray, complex, shape (p, 3)
        ``x2`` per pin, m (zero on a rigid pylon).
    pin_forces : ndarray, complex, shape (p, 3)
        Force on the pylon at each pin, N.
    """

    frequency_hz: float
    engine_motion: np.ndarray
    pin_motions: np.ndarray
    pin_forces: np.ndarray

    @property
    def pylon_force(self) -> np.ndarray:
        """Sum of the pin forces on the pylon, N, complex, shape (3,)."""
        return self.pin_forces.sum(axis=0)


@dataclass(frozen=True)
class FourPole:
    """The mount's four-pole parameters against frequency.

    Attributes
    ----------
    case_name : str
    frequencies_hz : ndarray, shape (f,)
    pins : list of str
        Pin names: the pylon-side hinges at each pin, joined by " + ".
    pin_positions : ndarray, shape (p, 3)
        m.
    k11 : ndarray, complex, shape (f, 6, 6)
        Engine driving-point dynamic stiffness, N/m, N/rad, N m/m, N m/rad.
    k12 : ndarray, complex, shape (f, 6, 3 p)
        Generalised engine force per pin motion (engine blocked), N/m, N m/m.
    k21 : ndarray, complex, shape (f, 3 p, 6)
        Pin force per engine motion (pins blocked), N/m, N/rad.
    k22 : ndarray, complex, shape (f, 3 p, 3 p)
        Pin driving-point dynamic stiffness, N/m.
    engine_stiffness : ndarray, complex, shape (f, 6, 6)
        ``Z_e``: the engine's own dynamic stiffness (inertia, rotors'
        gyroscopic coupling), N/m ...
    pin_kinematics : ndarray, shape (3 p, 6)
        ``T``: pin motions of the engine bolted rigidly to the pins, per
        engine coordinate.
    engine_center : ndarray, shape (3,)
        The engine's centre of gravity, m.
    modes : tuple of workbook.solve.modes.Mode
        The modes of the engine on its mount on a rigid pylon (the scene the
        set was formed from), whose undamped ones :meth:`respond` on a rigid
        pylon refuses (empty: not known).
    roundoff : workbook.solve.harmonic.RoundOff or None
        The round-off of the linearisation the set was condensed from; :meth:`respond` refuses an answer
        it could swamp (None: not checked).
    """

    case_name: str
    frequencies_hz: np.ndarray
    pins: list
    pin_positions: np.ndarray
    k11: np.ndarray
    k12: np.ndarray
    k21: np.ndarray
    k22: np.ndarray
    engine_stiffness: np.ndarray
    pin_kinematics: np.ndarray
    engine_center: np.ndarray
    _point_inputs: dict
    modes: tuple = ()
    roundoff: RoundOff | None = None

    def _input(self, point) -> np.ndarray:
        """Generalised engine force of a unit force in x, y, z at *point*, shape (6, 3)."""
        key = tuple(np.round(np.asarray(point, dtype=float), 12))
        if key not in self._point_inputs:
            raise CaseError("four-pole set", "point", tuple(point),
                            f"a point the set was formed for: {', '.join(map(str, self._point_inputs))}")
        return self._point_inputs[key]

    def direction_values(self, quantity: str) -> np.ndarray:
        """Per-direction value of *quantity* (see :data:`QUANTITIES`), complex, shape (f, 3), N/m.

        K11: the translation diagonal of K11. K21: the sum over the pins of
        the pin force in a direction per engine translation in it. K22: the
        force in a direction summed over the pins when every pin translates
        together in it.
        """
        pins = len(self.pins)
        if quantity == "K11":
            return np.stack([self.k11[:, d, d] for d in range(3)], axis=1)
        if quantity == "K21":
            return np.stack([self.k21[:, d::3, d].sum(axis=1) for d in range(3)], axis=1)
        if quantity == "K22":
            return np.stack([self.k22[:, d::3, d::3].reshape(-1, pins * pins).sum(axis=1) for d in range(3)],
                            axis=1)
        raise ValueError(f"quantity must be one of {', '.join(QUANTITIES)}, got {quantity!r}")

    def _pylon_matrix(self, pylon) -> np.ndarray:
        """The pylon impedance as a block-diagonal (f, 3 p, 3 p) complex array."""
        frequencies, pins = len(self.frequencies_hz), len(self.pins)
        value = np.asarray(pylon, dtype=complex)
        shapes = {(): "scalar", (frequencies,): "scalar per frequency", (3, 3): "3x3",
                  (frequencies, 3, 3): "3x3 per frequency", (frequencies, pins, 3, 3): "3x3 per frequency and pin"}
        if value.shape not in shapes:
            raise CaseError("pylon impedance", "shape", value.shape,
                            f"one of {', '.join(f'{s} ({w})' for s, w in shapes.items())} for {frequencies} "
                            f"frequencies and {pins} pins")
        if not np.all(np.isfinite(value)):
            raise CaseError("pylon impedance", "values", "NaN or infinite", "finite complex stiffnesses, N/m")
        if value.ndim < 2:
            value = np.broadcast_to(value, (frequencies,))[:, None, None] * np.eye(3)
        value = np.broadcast_to(value, (frequencies, 3, 3)) if value.ndim == 2 else value
        if value.ndim == 3:
            value = np.broadcast_to(value[:, None], (frequencies, pins, 3, 3))
        blocks = np.zeros((frequencies, 3 * pins, 3 * pins), dtype=complex)
        for p in range(pins):
            blocks[:, 3 * p:3 * p + 3, 3 * p:3 * p + 3] = value[:, p]
        return blocks

    def respond(self, force, point, pylon=None, *, compliance=None) -> list[PylonResponse]:
        """Response to the force phasor *force* (N, shape (3,)) at *point* of
        the engine (m), at every frequency of the set.

        Parameters
        ----------
        force : 3 complex
        point : 3 floats
            The excitation point (one the set was formed for).
        pylon : array-like, optional
            Point dynamic stiffness of the pylon at each pin (force on the
            pylon per pin motion), N/m: a scalar, a scalar per frequency, a
            3x3, a 3x3 per frequency, or a 3x3 per frequency and pin. None:
            a rigid pylon (unless *compliance* is given).
        compliance : array-like, complex, shape (f, 3 p, 3 p), optional
            The pylon given instead by its compliance at the pins, coupled
            between them (pin motion per force on the pylon, m/N; it need
            not be invertible: pins joined rigidly by the pylon): then
            ``(Z_e + K11 - K12 G (I + K22 G)^-1 K21) x1 = B f``, the force
            on the pylon ``-(I + K22 G)^-1 K21 x1`` and ``x2 = G F``.

        Raises
        ------
        workbook.errors.CaseError
            Both *pylon* and *compliance*, or a compliance of the wrong shape.
        workbook.errors.FourPoleError
            A singular matrix at a frequency (on a rigid pylon: one on an undamped mode of :attr:`modes`).
        workbook.errors.RoundOffError
            An answer the linearisation's round-off could swamp (:attr:`roundoff`).
        """
        source = self._input(point) @ np.asarray(force, dtype=complex)
        if compliance is not None:
            if pylon is not None:
                raise CaseError("pylon", "compliance", "a stiffness and a compliance", "one of them")
            return self._respond_compliant(source, self._compliance_matrix(compliance))
        pylon_matrix = None if pylon is None else self._pylon_matrix(pylon)
        responses = []
        for j, frequency in enumerate(self.frequencies_hz):
            k11, k12, k21, k22 = self.k11[j], self.k12[j], self.k21[j], self.k22[j]
            if pylon_matrix is None:
                engine = _solve(self.engine_stiffness[j] + k11, source[:, None],
                                "the engine on its mount on a rigid pylon", frequency, self.modes)[:, 0]
                pins = np.zeros(k21.shape[0], dtype=complex)
                loads = -k21 @ engine
            else:
                coupled = _solve(k22 + pylon_matrix[j], k21, "the mount's pylon side on the pylon", frequency)
                engine = _solve(self.engine_stiffness[j] + k11 - k12 @ coupled, source[:, None],
                                "the engine on its mount on the pylon", frequency)[:, 0]
                pins = -coupled @ engine
                loads = pylon_matrix[j] @ pins
            responses.append(self._response(frequency, engine, pins, loads))
        return responses

    def _response(self, frequency_hz: float, engine: np.ndarray, pins: np.ndarray, loads: np.ndarray
                  ) -> PylonResponse:
        """The response of engine motion *engine* (6), pin motions *pins* and pin forces *loads* (3 p each),
        checked against the round-off (:attr:`roundoff`)."""
        response = PylonResponse(float(frequency_hz), engine, pins.reshape(-1, 3), loads.reshape(-1, 3))
        if self.roundoff is not None:
            amplitude = max(float(np.abs(engine).max()), float(np.abs(pins).max(initial=0.0)))
            self.roundoff.check(frequency_hz, amplitude, response.pylon_force, loads)
        return response

    def _compliance_matrix(self, compliance) -> np.ndarray:
        """*compliance* checked: finite, complex, shape (f, 3 p, 3 p)."""
        value = np.asarray(compliance, dtype=complex)
        shape = (len(self.frequencies_hz), 3 * len(self.pins), 3 * len(self.pins))
        if value.shape != shape or not np.all(np.isfinite(value)):
            raise CaseError("pylon compliance", "shape", value.shape,
                            f"finite compliances (m/N) of shape {shape} (frequencies, 3 x pins, 3 x pins)")
        return value

    def _respond_compliant(self, source: np.ndarray, compliance: np.ndarray) -> list[PylonResponse]:
        """:meth:`respond` on a pylon of compliance *compliance* (checked)."""
        responses = []
        identity = np.eye(compliance.shape[1])
        for j, frequency in enumerate(self.frequencies_hz):
            g = compliance[j]
            coupled = _solve(identity + self.k22[j] @ g, self.k21[j], "the mount's pylon side on the pylon",
                             frequency)
            engine = _solve(self.engine_stiffness[j] + self.k11[j] - self.k12[j] @ g @ coupled, source[:, None],
                            "the engine on its mount on the pylon", frequency)[:, 0]
            loads = -coupled @ engine
            responses.append(self._response(frequency, engine, g @ loads, loads))
        return responses

    def transmissibility(self, force, point, pylon=None) -> np.ndarray:
        """Pylon-force transmissibility ``|F_pylon| / |F|`` per direction, shape (f, 3).

        ``|F|`` is the largest magnitude the force ``Re(f exp(i w t))``
        takes, ``sqrt((f^H f + |f^T f|) / 2)``: the amplitude of a rotating
        or a one-direction harmonic force alike.
        """
        phasor = np.asarray(force, dtype=complex)
        magnitude = float(np.sqrt((np.vdot(phasor, phasor).real + abs(phasor @ phasor)) / 2))
        return np.array([np.abs(r.pylon_force) for r in self.respond(force, point, pylon)]) / magnitude

    def rigid_attachment(self, force, point, pylon) -> np.ndarray:
        """Pylon force (N, complex, shape (f, 3)) with the engine bolted
        rigidly to the pins of a pylon of point dynamic stiffness *pylon*
        (see :meth:`respond`) instead of on its mount."""
        source = self._input(point) @ np.asarray(force, dtype=complex)
        pylon_matrix = self._pylon_matrix(pylon)
        kinematics = self.pin_kinematics
        forces = []
        for j, frequency in enumerate(self.frequencies_hz):
            bolted = self.engine_stiffness[j] + kinematics.T @ pylon_matrix[j] @ kinematics
            engine = _solve(bolted, source[:, None], "the engine bolted to the pylon", frequency)[:, 0]
            forces.append((pylon_matrix[j] @ kinematics @ engine).reshape(-1, 3).sum(axis=0))
        return np.array(forces)

    def insertion_loss(self, pylon, point=None) -> np.ndarray:
        """Insertion loss of the mount on a pylon of point dynamic stiffness
        *pylon* (see :meth:`respond`), dB, shape (f, 3).

        Per direction d: ``20 log10(|F_bolted,d| / |F_mount,d|)`` for a unit
        force in d at *point* (default: the centre of gravity), F the force
        on the pylon with the engine bolted rigidly to the pins and on its
        mount. Positive: the mount isolates.
        """
        point = self.engine_center if point is None else point
        loss = np.empty((len(self.frequencies_hz), 3))
        for d in range(3):
            unit = np.eye(3)[d]
            mounted = np.array([r.pylon_force[d] for r in self.respond(unit, point, pylon)])
            bolted = self.rigid_attachment(unit, point, pylon)[:, d]
            if np.any(np.abs(mounted) == 0) or np.any(np.abs(bolted) == 0):
                raise FourPoleError(f"the insertion loss in {DIRECTIONS[d]} is undefined: a unit force in "
                                    f"{DIRECTIONS[d]} puts no force in {DIRECTIONS[d]} on the pylon")
            loss[:, d] = 20 * np.log10(np.abs(bolted) / np.abs(mounted))
        return loss

    def to_pandas(self):
        """Magnitude (N/m) and phase (deg) of K11, K21 and K22 per direction.

        Returns
        -------
        pandas.DataFrame
            Index: frequency (Hz); columns ``|K11 x| N/m``, ``K11 x deg``, ...
        """
        import pandas as pd

        columns = {}
        for quantity in QUANTITIES:
            values = self.direction_values(quantity)
            for d, axis in enumerate(DIRECTIONS):
                columns[f"|{quantity} {axis}| N/m"] = np.abs(values[:, d])
                columns[f"{quantity} {axis} deg"] = np.degrees(np.angle(values[:, d]))
        return pd.DataFrame(columns, index=pd.Index(self.frequencies_hz, name="frequency Hz"))

    table = renamed("table", "to_pandas()", lambda self: self.to_pandas())

    def plot(self):
        """Magnitudes of K11, K21 and K22 per direction against frequency (log-log).

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 8), constrained_layout=True)
        for quantity, style in zip(QUANTITIES, ("-", "--", ":"), strict=True):
            values = np.abs(self.direction_values(quantity))
            for d, _axis in enumerate(DIRECTIONS):
                axes[d].loglog(self.frequencies_hz, values[:, d], style, label=quantity)
        for d, axis in enumerate(DIRECTIONS):
            axes[d].set_ylabel(f"|K| {axis} N/m")
            axes[d].grid(True, which="both", lw=0.3)
        axes[0].legend(title="dynamic stiffness", fontsize="small")
        axes[-1].set_xlabel("frequency Hz")
        fig.suptitle(f"{self.case_name}: four-pole parameters of the mount (pylon pins and engine blocked)")
        return fig


def mount_case(case: Case) -> Case:
    """The case whose scene the four-pole set is formed from: the pylon pins on
    rigid ground (no test-rig transducers: the rig is the pylon's side).

    Raises
    ------
    workbook.errors.CaseError
        A hinge with a nonlinear law (a clearance): the four-pole set is that of a linear mount;
        or a flexible engine: its engine-side points are on the rigid engine.
    """
    if case.engine.casing is not None:
        raise CaseError("engine", "casing", "a flexible casing", "None (a rigid engine) for the four-pole parameters "
                        "and a flexible pylon: their engine-side points are those of a rigid engine")
    for law, hinges in nonlinear_hinges(case).items():      # the first refuses
        raise CaseError(f"hinge {hinges[0].name!r}", *law.refusal(hinges[0]))
    if not case.pylon_hinges:
        raise CaseError("case", "hinges", "no pylon-side hinge", "at least one hinge on the pylon")
    return dataclasses.replace(case, effects=dataclasses.replace(case.effects, rig_sensors=False))


def _engine_first(basis: np.ndarray, engine: np.ndarray) -> np.ndarray:
    """An orthogonal turn R of the independent coordinates after which the
    first six are the engine's node coordinates and the others leave the
    engine still (``basis @ R`` has ``[I 0]`` in the engine's rows)."""
    import scipy.linalg as sla  # here: the command line's parser takes this module's defaults
    rows = basis[engine]
    if not np.allclose(rows @ rows.T, np.eye(len(engine)), atol=1e-9):
        raise FourPoleError("the engine's coordinates are constrained in the linearisation: no four-pole set")
    return np.hstack([rows.T, sla.null_space(rows)])


def condense(model, case: Case, frequencies_hz, *, points=(), modes=()) -> FourPole:
    """The four-pole set of the mount of *case* at *frequencies_hz* from the
    harmonic model of its preloaded scene.

    Parameters
    ----------
    model : HarmonicModel
        Of the scene of ``mount_case(case)`` (:func:`mount_case`), prepared
        with its preload.
    case : Case
    frequencies_hz : sequence of float
        Hz, > 0.
    points : sequence of 3 floats
        Excitation points of the engine (m) whose force inputs the set
        keeps for :meth:`FourPole.respond`; the case's excitation points and
        the centre of gravity are always kept.
    modes : sequence of workbook.solve.modes.Mode
        The modes of that scene (:attr:`FourPole.modes`).

    Raises
    ------
    workbook.errors.CaseError
        No frequency.
    workbook.errors.FourPoleError
        A singular set.
    """
    import scipy.linalg as sla  # here: the command line's parser takes this module's defaults
    frequencies = checked_frequencies(frequencies_hz)
    mount = mount_case(case)
    center = np.asarray(case.engine.center_of_mass, dtype=float)
    lin = model.linearization
    turn = _engine_first(lin.basis, lin.body_coordinates[ENGINE])
    project = lambda matrix: turn.T @ matrix @ turn  # noqa: E731
    mass, stiffness, damping = project(lin.mass), project(lin.stiffness), project(lin.damping)
    structural = np.zeros_like(mass) if lin.structural is None else project(lin.structural)
    gyroscopic = np.zeros_like(mass) if lin.gyroscopic is None else project(lin.gyroscopic)
    e = slice(0, ENGINE_COORDINATES)
    i = slice(ENGINE_COORDINATES, mass.shape[0])

    pins = [(np.asarray(position, dtype=float), carried) for position, carried in mount.pylon_pins()]
    channel = {name: n for n, name in enumerate(model.hinge_names)}
    hinges = {h.name: h for h in mount.hinges}
    rows_k, rows_h, rows_d, direct_k, direct_d = [], [], [], [], []
    damped = mount.effects.hinge_damping
    for _, carried in pins:
        rows_k.append(sum(model.stiffness_output[3 * channel[h]:3 * channel[h] + 3] for h in carried) @ turn)
        rows_h.append(sum(model.structural_output[3 * channel[h]:3 * channel[h] + 3] for h in carried) @ turn)
        rows_d.append(sum(model.damping_output[3 * channel[h]:3 * channel[h] + 3] for h in carried) @ turn)
        laws = [law_of(mount, hinges[h]).matrices(mount, hinges[h]) for h in carried]
        direct_k.append(sum(k + (1j * loss @ k if damped else 0.0) for k, _, loss in laws))
        direct_d.append(sum(d for _, d, _ in laws) if damped else np.zeros((3, 3)))
    output_k, output_h, output_d = np.vstack(rows_k), np.vstack(rows_h), np.vstack(rows_d)
    direct_k, direct_d = sla.block_diag(*direct_k), sla.block_diag(*direct_d)

    count, size = len(frequencies), 3 * len(pins)
    k11 = np.empty((count, ENGINE_COORDINATES, ENGINE_COORDINATES), dtype=complex)
    k12 = np.empty((count, ENGINE_COORDINATES, size), dtype=complex)
    k21 = np.empty((count, size, ENGINE_COORDINATES), dtype=complex)
    k22 = np.empty((count, size, size), dtype=complex)
    own = np.empty_like(k11)
    for j, frequency in enumerate(frequencies):
        omega = 2 * np.pi * frequency
        dynamic = stiffness - omega ** 2 * mass + 1j * (omega * damping + structural)
        own[j] = (-omega ** 2 * mass + 1j * omega * gyroscopic)[e, e]
        outputs = output_k + 1j * (output_h + omega * output_d)
        condensed = _solve(dynamic[i, i], np.hstack([dynamic[i, e], outputs[:, i].T]),
                           "the mount with both terminals blocked", frequency)
        by_engine, by_pins = condensed[:, :ENGINE_COORDINATES], condensed[:, ENGINE_COORDINATES:]
        k11[j] = dynamic[e, e] - own[j] - dynamic[e, i] @ by_engine
        k12[j] = dynamic[e, i] @ by_pins - outputs[:, e].T
        k21[j] = outputs[:, i] @ by_engine - outputs[:, e]
        k22[j] = direct_k + 1j * omega * direct_d - outputs[:, i] @ by_pins

    jacobian = lambda point: (model.engine_point_jacobian(np.asarray(point, dtype=float)) @ turn)[:, e]  # noqa: E731
    kinematics = np.vstack([jacobian(position) for position, _ in pins])
    wanted = [center, *(np.asarray(p, dtype=float) for p in points),
              *(np.asarray(p, dtype=float) for x in case.single_frequency_excitations() for p, _, _ in x.point_forces())]
    inputs = {}
    for point in wanted:
        key = tuple(np.round(point, 12))
        if key not in inputs:
            inputs[key] = jacobian(point).T
    return FourPole(case.name, frequencies, [" + ".join(carried) for _, carried in pins],
                    np.array([position for position, _ in pins]), k11, k12, k21, k22, own, kinematics, center,
                    inputs, tuple(modes), model.roundoff)
