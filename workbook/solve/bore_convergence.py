"""The bore peaks of the limit load cases on two refined meshes, and their convergence.

Each flexible link with a parametric geometry carries its load case's axial
force through its eyes; its bore peak is that force times the peak von Mises
stress per newton of a pin's bearing load (:mod:`flexbodies.bore_stress`), on
two meshes refined at the bores (:data:`flexbodies.bore_stress.BORE_DIVISIONS`
elements around the bore). The relative change between them is the
convergence shown: above :data:`CONVERGENCE_TOLERANCE` the peak is reported
as not converged. The reduced link's own peak (its bores tied to their master
nodes) is given beside it, and the margins of safety of the finer mesh's bore
peak against the link material's yield (limit load) and ultimate strength
(ultimate load, the load case's factor of safety) as
:mod:`workbook.solve.load_cases` gives them for the reduced link's peak.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

__all__ = ["CONVERGENCE_TOLERANCE", "BoreConvergence", "BoreStudy", "bore_convergence"]

#: The largest relative change of the bore peak between the two meshes that counts as converged.
CONVERGENCE_TOLERANCE = 0.05


@dataclass(frozen=True)
class BoreConvergence:
    """One link's bore peak under one load case on the two refined meshes.

    Attributes
    ----------
    load_case, link : str
    axial_force : float
        Tension (negative: compression), N.
    reduced_peak : float or None
        The reduced link's peak von Mises stress (its bores tied to the
        master nodes), Pa.
    bore_element_sizes : tuple of 2 floats
        Element edge at the bores of the two meshes, m.
    peaks : tuple of 2 floats
        Peak von Mises stress at the bores under the pin bearing load on
        each mesh, Pa.
    change : float
        ``peaks[1] / peaks[0] - 1`` (0 without a load).
    converged : bool
        ``|change| <= CONVERGENCE_TOLERANCE``.
    yield_margin, ultimate_margin : float or None
        Margins of safety of the finer mesh's peak, ``S_y / sigma - 1`` and
        ``S_u / (FS sigma) - 1`` (None without a load or a strength).
    """

    load_case: str
    link: str
    axial_force: float
    reduced_peak: float | None
    bore_element_sizes: tuple
    peaks: tuple
    change: float
    converged: bool
    yield_margin: float | None = None
    ultimate_margin: float | None = None


@dataclass(frozen=True)
class BoreStudy:
    """What :func:`bore_convergence` gives.

    Attributes
    ----------
    rows : list of BoreConvergence
    meshes : dict of str to tuple of 2 ints
        FE nodes of the two refined meshes of each distinct link model, by
        the names of the links that share it (joined by ", ").
    seconds : dict of str to tuple of 2 floats
        Time of meshing, assembling and solving those two meshes when they
        were computed (kept in the link cache with the peaks), s.
    skipped : tuple of str
        Links without a parametric geometry (a mesh file is not refined).
    """

    rows: list
    meshes: dict
    seconds: dict
    skipped: tuple

    def to_dict(self) -> dict:
        """JSON-ready, SI units."""
        return {"tolerance": CONVERGENCE_TOLERANCE, "rows": [dataclasses.asdict(row) for row in self.rows],
                "meshes": self.meshes, "seconds": self.seconds, "skipped": list(self.skipped)}


def bore_convergence(case, results) -> BoreStudy:
    """The bore peak of every flexible link of *case* in each load case result, on two refined meshes.

    Parameters
    ----------
    case : workbook.model.case.Case
    results : sequence of workbook.solve.load_cases.LoadCaseResult

    Returns
    -------
    BoreStudy
    """
    from flexbodies.bore_stress import bore_peaks, convergence_sizes
    from workbook.solve.load_cases import margin

    if not results:         # nothing to converge: no sub-model is meshed
        return BoreStudy([], {}, {}, ())
    peaks: dict = {}
    materials: dict = {}
    sharing: dict = {}
    skipped = []
    for link in case.links:
        if link.model is None or not link.flexible:
            continue
        if link.model.geometry is None:
            skipped.append(link.name)
            continue
        peaks[link.name] = [bore_peaks(link.model, size) for size in convergence_sizes(link.model)]
        materials[link.name] = link.model.material
        sharing.setdefault(link.model.key(), []).append(link.name)
    rows = []
    for result in results:
        for name, stress in result.links.items():
            if name not in peaks:
                continue
            coarse, fine = (p.peak(stress.axial_force) for p in peaks[name])
            change = fine / coarse - 1.0 if coarse > 0 else 0.0
            material = materials[name]
            rows.append(BoreConvergence(result.load_case.name, name, stress.axial_force, stress.von_mises,
                                        tuple(p.bore_element_size for p in peaks[name]), (coarse, fine), change,
                                        abs(change) <= CONVERGENCE_TOLERANCE, margin(material.yield_strength, fine),
                                        margin(material.ultimate_strength,
                                               result.load_case.factor_of_safety * fine)))
    distinct = {", ".join(names): peaks[names[0]] for names in sharing.values()}
    return BoreStudy(rows, {names: tuple(p.nodes for p in found) for names, found in distinct.items()},
                     {names: tuple(p.seconds for p in found) for names, found in distinct.items()}, tuple(skipped))
