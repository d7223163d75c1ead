"""What each link of a case became: FE size, frequencies, modes kept and why, cost.

This is the table ``mountwb links`` prints. A cached link reports the
reduction time stored when it was computed, and says it was a cache hit.
"""
from __future__ import annotations

import pandas as pd

from workbook.model.case import Case

__all__ = ["link_table"]

#: Stages whose times make up a reduction, as stored in ``ReducedBody.info``.
_STAGES = ("mesh_seconds", "assembly_seconds", "frequency_seconds", "reduction_seconds", "stiffening_seconds")


def link_table(case: Case, reduced: dict) -> pd.DataFrame:
    """One row per link of ``case``.

    Parameters
    ----------
    case : Case
    reduced : dict of str to flexbodies.ReducedBody
        From :func:`workbook.scene.build.reduce_links`.

    Returns
    -------
    pandas.DataFrame
        Indexed by link name: FE DOF, first free-free and as-mounted
        frequencies (Hz), the ratio of the highest excitation to the mounted
        fundamental (the one the mode decision was judged on), then one
        ``f_exc/f1 <excitation> (<f> Hz)`` column per excitation of the case
        when it has more than one, fixed-interface modes kept, DOF in the
        scene, reduction time (s), cache hit, and the reason for the modes kept.
    """
    excitations = {e.name: e.frequency for e in case.excitations} if len(case.excitations) > 1 else {}
    rows = []
    for link in case.links:
        item = reduced[link.name]
        flexible = case.link_is_flexible(link.name)
        ratio = item.decision.ratio
        rows.append({
            "link": link.name,
            "FE DOF": item.info["fe_dof"],
            "f1 free-free [Hz]": float(item.frequencies["free_free_hz"][0]),
            "f1 mounted [Hz]": float(item.frequencies["mounted_hz"][0]),
            "f_exc/f1": ratio if ratio is not None else float("nan"),
            **{f"f_exc/f1 {name} ({f:g} Hz)": f / float(item.frequencies["mounted_hz"][0])
               for name, f in excitations.items()},
            "fixed-interface modes": item.n_fixed_interface if flexible else 0,
            "DOF in scene": item.dof if flexible else 6,
            "reduction [s]": sum(item.info.get(stage, 0.0) for stage in _STAGES),
            "cache": "hit" if item.cache_hit else "computed",
            "why": item.decision.reason if flexible else "rigid link (mass properties only)",
        })
    return pd.DataFrame(rows).set_index("link")
