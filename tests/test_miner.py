"""Miner damage sums over a speed spectrum (workbook.solve.fatigue, workbook.model.spectrum):
the S-N curve and the sum by hand, the presets' S-N lines, bad spectra, and the reference mount's
sums against the node stresses of its own harmonic answers."""
import dataclasses
import json
import math

import numpy as np
import pytest

from flexbodies.materials import STEEL, TITANIUM, Material
from flexbodies.stress import alternating_von_mises, signed_von_mises
from workbook.cli.main import main
from workbook.errors import EXIT_BAD_INPUT, CaseError
from workbook.model.codec import from_json, to_json
from workbook.model.spectrum import SpeedBand, SpeedSpectrum, check_speed_spectra
from workbook.scene.build import reduce_links
from workbook.solve.fatigue import cycles_to_failure, equivalent_alternating, miner_damage, solve_fatigue

#: S_e = 500 MPa at N_e = 1e7 cycles, b = -0.1, S_u = 900 MPa.
SN = Material("test", 200e9, 0.3, 7800.0, 800e6, 900e6, 500e6, endurance_cycles=1e7, fatigue_exponent=-0.1)


def test_miner_sum_against_a_hand_calculation():
    # node 1: sigma_a 400, sigma_m 300 MPa: sigma_ar = 400 / (1 - 300/900) = 600 MPa,
    #   N = 1e7 (600/500)^(1/-0.1) = 1e7 / 1.2^10 = 1.6150559e6
    # node 2: sigma_a 300, sigma_m 300: 450 MPa, below S_e: no damage
    # node 3: sigma_a 520, sigma_m -300 (compressive, no credit): 520 MPa, N = 1e7 / 1.04^10 = 6.7556417e6
    alternating, mean = np.array([400e6, 300e6, 520e6]), np.array([300e6, 300e6, -300e6])
    equivalent = equivalent_alternating(alternating, mean, SN.ultimate_strength)
    np.testing.assert_allclose(equivalent, [600e6, 450e6, 520e6], rtol=1e-12)
    np.testing.assert_allclose(cycles_to_failure(equivalent, SN), [1.6150559e6, np.inf, 6.7556417e6], rtol=1e-7)
    # 2 h at 50 Hz: 360000 cycles; then 1 h at 100 Hz with the same stresses: 360000 more
    damage = miner_damage([equivalent, equivalent], [360e3, 360e3], SN)
    np.testing.assert_allclose(damage, [0.44580502, 0.0, 0.10657759], rtol=1e-7)
    # a mean at the ultimate strength is a static failure: infinite damage
    assert equivalent_alternating(1e6, 900e6, 900e6) == np.inf
    assert miner_damage([np.array([np.inf])], [1.0], SN)[0] == np.inf


def test_the_presets_s_n_lines_run_from_0_9_su_at_1e3_cycles_to_the_endurance_knee():
    assert STEEL.fatigue_exponent == pytest.approx(-math.log10(1.8) / 3, rel=1e-12)
    for material in (STEEL, TITANIUM):
        stress = 0.9 * material.ultimate_strength
        assert cycles_to_failure(stress, material) == pytest.approx(1e3, rel=1e-9)
        assert cycles_to_failure(material.endurance_strength, material) == np.inf


def test_a_band_is_solved_at_the_midpoints_of_five_sub_bands():
    points = SpeedBand(10.0, 50.0, 60.0).points()
    assert [f for f, _ in points] == pytest.approx([51.0, 53.0, 55.0, 57.0, 59.0])
    assert [h for _, h in points] == pytest.approx([2.0] * 5)


def test_bad_spectra_are_refused_naming_the_band(coarse_reference):
    with pytest.raises(CaseError, match="field 'hours'"):
        SpeedBand(-1.0, 50.0)
    with pytest.raises(CaseError, match="field 'to_hz'"):
        SpeedBand(1.0, 50.0, 40.0)
    unknown = dataclasses.replace(coarse_reference, speed_spectra=(SpeedSpectrum("no such rotor", (SpeedBand(1.0, 50.0),)),))
    with pytest.raises(CaseError, match="speed spectrum 'no such rotor', field 'excitation'"):
        check_speed_spectra(unknown)
    link = coarse_reference.links[0]
    bare = dataclasses.replace(link, model=dataclasses.replace(link.model, material=dataclasses.replace(
        link.model.material, fatigue_exponent=None)))
    case = dataclasses.replace(coarse_reference, links=(bare, *coarse_reference.links[1:]),
                               speed_spectra=(SpeedSpectrum("LP rotor", (SpeedBand(1.0, 50.0),)),))
    with pytest.raises(CaseError, match=f"link '{link.name}', field 'material.fatigue_exponent'"):
        check_speed_spectra(case)
    assert from_json(to_json(case)).speed_spectra == case.speed_spectra


def test_the_stress_command_names_a_missing_fatigue_exponent_when_a_spectrum_is_given(coarse_reference, tmp_path,
                                                                                      capsys):
    path = tmp_path / "case.json"
    spectrum = SpeedSpectrum("LP rotor", (SpeedBand(10.0, 50.0),))
    data = json.loads(to_json(dataclasses.replace(coarse_reference, speed_spectra=(spectrum,))))
    data["links"][0]["model"]["material"]["fatigue_exponent"] = None
    path.write_text(json.dumps(data))
    assert main(["stress", str(path)]) == EXIT_BAD_INPUT
    message = capsys.readouterr().err
    assert "material.fatigue_exponent" in message and "Miner" in message
    path.write_text(to_json(coarse_reference))               # without a spectrum no S-N curve is needed
    assert from_json(path.read_text()).speed_spectra == ()


@pytest.mark.slow
def test_the_reference_mounts_miner_sums_follow_its_harmonic_stresses(coarse_reference):
    """Endurance strengths lowered to 0.02 MPa so the mount's small imbalance stresses do damage: the sums of a
    two-speed spectrum against the node stresses of the harmonic answers at those speeds, summed by hand."""
    lp = coarse_reference.excitations[0]
    lowered = tuple(dataclasses.replace(link, model=dataclasses.replace(link.model, material=dataclasses.replace(
        link.model.material, endurance_strength=0.02e6))) for link in coarse_reference.links)
    speeds = (50.0, 70.0)
    spectrum = SpeedSpectrum(lp.name, (SpeedBand(100.0, speeds[0]), SpeedBand(40.0, speeds[1])))
    probes = tuple(dataclasses.replace(lp, name=f"probe {f:g}", frequency_hz=f) for f in speeds)
    case = dataclasses.replace(coarse_reference, links=lowered, excitations=(lp, *probes), speed_spectra=(spectrum,))
    result = solve_fatigue(case, reduced=reduce_links(case, probes[-1]))    # one reduction for every answer
    (answer,) = result.spectra
    assert [n for _, _, n in answer.speeds] == pytest.approx([50.0 * 3600 * 100, 70.0 * 3600 * 40])
    damaged = 0
    for name, found in answer.links.items():
        material = case.link_map[name].model.material
        mean = signed_von_mises(result.mean_stress[name])
        total = np.zeros(len(mean))
        for probe, (_, _, cycles) in zip(result.excitations[1:], answer.speeds, strict=True):
            sigma_a = alternating_von_mises(probe.amplitudes[name])
            sigma_ar = sigma_a / (1 - np.maximum(mean, 0) / material.ultimate_strength)
            n_f = np.where(sigma_ar > material.endurance_strength, material.endurance_cycles
                           * (sigma_ar / material.endurance_strength) ** (1 / material.fatigue_exponent), np.inf)
            total += cycles / n_f
        assert found.damage == pytest.approx(total.max(), rel=1e-9), name
        assert found.life_hours == (pytest.approx(140.0 / total.max(), rel=1e-9) if total.max() > 0 else np.inf)
        damaged += found.damage > 0
    assert damaged >= 2
    assert result.life_hours() == {name: pytest.approx(d.life_hours) for name, d in answer.links.items()}
