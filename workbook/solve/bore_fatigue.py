"""A conservative fatigue factor at the bores, from the bore sub-model and the links' axial forces.

The reduced link ties its bores rigidly to their master nodes, so its own
stresses there are not the bore's (:mod:`flexbodies.bore_stress`). A link
hinged at both eyes is a two-force member: its bore peak is its axial force
``N`` times the sub-model's peak von Mises stress per newton under a pin's
bearing load, ``k_t`` in tension and ``k_c`` in compression (the larger eye's,
on the finer of the two meshes, :func:`flexbodies.bore_stress.convergence_sizes`).
From the preload's axial force ``N_0`` and the amplitude ``|N^|`` of the
harmonic axial force of each excitation
(:attr:`~workbook.solve.fatigue.LinkFatigue.axial_force`,
:attr:`~workbook.solve.fatigue.LinkFatigue.axial_amplitude`):

- ``sigma_m = k(sign N_0) |N_0|``, counted as a tensile mean whatever the
  sign of ``N_0``;
- ``sigma_a = max(k_t, k_c) |N^|``;
- the Goodman factor ``1 / (sigma_a / S_e + sigma_m / S_u)``.

It is conservative: the mean and the alternating peak are put at one point
although they may sit at different points of the bore (and of the two
eyes), a compressive preload earns no credit, and the alternating part takes
the larger of the tension and compression peaks. It leaves out what is not
axial (the link's own inertia and any bending a hinge passes), a few per
mille of the reference links' forces. Links without a parametric geometry
(from mesh files) are not refined and have no row.
"""
from __future__ import annotations

from dataclasses import dataclass

from flexbodies.stress import goodman_factor

__all__ = ["BoreFatigue", "bore_fatigue"]


@dataclass(frozen=True)
class BoreFatigue:
    """The bore fatigue of one link under one excitation.

    Attributes
    ----------
    excitation : str
    frequency_hz : float
    link : str
    axial_force, axial_amplitude : float
        Preload axial force ``N_0`` (tension positive) and harmonic amplitude ``|N^|``, N.
    mean, alternating : float
        The bore's ``sigma_m`` and ``sigma_a`` as the module gives them, Pa.
    goodman : float
        Their Goodman factor (inf: nothing loads the bore).
    reduced_goodman : float
        The reduced link's own lowest Goodman factor (:class:`~workbook.solve.fatigue.LinkFatigue`), beside it.
    """

    excitation: str
    frequency_hz: float
    link: str
    axial_force: float
    axial_amplitude: float
    mean: float
    alternating: float
    goodman: float
    reduced_goodman: float


def bore_fatigue(case, fatigue) -> list[BoreFatigue]:
    """The bore fatigue of every flexible link with a parametric geometry and each excitation of *fatigue*.

    Parameters
    ----------
    case : workbook.model.case.Case
    fatigue : workbook.solve.fatigue.FatigueResult
        Of *case*.

    Returns
    -------
    list of BoreFatigue
        By excitation, then link.
    """
    from flexbodies.bore_stress import bore_peaks, convergence_sizes

    per_newton: dict = {}
    rows = []
    for answer in fatigue.excitations:
        for name, link in answer.links.items():
            model = case.link_map[name].model
            if model.geometry is None or link.axial_force is None:
                continue
            if name not in per_newton:
                peaks = bore_peaks(model, convergence_sizes(model)[1])
                per_newton[name] = (max(peaks.tension), max(peaks.compression))
            tension, compression = per_newton[name]
            mean = (tension if link.axial_force >= 0 else compression) * abs(link.axial_force)
            alternating = max(tension, compression) * link.axial_amplitude
            material = model.material
            rows.append(BoreFatigue(answer.excitation, answer.frequency_hz, name, link.axial_force,
                                    link.axial_amplitude, mean, alternating,
                                    float(goodman_factor(alternating, mean, material.endurance_strength,
                                                         material.ultimate_strength)), link.goodman))
    return rows
