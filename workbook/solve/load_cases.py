"""Limit load cases: one static solve each, hinge and link forces, engine displacement and link stresses.

Each :class:`~workbook.model.load_cases.LoadCase` replaces the case's static
loads and is solved as the preload is (:func:`workbook.solve.preload.solve_preload`:
mechanism check, Newton, stability and equilibrium checks, then the
stress stiffening of :mod:`workbook.solve.stress_stiffening`), without
excitation. A fail-safe load case removes its link first. Each flexible
link's stress field is its stress shapes times its modal coordinates
(:mod:`flexbodies.stress`), reported per link: axial force, nominal shank
stress, the peak von Mises and largest principal stress with where they are,
and the margins of safety

- against yield at limit load: ``MS_y = F_ty / sigma_vM - 1``;
- against ultimate strength at ultimate load: ``MS_u = F_tu / (FS sigma_vM) - 1``

(the stress is linear in the load, so the ultimate stress is the limit
stress times the factor of safety FS). A rigid link has no stress field:
its axial force and nominal stress only.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from flexbodies.stress import REGIONS, link_regions, max_principal, state_stress, von_mises
from workbook.model.case import Case
from workbook.model.load_cases import LoadCase
from workbook.scene.build import build_scene, reduce_links
from workbook.solve.preload import link_compression, solve_preload
from workbook.solve.stress_stiffening import stiffen_links

__all__ = ["LinkStress", "LoadCaseResult", "load_case_scene_case", "link_stress", "link_coordinates", "margin",
           "solve_load_case", "solve_load_cases"]


@dataclass(frozen=True)
class LinkStress:
    """The strength of one link under one load case.

    Attributes
    ----------
    link : str
    axial_force : float
        Tension (negative: compression), N, from the hinge forces.
    shank_area : float or None
        Shank cross-section, m^2 (None: a link from a mesh file).
    nominal_stress : float or None
        ``axial_force / shank_area``, Pa.
    von_mises, max_principal : float or None
        Peak von Mises and largest principal stress over the link's nodes,
        Pa (None: a rigid link).
    von_mises_region, max_principal_region : str or None
        ``"eye A"``, ``"shank"`` or ``"eye B"``.
    von_mises_point, max_principal_point : tuple of 3 floats or None
        Where, global coordinates of the undeformed node, m.
    yield_margin, ultimate_margin : float or None
        Margins of safety (module docstring); None when the stress or the
        material's strength is not known.
    """

    link: str
    axial_force: float
    shank_area: float | None
    nominal_stress: float | None
    von_mises: float | None = None
    von_mises_region: str | None = None
    von_mises_point: tuple | None = None
    max_principal: float | None = None
    max_principal_region: str | None = None
    max_principal_point: tuple | None = None
    yield_margin: float | None = None
    ultimate_margin: float | None = None


@dataclass(frozen=True)
class LoadCaseResult:
    """What one load case gives.

    Attributes
    ----------
    load_case : LoadCase
    hinge_forces : dict of str to ndarray, shape (3,)
        Force of each hinge on its first body (the pylon for pylon-side hinges), N.
    pylon_force, applied_force : ndarray, shape (3,)
        Sum of the pylon-side hinge forces and of the applied loads, N.
    engine_displacement : ndarray, shape (3,)
        Static displacement of the engine's centre of gravity, m.
    engine_rotation : ndarray, shape (3,)
        Its rotation (Rxyz angles), rad.
    links : dict of str to LinkStress
    stress_seconds : float
        Wall time of the stress recovery of all links, s.
    """

    load_case: LoadCase
    hinge_forces: dict
    pylon_force: np.ndarray
    applied_force: np.ndarray
    engine_displacement: np.ndarray
    engine_rotation: np.ndarray
    links: dict
    stress_seconds: float

    def to_dict(self) -> dict:
        """JSON-ready: SI units."""
        return {
            "load_case": self.load_case.name, "factor_of_safety": self.load_case.factor_of_safety,
            "without_link": self.load_case.without_link,
            "hinge_forces_N": {k: v.tolist() for k, v in self.hinge_forces.items()},
            "pylon_force_N": self.pylon_force.tolist(), "applied_force_N": self.applied_force.tolist(),
            "engine_displacement_m": self.engine_displacement.tolist(),
            "engine_rotation_rad": self.engine_rotation.tolist(),
            "links": {name: dataclasses.asdict(stress) for name, stress in self.links.items()},
            "stress_seconds": self.stress_seconds,
        }


def load_case_scene_case(case: Case, load_case: LoadCase) -> Case:
    """The case a load case is solved on: its static loads, no excitation, the preload on, the fail-safe link removed."""
    load_case.check(case.link_map)
    base = case.without_link(load_case.without_link) if load_case.without_link else case
    return dataclasses.replace(base, name=f"{case.name} / {load_case.name}", static_loads=load_case.static_loads(case.engine),
                               excitations=(), load_cases=(),
                               effects=dataclasses.replace(base.effects, preload=True))


def margin(strength, stress) -> float | None:
    """The margin of safety ``strength / stress - 1`` (None without a strength or a positive stress)."""
    if strength is None or stress is None or stress <= 0:
        return None
    return float(strength / stress - 1.0)


def link_stress(link, reduced, modal_coordinates, axial_force: float, rotation, factor_of_safety: float) -> LinkStress:
    """One link's stresses and margins from its modal coordinates.

    Parameters
    ----------
    link : workbook.model.case.Link
    reduced : flexbodies.ReducedBody
    modal_coordinates : array_like or None
        The link's elastic coordinates (None: a rigid link).
    axial_force : float
        Tension, N.
    rotation : ndarray, shape (3, 3)
        Link frame to global.
    factor_of_safety : float
        Ultimate over limit load.

    Returns
    -------
    LinkStress
    """
    geometry = getattr(link.model, "geometry", None)
    area = geometry.shank_width * geometry.shank_thickness if geometry is not None else None
    found = LinkStress(link.name, float(axial_force), area, float(axial_force / area) if area else None)
    if modal_coordinates is None or reduced.stress_modes.size == 0:
        return found
    stress = state_stress(reduced, modal_coordinates)
    regions = link_regions(reduced)
    nodes = reduced.nodes[: len(regions)]

    def where(index):
        point = np.asarray(link.end_a) + rotation @ nodes[index]
        return REGIONS[regions[index]], tuple(float(x) for x in point)

    vm, principal = von_mises(stress), max_principal(stress)
    i, j = int(np.argmax(vm)), int(np.argmax(principal))
    material = link.model.material
    return dataclasses.replace(
        found, von_mises=float(vm[i]), von_mises_region=where(i)[0], von_mises_point=where(i)[1],
        max_principal=float(principal[j]), max_principal_region=where(j)[0], max_principal_point=where(j)[1],
        yield_margin=margin(material.yield_strength, float(vm[i])),
        ultimate_margin=margin(material.ultimate_strength, factor_of_safety * float(vm[i])))


def link_coordinates(scene) -> dict:
    """The modal coordinates of every flexible link of *scene* in its current state.

    Returns
    -------
    dict of str to ndarray, shape (n_modes,)
    """
    import exudyn as exu

    return {name: np.array(scene.mbs.GetNodeOutput(items.nodes[1], exu.OutputVariableType.Coordinates))
            for name, items in scene.links.items() if items.flexible}


def solve_load_case(case: Case, load_case: LoadCase, *, reduced: dict | None = None) -> LoadCaseResult:
    """Solve one limit load case of *case* (see the module).

    Parameters
    ----------
    case : Case
    load_case : LoadCase
    reduced : dict of str to flexbodies.ReducedBody, optional
        The case's reduced links (reduced, or loaded, when omitted).

    Raises
    ------
    CaseError
        The fail-safe link is not a link of the case.
    workbook.errors.SimulationError
        A mechanism (a fail-safe case without enough links), a failed or
        unstable static solve.
    """
    import exudyn as exu

    solved = load_case_scene_case(case, load_case)
    if reduced is None:
        reduced = reduce_links(dataclasses.replace(case, load_cases=()))
    reduced = {name: reduced[name] for name in solved.link_map}
    scene = build_scene(solved, None, reduced=reduced)
    try:
        preload = solve_preload(scene)
        scene, preload = stiffen_links(solved, None, scene, preload)
        with scene:
            forces = preload.hinge_forces
            tension = {name: -value for name, value in link_compression(scene, forces).items()}
            coordinates = np.array(scene.mbs.GetNodeOutput(scene.engine.node, exu.OutputVariableType.Coordinates))
            start = time.perf_counter()
            links = {}
            modal = link_coordinates(scene)
            for link in solved.links:
                links[link.name] = link_stress(link, scene.reduced[link.name], modal.get(link.name),
                                               tension[link.name], scene.links[link.name].rotation,
                                               load_case.factor_of_safety)
            seconds = time.perf_counter() - start
    except BaseException:
        scene.close()
        raise
    return LoadCaseResult(load_case, forces, preload.pylon_force, preload.applied_force, coordinates[:3],
                          coordinates[3:6], links, seconds)


def solve_load_cases(case: Case, load_cases=None) -> list[LoadCaseResult]:
    """Solve every load case of *case* (or those given), the links reduced once.

    Parameters
    ----------
    case : Case
    load_cases : sequence of LoadCase, optional
        Default ``case.load_cases``.

    Returns
    -------
    list of LoadCaseResult
    """
    chosen = tuple(case.load_cases if load_cases is None else load_cases)
    for load_case in chosen:
        load_case.check(case.link_map)
    reduced = reduce_links(dataclasses.replace(case, load_cases=())) if chosen else {}
    return [solve_load_case(case, load_case, reduced=reduced) for load_case in chosen]

