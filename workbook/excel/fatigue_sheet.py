"""The table of link fatigue written to a case workbook (``Result fatigue``) and a report (``Fatigue``).

One row per single-frequency excitation and flexible link
(:class:`~workbook.solve.fatigue.ExcitationFatigue`): the peak alternating
stress, the alternating and mean stress at the node of the lowest Goodman
factor, the Goodman and Gerber factors and where, and the Haigh factor of a
material with a Haigh curve (the lowest of each over the nodes; the column
only when a link's material has one). With speed spectra, one
row per spectrum and link (:class:`~workbook.solve.fatigue.SpectrumDamage`):
its hours, the largest Goodman-equivalent stress and its speed, the Miner
sum D and the life; with several spectra, a row per link of its life under
all of them. Stresses in MPa, points in m, lives in hours; an empty cell is
a value that does not apply to the row; "infinite" a Goodman factor with nothing
alternating or a life without damage.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["NOTE", "QUANTITIES", "fatigue_frame"]

#: The sheet's note (row 1).
NOTE = ("Link fatigue on the preload of the case as its sheets give it (the Runs sheet's overrides do not apply): "
        "Goodman 1/n = sigma_a/S_e + sigma_m/S_u, Gerber n sigma_a/S_e + (n sigma_m/S_u)^2 = 1, Haigh "
        "(n sigma_m, n sigma_a) on the material's Haigh curve where it has one; speed spectra: "
        "Miner D = sum n/N, sigma_ar = sigma_a/(1 - sigma_m/S_u), N = N_e (sigma_ar/S_e)^(1/b), no damage at or "
        "below S_e, life = hours / D")
_STRESSES = ("peak sigma_a MPa", "sigma_a MPa", "sigma_m MPa", "peak sigma_ar MPa")
_COLUMNS = ("kind", "excitation", "frequency Hz", "link", *_STRESSES[:3], "Goodman", "Gerber", "Haigh", "at",
            *(f"at {axis} m" for axis in "xyz"), "hours", _STRESSES[3], "Miner D", "life h")
#: FORMATS key of the columns whose header does not tell it (:func:`~workbook.excel.styling.quantity_of`).
QUANTITIES = {**dict.fromkeys(_STRESSES, "number"), "Goodman": "margin", "Gerber": "margin", "Haigh": "margin",
              "Miner D": "number", "life h": "number", "hours": "number", **{f"at {axis} m": "m" for axis in "xyz"}}


def fatigue_frame(result) -> pd.DataFrame:
    """The table of *result* (a :class:`~workbook.solve.fatigue.FatigueResult`)."""
    import pandas as pd

    rows = []
    for answer in result.excitations:
        for name, f in answer.links.items():
            rows.append(["harmonic", answer.excitation, answer.frequency_hz, name, f.peak_alternating / 1e6,
                         f.alternating / 1e6, f.mean / 1e6, f.goodman, f.gerber, f.haigh, f.region, *f.point,
                         None, None, None, None])
    for answer in result.spectra:
        for name, d in answer.links.items():
            rows.append(["spectrum", answer.spectrum.excitation, d.speed_hz, name, *[None] * 6, d.region, *d.point,
                         answer.spectrum.hours, d.equivalent / 1e6, d.damage, d.life_hours])
    if len(result.spectra) > 1:
        for name, life in result.life_hours().items():
            rows.append(["all spectra", None, None, name, *[None] * 10, None, None, None, life])
    frame = pd.DataFrame(rows, columns=list(_COLUMNS))
    if frame["Haigh"].isna().all():      # no link's material has a Haigh curve
        frame = frame.drop(columns="Haigh")
    return frame.replace(float("inf"), "infinite")
