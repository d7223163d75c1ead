"""The conservative bore fatigue factor (workbook.solve.bore_fatigue) against a hand calculation from the
bore sub-model's peaks per newton and the links' axial forces."""
from types import SimpleNamespace

import numpy as np
import pytest

from flexbodies import LinkGeometry, LinkModel
from flexbodies.bore_stress import bore_peaks, convergence_sizes
from flexbodies.materials import STEEL
from workbook.model.case import Link
from workbook.solve.fatigue import ExcitationFatigue, FatigueResult, LinkFatigue


def test_bore_fatigue_against_a_hand_calculation(cache_dir, monkeypatch, capsys):
    import flexbodies.bore_stress as bore_stress
    from workbook.cli.stress import print_bore_fatigue
    from workbook.solve.bore_fatigue import bore_fatigue

    monkeypatch.setattr(bore_stress, "BORE_DIVISIONS", (8, 10))   # a coarse pair: the test's time
    geometry = LinkGeometry(length=0.20, eye_outer_radius=0.020, bore_radius=0.010, thickness=0.012,
                            shank_width=0.025, shank_thickness=0.012)
    model = LinkModel(geometry=geometry, material=STEEL, element_size=0.008)
    case = SimpleNamespace(link_map={"bar": Link("bar", (0.0, 0.0, 0.0), (0.20, 0.0, 0.0), model),
                                     "twin": Link("twin", (0.0, 1.0, 0.0), (0.20, 1.0, 0.0), model)})

    def reduced(name, goodman, axial_force, axial_amplitude):
        return LinkFatigue(name, 1e6, 1e6, 1e7, goodman, goodman, "shank", (0.0, 0.0, 0.0),
                           axial_force=axial_force, axial_amplitude=axial_amplitude)

    links = {"bar": reduced("bar", 20.0, 2e4, 300.0), "twin": reduced("twin", 30.0, -2e4, 300.0)}
    fatigue = FatigueResult("bars", [ExcitationFatigue("LP rotor", 50.0, links, {})], {}, 0.0, {})
    rows = bore_fatigue(case, fatigue)
    assert [(row.excitation, row.link) for row in rows] == [("LP rotor", "bar"), ("LP rotor", "twin")]
    fine = bore_peaks(model, convergence_sizes(model)[1], cache_dir=cache_dir)
    k_t, k_c = max(fine.tension), max(fine.compression)
    assert k_c < k_t                                          # the bearing side's peak is the lower
    se, su = STEEL.endurance_strength, STEEL.ultimate_strength
    for row, k_mean in zip(rows, (k_t, k_c), strict=True):
        # sigma_m from the preload's direction, counted tensile; sigma_a from the larger peak per newton
        assert (row.mean, row.alternating) == pytest.approx((k_mean * 2e4, k_t * 300.0), rel=1e-12)
        assert row.goodman == pytest.approx(1 / (k_t * 300.0 / se + k_mean * 2e4 / su), rel=1e-12)
        assert row.reduced_goodman == links[row.link].goodman
    assert rows[1].goodman > rows[0].goodman                   # the compressive preload loads the bore less
    print_bore_fatigue(rows)                                   # the table of mountwb stress
    printed = [line.split() for line in capsys.readouterr().out.splitlines() if line.split()[2:3] in (["bar"], ["twin"])]
    assert [(words[2], float(words[3]), float(words[-2]), float(words[-1])) for words in printed] == [
        (row.link, round(row.axial_force / 1e3, 2), float(f"{row.goodman:.3g}"), row.reduced_goodman) for row in rows]
    # nothing axial: nothing loads the bore
    links["bar"] = reduced("bar", 20.0, 0.0, 0.0)
    assert np.isinf(bore_fatigue(case, fatigue)[0].goodman)
