"""Dynamic link stresses and fatigue factors (workbook.solve.fatigue, flexbodies.stress):
the multiaxial criterion, Goodman and Gerber by hand, the quasi-static limit, the reference mount."""
import dataclasses
import json

import numpy as np
import pytest

from flexbodies.materials import STEEL
from flexbodies.stress import alternating_von_mises, gerber_factor, goodman_factor, state_stress, von_mises
from workbook.cli.main import main
from workbook.errors import EXIT_BAD_INPUT, CaseError
from workbook.model.case import PointForce
from workbook.model.codec import to_json
from workbook.model.load_cases import LoadCase
from workbook.scene.build import build_scene, reduce_links
from workbook.solve.fatigue import solve_fatigue
from workbook.solve.load_cases import link_coordinates
from workbook.solve.pipeline import prepare
from workbook.solve.preload import link_compression, solve_preload


def test_alternating_stress_is_the_largest_von_mises_over_the_cycle():
    rng = np.random.default_rng(26)
    amplitude = rng.normal(size=(50, 6)) + 1j * rng.normal(size=(50, 6))
    phases = np.linspace(0.0, 2 * np.pi, 20001)
    sampled = np.max([von_mises((amplitude * np.exp(1j * phi)).real) for phi in phases], axis=0)
    np.testing.assert_allclose(alternating_von_mises(amplitude), sampled, rtol=1e-7)
    # proportional stress (every component in phase): the von Mises stress of the amplitude
    real = rng.normal(size=(50, 6))
    np.testing.assert_allclose(alternating_von_mises(real * np.exp(0.7j)), von_mises(real), rtol=1e-12)
    # a stress rotating in the xy plane (pure shear at 45 degrees, a quarter period later) counts in full
    rotating = np.array([[1.0, -1.0, 0, 0, 0, 1j]])
    np.testing.assert_allclose(alternating_von_mises(rotating), [np.sqrt(3.0)], rtol=1e-12)


def test_fatigue_factors_against_a_hand_calculation():
    # sigma_a = 100 MPa, sigma_m = 200 MPa, S_e = 500 MPa, S_u = 900 MPa
    # Goodman: 1 / n = 100/500 + 200/900 = 0.42222..., n = 2.368421
    assert goodman_factor(100e6, 200e6, 500e6, 900e6) == pytest.approx(2.368421, rel=1e-6)
    # Gerber: (200/900)^2 n^2 + (100/500) n - 1 = 0, n = (-0.2 + sqrt(0.04 + 4 * 0.0493827)) / (2 * 0.0493827)
    assert gerber_factor(100e6, 200e6, 500e6, 900e6) == pytest.approx(2.909635, rel=1e-6)
    # a compressive mean earns no credit; nothing alternating: the static ultimate factor
    assert goodman_factor(100e6, -200e6, 500e6, 900e6) == gerber_factor(100e6, -200e6, 500e6, 900e6) == 5.0
    assert goodman_factor(0.0, 300e6, 500e6, 900e6) == gerber_factor(0.0, 300e6, 500e6, 900e6) == 3.0


@pytest.mark.slow
def test_harmonic_stress_at_a_low_frequency_equals_the_static_stress(coarse_reference):
    """The quasi-static limit: a force phasor F at 1e-4 Hz against static solves at +-F (central
    difference: the geometric nonlinearity's even part cancels), without other static loads: the
    link stresses and the links' axial forces from the hinge forces."""
    case = dataclasses.replace(coarse_reference, static_loads=(),
                               effects=dataclasses.replace(coarse_reference.effects, stress_stiffening="off"))
    excitation = case.excitations[0]
    reduced = reduce_links(case, excitation)
    # a probe of 100 N: the odd (third-order) part of the geometric nonlinearity, which the central
    # difference keeps, is then far below 1e-6 (5e-7 at 1000 N, 2e-8 at 100 N)
    point, force = np.array([0.5, 0.1, 0.2]), np.array([30.0, -50.0, 100.0])
    prepared = prepare(case, excitation, reduced=reduced)
    with prepared.scene as scene:
        model = prepared.model
        motion = model.motion(1e-4, model.input_matrix(point) @ force.astype(complex))
        phasors = model.link_phasors(motion)
        harmonic = {name: state_stress(scene.reduced[name], q) for name, q in phasors.items()}
        axial = link_compression(scene, model.respond_generalised(1e-4, model.input_matrix(point)
                                                                   @ force.astype(complex)).hinge_forces)
    static, compression = [], []
    for sign in (1.0, -1.0):
        loaded = dataclasses.replace(case, excitations=(),
                                     static_loads=(PointForce("probe", tuple(sign * force), tuple(point)),))
        with build_scene(loaded, None, reduced=reduced) as scene:
            compression.append(link_compression(scene, solve_preload(scene).hinge_forces))
            static.append({name: state_stress(scene.reduced[name], q) for name, q in link_coordinates(scene).items()})
    # the axial force phasor of the bore fatigue (hinge force phasors on the link axis) likewise
    largest = max(abs(value) for value in compression[0].values())
    for name, value in axial.items():
        assert abs(value - (compression[0][name] - compression[1][name]) / 2) < 1e-6 * largest, name
    assert len(phasors) == len(case.links)
    peak = max(np.abs(stress).max() for stress in static[0].values())
    for name, stress in harmonic.items():
        difference = (static[0][name] - static[1][name]) / 2
        assert np.abs(stress.real - difference).max() < 1e-6 * peak, name
        assert np.abs(stress.imag).max() < 1e-6 * peak, name


@pytest.fixture(scope="module")
def fatigue(coarse_reference):
    return solve_fatigue(coarse_reference)


@pytest.mark.slow
def test_reference_fatigue_factors_follow_from_the_reported_stresses(coarse_reference, fatigue):
    assert [e.excitation for e in fatigue.excitations] == ["LP rotor", "HP rotor"]
    for answer in fatigue.excitations:
        assert set(answer.links) == {link.name for link in coarse_reference.links}
        for name, link in answer.links.items():
            material = coarse_reference.link_map[name].model.material
            se, su = material.endurance_strength, material.ultimate_strength
            assert link.goodman == pytest.approx(1 / (link.alternating / se + max(link.mean, 0.0) / su), rel=1e-12)
            assert link.gerber >= link.goodman          # the parabola lies outside the line
            assert 0 < link.alternating <= link.peak_alternating
            assert link.peak_alternating == pytest.approx(alternating_von_mises(answer.amplitudes[name]).max())
            assert link.region in ("eye A", "shank", "eye B")
    assert fatigue.stress_seconds < 1.0


def test_a_material_without_endurance_strength_is_refused(coarse_reference):
    link = coarse_reference.links[2]
    bare = dataclasses.replace(link, model=dataclasses.replace(
        link.model, material=dataclasses.replace(STEEL, endurance_strength=None)))
    case = dataclasses.replace(coarse_reference, links=tuple(bare if x.name == link.name else x
                                                             for x in coarse_reference.links))
    with pytest.raises(CaseError, match=f"link '{link.name}', field 'material.endurance_strength'"):
        solve_fatigue(case)


@pytest.mark.slow
def test_the_stress_command_prints_json_and_writes_vtu(coarse_reference, tmp_path, capsys):
    import meshio

    path = tmp_path / "case.json"
    path.write_text(to_json(dataclasses.replace(coarse_reference, load_cases=(LoadCase("cruise", thrust=23e3),))))
    assert main(["stress", str(path), "--vtu", str(tmp_path / "vtu"), "--png", str(tmp_path / "png"), "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert sorted(p.name for p in (tmp_path / "png").iterdir()) == sorted(f"{x.name}.png" for x in coarse_reference.links)
    assert answer["load_cases"][0]["load_case"] == "cruise"
    lp = answer["fatigue"]["excitations"][0]
    assert lp["excitation"] == "LP rotor" and lp["links"]["rear-middle"]["goodman"] > 1
    mesh = meshio.read(tmp_path / "vtu" / "rear-middle.vtu")
    preload = mesh.point_data["preload stress"]
    np.testing.assert_allclose(mesh.point_data["preload von Mises"], von_mises(preload), rtol=1e-12)
    assert mesh.point_data["LP rotor alternating von Mises"].max() == pytest.approx(
        lp["links"]["rear-middle"]["peak_alternating"], rel=1e-12)
    assert mesh.point_data["mode 1"].shape == (len(preload), 3)


def test_a_link_is_drawn_with_the_peaks_of_its_stress_fields(fatigue):
    figure = fatigue.plot("rear-middle")
    titles = [ax.get_title() for ax in figure.axes if ax.get_title()]
    preload = von_mises(fatigue.mean_stress["rear-middle"]).max()
    assert titles[0] == f"preload von Mises: peak {preload / 1e6:.3g} MPa"
    for title, answer in zip(titles[1:], fatigue.excitations, strict=True):
        peak = answer.links["rear-middle"].peak_alternating
        assert title.startswith(answer.excitation) and title.endswith(f"peak {peak / 1e6:.3g} MPa")


def test_the_stress_command_names_a_missing_endurance_strength(coarse_reference, tmp_path, capsys):
    path = tmp_path / "case.json"
    path.write_text(to_json(coarse_reference))
    bad = json.loads(path.read_text())
    text = json.dumps(bad).replace('"endurance_strength": 235000000.0', '"endurance_strength": null', 1)
    assert text != json.dumps(bad)
    path.write_text(text)
    assert main(["stress", str(path)]) == EXIT_BAD_INPUT
    assert "material.endurance_strength" in capsys.readouterr().err
