"""Dynamic link stresses and fatigue safety factors of the rotor excitations.

About the preloaded equilibrium a harmonic excitation moves each flexible
link's modal coordinates by ``Re(q_hat exp(i w t))``
(:attr:`~workbook.answers.results.ExcitationResult.link_phasors`), so its
stress is ``sigma(t) = sigma_m + Re(S q_hat exp(i w t))``: the mean
``sigma_m = S q_0`` of the static preload (the case's static loads: 1 g and
whatever else it holds, e.g. the cruise thrust) plus a complex amplitude
field ``S q_hat``, both one matrix product with the link's stress shapes
(:mod:`flexbodies.stress`). At every node of the link:

- the alternating equivalent stress ``sigma_a`` is the largest von Mises
  stress of the alternating part over the cycle
  (:func:`flexbodies.stress.alternating_von_mises`): exact for proportional
  stress, and for non-proportional stress (components out of phase, as a
  rotating imbalance gives) half the major axis of the elliptic stress path,
  so a rotating stress of constant von Mises value counts in full;
- the mean equivalent stress ``sigma_m`` is the von Mises stress of the mean,
  signed by its hydrostatic part (:func:`flexbodies.stress.signed_von_mises`);
- the fatigue safety factors by the modified Goodman line and the Gerber
  parabola (:func:`flexbodies.stress.goodman_factor`,
  :func:`flexbodies.stress.gerber_factor`), against the material's endurance
  and ultimate strength, and, when the material has a Haigh curve
  (:attr:`flexbodies.materials.Material.haigh_curve`), the Haigh factor on
  the proportional load line (:func:`flexbodies.stress.haigh_factor`); a
  compressive mean earns no credit.

Per link and excitation the lowest Goodman factor over the nodes is reported
with its node and its stresses, the lowest Gerber and Haigh factors over the
nodes (at that node or another: each criterion's own worst node), and the
peak alternating stress; and the link's axial force, of the preload and the
amplitude of its phasor (the hinge forces and force phasors at its eyes on
the link axis, :func:`~workbook.solve.preload.link_compression`), from which
:mod:`workbook.solve.bore_fatigue` gives the fatigue at the bores. Every single-frequency excitation is answered alone: each point of a
sweep (a speed of a run-up) and each part of a simultaneous excitation, by
the harmonic model of :mod:`workbook.solve.harmonic` (for a case with hinge
clearance, linearised about the preload).

A speed spectrum of a rotor (:class:`~workbook.model.spectrum.SpeedSpectrum`:
hours at each speed) gives each link's Miner damage sum ``D = sum n_i / N_i``
over its speeds, each speed one harmonic solve of the rotor's excitation:

- at every node the Goodman-equivalent fully reversed stress
  ``sigma_ar = sigma_a / (1 - sigma_m / S_u)`` (``sigma_a`` for a
  compressive mean; infinite, a static failure, for ``sigma_m >= S_u``);
- the cycles ``n_i = f_i x 3600 x hours_i`` (one per revolution, f in Hz);
- the cycles to failure of the material's S-N curve,
  ``N = N_e (sigma_ar / S_e)^(1/b)`` (Basquin through the knee
  ``(N_e, S_e)``); a stress at or below the endurance strength does no
  damage (``N`` infinite: Miner's rule with an endurance limit);
- ``D`` the largest node sum over the link, the life ``spectrum hours / D``
  (infinite for ``D = 0``).

Several rotors' damages add per flight hour: the link's life under all its
spectra is ``1 / sum(D_r / hours_r)`` (the rotors' stresses are counted
apart, as if they did not superpose). The case's gyroscopic rotors keep
their speed.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np

from flexbodies.stress import (
    REGIONS,
    alternating_von_mises,
    gerber_factor,
    goodman_factor,
    haigh_factor,
    link_regions,
    signed_von_mises,
    state_stress,
)
from workbook.errors import CaseError
from workbook.model.case import Case, Simultaneous, Sweep
from workbook.model.spectrum import SECONDS_PER_HOUR, SpeedSpectrum, check_speed_spectra
from workbook.solve.load_cases import link_coordinates
from workbook.solve.preload import link_compression

__all__ = ["LinkFatigue", "ExcitationFatigue", "LinkDamage", "SpectrumDamage", "FatigueResult", "link_fatigue",
           "equivalent_alternating", "cycles_to_failure", "miner_damage", "solve_fatigue"]


@dataclass(frozen=True)
class LinkFatigue:
    """The fatigue of one link under one harmonic excitation on its preload.

    Attributes
    ----------
    link : str
    peak_alternating : float
        Largest alternating equivalent stress over the link's nodes, Pa.
    alternating, mean : float
        Alternating and signed mean equivalent stress at the node of the
        lowest Goodman factor, Pa.
    goodman : float
        The lowest Goodman factor over the nodes.
    gerber : float
        The lowest Gerber factor over the nodes (at that node or another).
    region : str
        Where that node is: ``"eye A"``, ``"shank"`` or ``"eye B"``.
    point : tuple of 3 floats
        That node, global coordinates of the undeformed link, m.
    haigh : float or None
        The lowest Haigh factor over the nodes (at that node or another),
        None when the link's material has no Haigh curve.
    axial_force : float or None
        The preload's axial force N_0 of the link, tension positive, N (from
        the hinge forces at its eyes).
    axial_amplitude : float or None
        The amplitude ``|N^|`` of the link's harmonic axial force, N (from the
        hinge force phasors at its eyes, projected on the link axis).
    """

    link: str
    peak_alternating: float
    alternating: float
    mean: float
    goodman: float
    gerber: float
    region: str
    point: tuple
    haigh: float | None = None
    axial_force: float | None = None
    axial_amplitude: float | None = None


@dataclass(frozen=True)
class ExcitationFatigue:
    """The fatigue of every flexible link under one excitation.

    Attributes
    ----------
    excitation : str
    frequency_hz : float
    links : dict of str to LinkFatigue
    amplitudes : dict of str to ndarray, complex, shape (n, 6)
        Complex stress amplitude ``S q_hat`` of each link at its FE nodes,
        link frame, Voigt order, Pa.
    """

    excitation: str
    frequency_hz: float
    links: dict
    amplitudes: dict = field(repr=False)


@dataclass(frozen=True)
class LinkDamage:
    """The Miner damage sum of one link over one speed spectrum.

    Attributes
    ----------
    link : str
    damage : float
        The largest Miner sum ``D`` over the link's nodes, dimensionless.
    life_hours : float
        Spectrum hours over ``D``, h (inf: no damage).
    equivalent : float
        The largest Goodman-equivalent alternating stress over the nodes and
        speeds, Pa.
    speed_hz : float
        The speed of that stress, Hz.
    region : str
        Where the node of the largest damage is (of the largest equivalent
        stress when nothing is damaged).
    point : tuple of 3 floats
        That node, global coordinates of the undeformed link, m.
    """

    link: str
    damage: float
    life_hours: float
    equivalent: float
    speed_hz: float
    region: str
    point: tuple


@dataclass(frozen=True)
class SpectrumDamage:
    """The damage of every flexible link over one rotor's speed spectrum.

    Attributes
    ----------
    spectrum : SpeedSpectrum
    speeds : tuple of (float, float, float)
        ``(speed Hz, hours, cycles)`` of each speed solved.
    links : dict of str to LinkDamage
    """

    spectrum: SpeedSpectrum
    speeds: tuple
    links: dict


@dataclass(frozen=True)
class FatigueResult:
    """What :func:`solve_fatigue` gives.

    Attributes
    ----------
    case : str
    excitations : list of ExcitationFatigue
    mean_stress : dict of str to ndarray, shape (n, 6)
        Static (preload) stress of each flexible link of the run that
        prepared the first excitation, Pa.
    stress_seconds : float
        Wall time of the stress recovery and the factors, all links and
        excitations, s.
    reduced : dict of str to flexbodies.ReducedBody
        The flexible links of that run (their meshes and stress shapes).
    spectra : list of SpectrumDamage
        The Miner sums of the case's speed spectra.
    """

    case: str
    excitations: list
    mean_stress: dict = field(repr=False)
    stress_seconds: float
    reduced: dict = field(repr=False)
    spectra: list = field(default_factory=list)

    def life_hours(self) -> dict:
        """Each link's life under all the spectra, ``1 / sum(D_r / hours_r)``, h (inf: no damage)."""
        rate: dict = {}
        for answer in self.spectra:
            for name, damage in answer.links.items():
                rate[name] = rate.get(name, 0.0) + damage.damage / answer.spectrum.hours
        with np.errstate(divide="ignore"):
            return {name: float(np.divide(1.0, value)) for name, value in rate.items()}

    def plot(self, link: str):
        """The stress fields of *link* on its shape: the preload's von Mises
        stress, then each excitation's alternating von Mises stress, MPa, at
        the FE nodes seen along the bore axes (link frame: x along the link),
        the peak starred.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        from flexbodies.stress import alternating_von_mises, von_mises

        reduced = self.reduced[link]
        fields = {"preload von Mises": von_mises(self.mean_stress[link])}
        for answer in self.excitations:
            fields[f"{answer.excitation} ({answer.frequency_hz:g} Hz) alternating von Mises"] = \
                alternating_von_mises(answer.amplitudes[link])
        nodes = 1e3 * reduced.nodes[: len(next(iter(fields.values())))]
        fig, axes = plt.subplots(len(fields), 1, figsize=(9, 2.4 * len(fields)), squeeze=False,
                                 constrained_layout=True)
        for ax, (title, values) in zip(axes[:, 0], fields.items(), strict=True):
            order = np.argsort(values)       # the highest stresses drawn last, on top
            drawn = ax.scatter(nodes[order, 0], nodes[order, 1], c=values[order] / 1e6, s=4, cmap="viridis")
            peak = int(np.argmax(values))
            ax.plot(nodes[peak, 0], nodes[peak, 1], marker="*", color="red", markersize=12)
            ax.set_title(f"{title}: peak {values[peak] / 1e6:.3g} MPa", fontsize="small")
            ax.set_aspect("equal")
            ax.set_ylabel("y mm")
            fig.colorbar(drawn, ax=ax, label="MPa")
        axes[-1, 0].set_xlabel("x mm (along the link)")
        fig.suptitle(f"{self.case}: link {link}")
        return fig

    def to_dict(self) -> dict:
        """JSON-ready, SI units but hours (without the stress fields)."""
        return {"case": self.case, "stress_seconds": self.stress_seconds,
                "excitations": [{"excitation": e.excitation, "frequency_hz": e.frequency_hz,
                                 "links": {name: dataclasses.asdict(f) for name, f in e.links.items()}}
                                for e in self.excitations],
                "spectra": [{"excitation": d.spectrum.excitation, "hours": d.spectrum.hours,
                             "speeds": [{"speed_hz": f, "hours": h, "cycles": n} for f, h, n in d.speeds],
                             "links": {name: dataclasses.asdict(x) for name, x in d.links.items()}}
                            for d in self.spectra],
                "life_hours": self.life_hours()}


def _strengths(case: Case) -> None:
    for link in case.links:
        material = link.model.material if link.model is not None else None
        if material is None:
            continue
        for what in ("endurance_strength", "ultimate_strength"):
            if getattr(material, what) is None:
                raise CaseError(f"link {link.name!r}", f"material.{what}", None,
                                f"the {what.replace('_', ' ')} of material {material.name!r} in Pa: "
                                "the fatigue factors need it")


def link_fatigue(link, reduced, mean_coordinates, amplitude: np.ndarray, rotation) -> LinkFatigue:
    """One link's fatigue from its mean modal coordinates and its stress amplitude.

    Parameters
    ----------
    link : workbook.model.case.Link
        Its material has endurance and ultimate strengths.
    reduced : flexbodies.ReducedBody
    mean_coordinates : array_like, shape (n_modes,)
        The preloaded state's modal coordinates.
    amplitude : ndarray, complex, shape (n, 6)
        Complex stress amplitude at the FE nodes, Pa.
    rotation : ndarray, shape (3, 3)
        Link frame to global.

    Returns
    -------
    LinkFatigue
    """
    material = link.model.material
    alternating = alternating_von_mises(amplitude)
    mean = signed_von_mises(state_stress(reduced, mean_coordinates))
    goodman = goodman_factor(alternating, mean, material.endurance_strength, material.ultimate_strength)
    gerber = gerber_factor(alternating, mean, material.endurance_strength, material.ultimate_strength)
    haigh = None if material.haigh_curve is None else float(haigh_factor(alternating, mean, material.haigh_curve).min())
    i = int(np.argmin(goodman))
    regions = link_regions(reduced)
    point = np.asarray(link.end_a) + rotation @ reduced.nodes[i]
    return LinkFatigue(link.name, float(alternating.max()), float(alternating[i]), float(mean[i]),
                       float(goodman[i]), float(gerber.min()), REGIONS[regions[i]], tuple(float(x) for x in point),
                       haigh)


def equivalent_alternating(alternating, mean, ultimate: float) -> np.ndarray:
    """Goodman-equivalent fully reversed stress ``sigma_a / (1 - sigma_m / S_u)``.

    A compressive mean is taken as zero (``sigma_a``, as :func:`flexbodies.stress.goodman_factor`
    does); a mean at or beyond the ultimate strength gives inf (a static failure).

    Parameters
    ----------
    alternating, mean : array_like
        Equivalent alternating and signed mean stress, Pa.
    ultimate : float
        Ultimate strength S_u, Pa.

    Returns
    -------
    ndarray, Pa
    """
    remaining = 1.0 - np.maximum(np.asarray(mean, float), 0.0) / ultimate
    alternating = np.asarray(alternating, float)
    with np.errstate(divide="ignore"):
        return np.where(remaining > 0.0, alternating / np.where(remaining > 0.0, remaining, 1.0), np.inf)


def cycles_to_failure(equivalent, material) -> np.ndarray:
    """Cycles to failure ``N_e (sigma_ar / S_e)^(1/b)`` of the material's S-N curve; inf at or below ``S_e``.

    Parameters
    ----------
    equivalent : array_like
        Fully reversed stress amplitude, Pa.
    material : flexbodies.Material
        With endurance strength, endurance cycles and fatigue exponent.
    """
    ratio = np.asarray(equivalent, float) / material.endurance_strength
    above = ratio > 1.0
    with np.errstate(over="ignore", divide="ignore"):
        return np.where(above, material.endurance_cycles * np.where(above, ratio, 2.0) ** (1.0 / material.fatigue_exponent),
                        np.inf)


def miner_damage(equivalents, cycles, material) -> np.ndarray:
    """Miner's sum ``sum_i n_i / N_i`` at each node.

    Parameters
    ----------
    equivalents : sequence of array_like, shape (n,)
        Goodman-equivalent stress at the nodes at each speed, Pa.
    cycles : sequence of float
        The cycles n_i at each speed.
    material : flexbodies.Material

    Returns
    -------
    ndarray, shape (n,)
    """
    total = np.zeros(np.shape(equivalents[0]))
    with np.errstate(divide="ignore"):    # N = 0 (a static failure): infinite damage
        for equivalent, n in zip(equivalents, cycles, strict=True):
            total += n / cycles_to_failure(equivalent, material)
    return total


def _solved(case: Case, points: tuple, reduced: dict | None):
    """Yield ``(point, scene, means, tension, result)`` per single-frequency *points*, on one prepared scene
    (*tension*: each link's preload axial force, N)."""
    from workbook.solve.pipeline import prepare

    highest = max(points, key=lambda point: point.frequency)
    prepared = prepare(case, points[0], reduce_for=highest, reduced=reduced)
    scene, model = prepared.scene, prepared.model
    assert model is not None
    with scene:
        means = link_coordinates(scene)
        tension = {name: -float(value) for name, value in link_compression(scene, prepared.preload.hinge_forces).items()}
        for point in points:
            yield point, scene, means, tension, model.result(point, case.analysis.steady_tolerance)


def _spectrum_damage(case: Case, spectrum: SpeedSpectrum, reduced: dict | None) -> SpectrumDamage:
    """The Miner sums of every flexible link over *spectrum* (see the module)."""
    speeds = spectrum.points()
    cycles = [f * SECONDS_PER_HOUR * hours for f, hours in speeds]
    points = tuple(spectrum.at(case.excitations, f) for f, _ in speeds)
    equivalents: dict = {}
    found: dict = {}
    for _, scene, means, _, result in _solved(case, points, reduced):
        for name in (name for name in case.link_map if name in means):
            link, body = case.link_map[name], scene.reduced[name]
            if name not in found:
                found[name] = (signed_von_mises(state_stress(body, means[name])), link_regions(body),
                               scene.links[name].rotation, body)
            alternating = alternating_von_mises(state_stress(body, result.link_phasors[name]))
            equivalents.setdefault(name, []).append(
                equivalent_alternating(alternating, found[name][0], link.model.material.ultimate_strength))
    links = {}
    for name, stresses in equivalents.items():
        link = case.link_map[name]
        _, regions, rotation, body = found[name]
        damage = miner_damage(stresses, cycles, link.model.material)
        peaks = np.array([s.max() for s in stresses])
        k = int(np.argmax(peaks))
        i = int(np.argmax(damage)) if damage.max() > 0 else int(np.argmax(stresses[k]))
        total = float(damage.max())
        point = np.asarray(link.end_a) + rotation @ body.nodes[i]
        with np.errstate(divide="ignore"):
            life = float(np.divide(spectrum.hours, total))
        links[name] = LinkDamage(name, total, life, float(peaks[k]), speeds[k][0], REGIONS[regions[i]],
                                 tuple(float(x) for x in point))
    return SpectrumDamage(spectrum, tuple((f, h, n) for (f, h), n in zip(speeds, cycles, strict=True)), links)


def solve_fatigue(case: Case, *, reduced: dict | None = None) -> FatigueResult:
    """Dynamic stresses, fatigue factors and Miner sums of *case* (see the module).

    Parameters
    ----------
    case : Case
        On a rigid pylon.
    reduced : dict of str to flexbodies.ReducedBody, optional
        The case's reduced links (reduced, or loaded, for the highest
        frequency of each excitation when omitted).

    Returns
    -------
    FatigueResult

    Raises
    ------
    CaseError
        A flexible link's material without an endurance or ultimate
        strength (or, with speed spectra, an S-N parameter), a spectrum the
        case cannot answer (:func:`~workbook.model.spectrum.check_speed_spectra`),
        or a flexible pylon.
    workbook.errors.SimulationError
        A mechanism, a failed preload or an excitation on an undamped mode.
    """
    _strengths(case)
    check_speed_spectra(case)
    if case.flexible_pylon:
        raise CaseError(f"case {case.name!r}", "pylon", "a flexible pylon",
                        "a rigid pylon: the link stresses are recovered on the mount's own scene")
    answers: list = []
    mean_stress: dict = {}
    first: dict = {}
    seconds = 0.0
    for item in case.excitations:
        points = item.expand() if isinstance(item, (Sweep, Simultaneous)) else (item,)
        for point, scene, means, tension, result in _solved(case, points, reduced):
            start = time.perf_counter()
            amplitudes, links = {}, {}
            axial = link_compression(scene, result.hinge_phasors)
            for name in (name for name in case.link_map if name in means):
                body = scene.reduced[name]
                amplitudes[name] = state_stress(body, result.link_phasors[name])
                found = link_fatigue(case.link_map[name], body, means[name], amplitudes[name], scene.links[name].rotation)
                links[name] = dataclasses.replace(found, axial_force=tension[name], axial_amplitude=float(abs(axial[name])))
            seconds += time.perf_counter() - start
            answers.append(ExcitationFatigue(point.name, point.frequency, links, amplitudes))
            if not mean_stress:
                mean_stress = {name: state_stress(scene.reduced[name], q) for name, q in means.items()}
                first = {name: scene.reduced[name] for name in means}
    spectra = [_spectrum_damage(case, spectrum, reduced) for spectrum in case.speed_spectra]
    return FatigueResult(case.name, answers, mean_stress, seconds, first, spectra)
