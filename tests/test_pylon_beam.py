"""The pylon as a clamped box beam carrying the pins.

Closed forms: a cantilever's static tip stiffnesses (EA/L, 3EI/L^3 in both
planes; through a rigid offset r, the torsion r^2 L / GJ and the bending
r^2 L / EI of the offset's moment add to the compliance) and its first
bending frequency (1.8751^2 sqrt(EI / (rho A L^4)) / 2 pi). The four-pole
closure by compliance equals the closure by stiffness for uncoupled pins.
A run of the single-DOF engine on a vertical beam, excited along the beam:
the hinges in series with the beam's axial dynamic stiffness
``E* A beta cot(beta L)`` (``beta = w sqrt(rho / E*)``, ``E* = E (1 + i eta)``).
"""
import dataclasses
import math

import numpy as np
import pytest
import scipy.linalg as sla
from test_sdof import DAMPING, MASS, STIFFNESS, sdof_case

from flexbodies.materials import Material
from workbook.cli.main import main
from workbook.errors import EXIT_BAD_INPUT, CaseError
from workbook.model.case import AnalysisSettings, HarmonicForce
from workbook.model.codec import from_json, to_json
from workbook.model.pylon_beam import BoxBeamPylon, beam_model
from workbook.model.pylon_impedance import PylonImpedance
from workbook.solve.pipeline import four_pole, run_case

ALUMINIUM = Material("aluminium", youngs_modulus=70e9, poisson_ratio=0.33, density=2800.0)
FREQUENCIES = (3.0, 10.5, 25.0)


def _beam(**changes):
    fields = dict(root=(0.0, 0.0, 0.0), tip=(2.0, 0.0, 0.0), width=0.3, height=0.5, wall=0.01, material=ALUMINIUM,
                  loss_factor=0.0, elements=8)
    return BoxBeamPylon(**{**fields, **changes})


def test_static_tip_stiffness_is_the_cantilevers():
    beam = _beam()
    section, e, length, arm = beam.section(), ALUMINIUM.youngs_modulus, beam.length, 0.4
    g = e / (2 * (1 + ALUMINIUM.poisson_ratio))
    compliance = beam_model(beam, [(2.0, 0.0, 0.0), (2.0, 0.0, arm)]).compliance([0.0])[0].real
    expected = {(0, 0): length / (e * section.area),
                (1, 1): length ** 3 / (3 * e * section.second_moment_3),
                (2, 2): length ** 3 / (3 * e * section.second_moment_2),
                # the offset pin: a width force twists the beam, a heading force bends it by its moment
                (4, 4): length ** 3 / (3 * e * section.second_moment_3) + arm ** 2 * length / (g * section.torsion_constant),
                (3, 3): length / (e * section.area) + arm ** 2 * length / (e * section.second_moment_2)}
    for (row, column), value in expected.items():
        assert compliance[row, column] == pytest.approx(value, rel=1e-9)
    np.testing.assert_allclose(compliance, compliance.T, atol=1e-12 * np.abs(compliance).max())


def test_first_bending_frequency_converges_to_the_cantilevers():
    beam = _beam(elements=40)
    section = beam.section()
    model = beam_model(beam, [beam.tip])
    lowest = np.sqrt(sla.eigh(model.stiffness, model.mass, eigvals_only=True)[0]) / (2 * math.pi)
    expected = 1.875104 ** 2 * math.sqrt(ALUMINIUM.youngs_modulus * section.second_moment_3
                                         / (ALUMINIUM.density * section.area * beam.length ** 4)) / (2 * math.pi)
    assert lowest == pytest.approx(expected, rel=1e-5)


def test_the_compliance_closure_is_the_stiffness_closure():
    """Uncoupled pins of stiffness Z: G = Z^-1 per pin gives the same
    response as Z itself; G = 0 is the rigid pylon."""
    case = sdof_case(())
    pole = four_pole(case, FREQUENCIES)
    w = 2 * np.pi * np.array(FREQUENCIES)
    per_pin = (3 * STIFFNESS + 1j * w * 40.0 - w ** 2 * 20.0)[:, None, None] * np.eye(3)
    pins = len(pole.pins)
    compliance = np.stack([np.kron(np.eye(pins), np.linalg.inv(z)) for z in per_pin])
    force, point = np.array([0.0, 1.0, -1j]), case.engine.center_of_mass
    by_stiffness = pole.respond(force, point, per_pin)
    by_compliance = pole.respond(force, point, compliance=compliance)
    rigid, zero = pole.respond(force, point), pole.respond(force, point, compliance=np.zeros_like(compliance))
    for a, b in zip(by_stiffness, by_compliance, strict=True):
        np.testing.assert_allclose(b.pin_forces, a.pin_forces, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(b.pin_motions, a.pin_motions, rtol=1e-9, atol=1e-18)
    for a, b in zip(rigid, zero, strict=True):
        np.testing.assert_allclose(b.pin_forces, a.pin_forces, rtol=1e-12)
    with pytest.raises(CaseError, match="one of them"):
        pole.respond(force, point, per_pin, compliance=compliance)


def _vertical_case(beam_length=3.0, **changes):
    """The single-DOF engine on four hinges whose pins hang on the tip of a
    vertical box beam above it, excited vertically at its centre of gravity."""
    base = sdof_case(())
    cg = base.engine.center_of_mass
    excitations = tuple(HarmonicForce(f"{f:g} Hz", point=cg, direction=(0.0, 0.0, 1.0), amplitude=1000.0,
                                      frequency_hz=f) for f in FREQUENCIES)
    beam = BoxBeamPylon(root=(cg[0], cg[1], cg[2] + beam_length), tip=cg, width=0.05, height=0.05, wall=0.002,
                        material=ALUMINIUM, loss_factor=0.05, up=(1.0, 0.0, 0.0), elements=60, **changes)
    return dataclasses.replace(base, excitations=excitations, analysis=AnalysisSettings(method="auto"),
                               pylon=beam)


def test_an_axially_loaded_beam_pylon_is_the_rod_in_series():
    case = _vertical_case()
    beam = case.pylon
    result = run_case(case)
    area, density = beam.section().area, ALUMINIUM.density
    modulus = ALUMINIUM.youngs_modulus * (1 + 1j * beam.loss_factor)
    for frequency in FREQUENCIES:
        w = 2 * math.pi * frequency
        beta = w * np.sqrt(density / modulus)
        rod = modulus * area * beta / np.tan(beta * beam.length)
        hinges = 4 * (STIFFNESS + 1j * w * DAMPING)
        series = hinges * rod / (hinges + rod)
        expected = abs(series / (series - w ** 2 * MASS))
        run = result.run(f"{frequency:g} Hz")
        assert run.transmissibility[2] == pytest.approx(expected, rel=1e-4)
        assert abs(run.transmissibility[2] / abs(hinges / (hinges - w ** 2 * MASS)) - 1) > 0.01   # the beam matters
        assert max(run.transmissibility[:2]) < 1e-9
        card = result.model_cards[run.name]
        assert any(e.name == "flexible pylon (box beam)" for e in card.effects)


def test_a_stiff_beam_is_the_rigid_pylon():
    stiff = dataclasses.replace(_vertical_case(), pylon=dataclasses.replace(
        _vertical_case().pylon, material=dataclasses.replace(ALUMINIUM, youngs_modulus=1e22)))
    rigid = run_case(dataclasses.replace(stiff, pylon=None))
    on_beam = run_case(stiff)
    for run in rigid.runs:
        np.testing.assert_allclose(on_beam.run(run.name).transmissibility[2], run.transmissibility[2], rtol=1e-6)


def test_bad_beams_and_the_time_domain_are_refused(tmp_path, capsys):
    case = _vertical_case()
    with pytest.raises(CaseError, match="reaches the foot of the pin"):
        run_case(dataclasses.replace(case, pylon=dataclasses.replace(
            case.pylon, tip=tuple(np.add(case.engine.center_of_mass, (0.0, 0.0, 0.5))))))
    with pytest.raises(CaseError, match="wall"):
        _beam(wall=0.2)
    with pytest.raises(CaseError, match="not along the beam axis"):
        _beam(up=(1.0, 0.0, 0.0))
    table = PylonImpedance.from_array("table", [1.0, 50.0], ["hinge 0", "hinge 1", "hinge 2", "hinge 3"],
                                      np.ones((2, 4, 3, 3)) * 1e6)
    with pytest.raises(CaseError, match="one pylon model"), pytest.warns(DeprecationWarning, match="Case.pylon"):
        dataclasses.replace(case, pylon_impedance=table)
    assert from_json(to_json(case)) == case
    path = tmp_path / "case.json"
    path.write_text(to_json(case))
    assert main(["run", str(path), "--method", "time"]) == EXIT_BAD_INPUT
    assert "pylon beam" in capsys.readouterr().err
