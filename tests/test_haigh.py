"""The Haigh factor of a material's Haigh curve (flexbodies.stress.haigh_factor, Material.haigh_curve):
the Goodman line, a refined Gerber parabola and a hand-computed polyline; the curve's checks and its
JSON round trip; the factor in the fatigue of the reference mount."""
import dataclasses

import numpy as np
import pytest

from flexbodies.errors import LinkModelError
from flexbodies.materials import STEEL
from flexbodies.stress import gerber_factor, goodman_factor, haigh_factor
from workbook.model.codec import from_json, to_json

SE, SU = 235e6, 470e6


def _stresses(count=400, seed=26):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.0, 200e6, count), rng.uniform(-300e6, 450e6, count)


def test_a_curve_on_the_goodman_line_gives_the_goodman_factor():
    alternating, mean = _stresses()
    haigh = haigh_factor(alternating, mean, ((0.0, SE), (SU, 0.0)))
    np.testing.assert_allclose(haigh, goodman_factor(alternating, mean, SE, SU), rtol=1e-12)
    # the same line cut into unequal pieces
    cut = [(m, SE * (1 - m / SU)) for m in (0.0, 0.1 * SU, 0.15 * SU, 0.6 * SU, 0.99 * SU)] + [(SU, 0.0)]
    np.testing.assert_allclose(haigh_factor(alternating, mean, cut), goodman_factor(alternating, mean, SE, SU),
                               rtol=1e-12)


def test_a_sampled_gerber_parabola_converges_to_the_gerber_factor():
    alternating, mean = _stresses()
    gerber = gerber_factor(alternating, mean, SE, SU)
    errors = []
    for segments in (4, 8, 16, 32, 64, 128):
        m = np.linspace(0.0, SU, segments + 1)
        curve = np.column_stack([m, SE * (1 - (m / SU) ** 2)])
        haigh = haigh_factor(alternating, mean, curve)
        assert np.all(haigh <= gerber * (1 + 1e-12))       # the chords lie inside the concave parabola
        errors.append(np.max(1 - haigh / gerber))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3.5) & (ratios < 4.5)), ratios   # second order in the chord length
    assert errors[-1] < 2e-5


def test_a_polyline_against_a_hand_calculation():
    curve = ((0.0, 500e6), (300e6, 400e6), (900e6, 0.0))
    # sigma_a 100, sigma_m 200 MPa: the ray meets the second segment a = 600 - 2 m / 3 at
    # 100 n = 600 - 400 n / 3, n = 18 / 7 (the point (514, 257) MPa lies beyond m = 300)
    # sigma_a 200, sigma_m 50 MPa: the first segment a = 500 - m / 3, 200 n = 500 - 50 n / 3, n = 30 / 13
    # a compressive mean: no credit, 500 / 100; only a mean: 900 / 300; nothing at all: inf
    expected = [18 / 7, 30 / 13, 5.0, 3.0, np.inf]
    found = haigh_factor([100e6, 200e6, 100e6, 0.0, 0.0], [200e6, 50e6, -200e6, 300e6, 0.0], curve)
    np.testing.assert_allclose(found, expected, rtol=1e-14)
    # the corner point itself
    assert haigh_factor(40e6, 30e6, curve) == pytest.approx(10.0, rel=1e-14)


BAD_CURVES = {
    "one point": (((0.0, SE),), "at least two points"),
    "not pairs": (((0.0, SE, 1.0), (SU, 0.0)), "(mean, alternating) stress pairs"),
    "text": (((0.0, "high"), (SU, 0.0)), "(mean, alternating) stress pairs"),
    "not finite": (((0.0, SE), (np.nan, 1e6), (SU, 0.0)), "point 2 (nan, 1000000.0) is not finite"),
    "off the alternating axis": (((1e6, SE), (SU, 0.0)), "must start on the alternating axis"),
    "off the mean axis": (((0.0, SE), (SU, 1e6)), "must end on the mean axis"),
    "means back": (((0.0, SE), (300e6, 100e6), (200e6, 50e6), (SU, 0.0)), "the means must increase strictly, point 3"),
    "alternating up": (((0.0, SE), (100e6, 240e6), (SU, 0.0)), "the alternating stresses must not increase, point 2"),
    "on the mean axis early": (((0.0, SE), (300e6, 0.0), (SU, 0.0)), "only its last point lies on the mean axis"),
}


@pytest.mark.parametrize("name", BAD_CURVES)
def test_a_bad_haigh_curve_is_refused_with_what_is_wrong(name):
    curve, message = BAD_CURVES[name]
    with pytest.raises(LinkModelError, match=f"material 'steel': the Haigh curve.*{message}".replace("(", r"\(")
                       .replace(")", r"\)")):
        dataclasses.replace(STEEL, haigh_curve=curve)


def test_the_curve_round_trips_through_json_and_does_not_touch_the_reduction():
    material = dataclasses.replace(STEEL, haigh_curve=[[0, SE], [200e6, 180e6], [SU, 0]])
    assert material.haigh_curve == ((0.0, SE), (200e6, 180e6), (SU, 0.0))
    assert from_json(to_json(material)) == material
    assert hash(material) == hash(from_json(to_json(material)))
    assert material.elastic_inputs() == STEEL.elastic_inputs()
    text = to_json(material).replace("200000000.0, 180000000.0", "200000000.0, 300000000.0")
    with pytest.raises(LinkModelError, match="alternating stresses must not increase, point 2"):
        from_json(text)


@pytest.mark.slow
def test_the_fatigue_of_a_link_with_a_curve_reports_its_haigh_factor(coarse_reference, capsys):
    """A link whose curve is its Goodman line reports its Goodman factor as its Haigh factor; the
    text, the JSON and the fatigue table show it, '-' or empty for the links without a curve."""
    from workbook.cli.stress import print_fatigue_factors
    from workbook.excel.fatigue_sheet import fatigue_frame
    from workbook.solve.fatigue import solve_fatigue

    def with_curve(link):
        material = link.model.material
        curve = ((0.0, material.endurance_strength), (material.ultimate_strength, 0.0))
        return dataclasses.replace(link, model=dataclasses.replace(
            link.model, material=dataclasses.replace(material, haigh_curve=curve)))

    named = coarse_reference.links[2].name
    case = dataclasses.replace(coarse_reference, links=tuple(with_curve(x) if x.name == named else x
                                                             for x in coarse_reference.links))
    fatigue = solve_fatigue(case)
    for answer in fatigue.to_dict()["excitations"]:
        for name, link in answer["links"].items():
            if name == named:
                assert link["haigh"] == pytest.approx(link["goodman"], rel=1e-12)
            else:
                assert link["haigh"] is None
    print_fatigue_factors(fatigue)
    lines = capsys.readouterr().out.splitlines()
    header = next(line.split() for line in lines if "Goodman" in line and "peak" in line)
    assert header[-3:] == ["Gerber", "Haigh", "at"]
    rows = [line.split() for line in lines if line.split()[:1] in ([x.name] for x in case.links)]
    assert len(rows) == len(case.links) * len(fatigue.excitations)
    assert all(row[6] == row[4] for row in rows if row[0] == named)      # Haigh printed as Goodman
    assert all(row[6] == "-" for row in rows if row[0] != named)
    harmonic = fatigue_frame(fatigue).query("kind == 'harmonic'")
    chosen = harmonic["link"] == named
    np.testing.assert_allclose(harmonic.loc[chosen, "Haigh"].astype(float),
                               harmonic.loc[chosen, "Goodman"].astype(float), rtol=1e-12)
    assert harmonic.loc[~chosen, "Haigh"].isna().all()
    # without a curve: no Haigh column, in the text nor in the table
    bare = dataclasses.replace(fatigue, excitations=[dataclasses.replace(
        answer, links={name: dataclasses.replace(f, haigh=None) for name, f in answer.links.items()})
        for answer in fatigue.excitations])
    assert "Haigh" not in fatigue_frame(bare).columns
    print_fatigue_factors(bare)
    assert "Haigh" not in capsys.readouterr().out
