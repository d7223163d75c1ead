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
  and ultimate strength; a compressive mean earns no credit.

Per link and excitation the lowest Goodman factor over the nodes is reported
with its node, its stresses and its Gerber factor, and the peak alternating
stress. Every single-frequency excitation is answered alone: each point of a
sweep (a speed of a run-up) and each part of a simultaneous excitation, by
the harmonic model of :mod:`workbook.solve.harmonic` (for a case with hinge
clearance, linearised about the preload). A Miner damage sum over a speed
spectrum is not computed.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from flexbodies.stress import REGIONS, alternating_von_mises, gerber_factor, goodman_factor, link_regions, signed_von_mises, state_stress
from workbook.errors import CaseError
from workbook.model.case import Case, Simultaneous, Sweep
from workbook.solve.load_cases import link_coordinates

__all__ = ["LinkFatigue", "ExcitationFatigue", "FatigueResult", "link_fatigue", "solve_fatigue"]


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
    """

    link: str
    peak_alternating: float
    alternating: float
    mean: float
    goodman: float
    gerber: float
    region: str
    point: tuple


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
    reduced : dict of str to flexbodies.ReducedLink
        The flexible links of that run (their meshes and stress shapes).
    """

    case: str
    excitations: list
    mean_stress: dict = field(repr=False)
    stress_seconds: float
    reduced: dict = field(repr=False)

    def to_dict(self) -> dict:
        """JSON-ready, SI units (without the stress fields)."""
        import dataclasses

        return {"case": self.case, "stress_seconds": self.stress_seconds,
                "excitations": [{"excitation": e.excitation, "frequency_hz": e.frequency_hz,
                                 "links": {name: dataclasses.asdict(f) for name, f in e.links.items()}}
                                for e in self.excitations]}


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
    reduced : flexbodies.ReducedLink
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
    i = int(np.argmin(goodman))
    regions = link_regions(reduced)
    point = np.asarray(link.end_a) + rotation @ reduced.nodes[i]
    return LinkFatigue(link.name, float(alternating.max()), float(alternating[i]), float(mean[i]),
                       float(goodman[i]), float(gerber.min()), REGIONS[regions[i]], tuple(float(x) for x in point))


def solve_fatigue(case: Case, *, reduced: dict | None = None) -> FatigueResult:
    """Dynamic stresses and fatigue factors of every single-frequency excitation of *case* (see the module).

    Parameters
    ----------
    case : Case
        On a rigid pylon.
    reduced : dict of str to flexbodies.ReducedLink, optional
        The case's reduced links (reduced, or loaded, for the highest
        frequency of each excitation when omitted).

    Returns
    -------
    FatigueResult

    Raises
    ------
    CaseError
        A flexible link's material without an endurance or ultimate
        strength, or a flexible pylon.
    workbook.errors.SimulationError
        A mechanism, a failed preload or an excitation on an undamped mode.
    """
    from workbook.solve.pipeline import prepare

    _strengths(case)
    if case.flexible_pylon:
        raise CaseError(f"case {case.name!r}", "pylon", "a flexible pylon",
                        "a rigid pylon: the link stresses are recovered on the mount's own scene")
    answers: list = []
    mean_stress: dict = {}
    first: dict = {}
    seconds = 0.0
    for item in case.excitations:
        points = item.expand() if isinstance(item, (Sweep, Simultaneous)) else (item,)
        highest = max(points, key=lambda point: point.frequency)
        prepared = prepare(case, points[0], reduce_for=highest, reduced=reduced)
        scene, model = prepared.scene, prepared.model
        assert model is not None
        with scene:
            means = link_coordinates(scene)
            flexible = [link for link in case.links if link.name in means]
            for point in points:
                result = model.result(point, case.analysis.steady_tolerance)
                start = time.perf_counter()
                amplitudes, links = {}, {}
                for link in flexible:
                    body = scene.reduced[link.name]
                    amplitudes[link.name] = state_stress(body, result.link_phasors[link.name])
                    links[link.name] = link_fatigue(link, body, means[link.name], amplitudes[link.name],
                                                    scene.links[link.name].rotation)
                seconds += time.perf_counter() - start
                answers.append(ExcitationFatigue(point.name, point.frequency, links, amplitudes))
            if not mean_stress:
                mean_stress = {name: state_stress(scene.reduced[name], q) for name, q in means.items()}
                first = {name: scene.reduced[name] for name in means}
    return FatigueResult(case.name, answers, mean_stress, seconds, first)

