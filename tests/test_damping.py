"""Loss-factor (structural) damping against closed forms and an independent path.

A rigid mass on four identical hinges with loss factor eta (the single-DOF
scene of tests/test_sdof.py, without viscous damping) transmits

    T(r) = sqrt(1 + eta^2) / sqrt((1 - r^2)^2 + eta^2)

in the steady state at r = f / f_n: exactly in the frequency domain (complex
stiffness k (1 + i eta)), and in the time domain through the viscous
equivalent d = eta k / w built at the run's own frequency.
"""
import dataclasses
import math

import numpy as np
import pytest

from workbook.errors import CaseError
from workbook.model.case import ENGINE, PYLON, AnalysisSettings, Case, Engine, Hinge, Link, RotatingForce
from workbook.model.reference import LP_ROTOR
from workbook.scene.structural_damping import equivalent_viscous_damping
from workbook.solve.pipeline import prepare, run_case

MASS = 500.0              # kg
NATURAL_HZ = 10.0
ETA = 0.1
STIFFNESS = MASS * (2 * math.pi * NATURAL_HZ) ** 2 / 4      # per hinge, N/m
RATIOS = (0.5, 1.5, 3.0)


def closed_form(ratio: float, eta: float = ETA) -> float:
    return math.sqrt((1 + eta ** 2) / ((1 - ratio ** 2) ** 2 + eta ** 2))


def lossy_case(method: str) -> Case:
    cg = (0.2, -0.1, 0.3)
    hinges = tuple(Hinge(f"hinge {i}", PYLON, ENGINE, (cg[0] + sx * 0.4, cg[1] + sy * 0.3, cg[2]), STIFFNESS,
                         loss_factor=ETA)
                   for i, (sx, sy) in enumerate([(1, 1), (1, -1), (-1, 1), (-1, -1)]))
    excitations = tuple(RotatingForce(f"r = {r:g}", point=cg, frequency_hz=r * NATURAL_HZ, amplitude=1000.0)
                        for r in RATIOS)
    return Case("single DOF, loss factor", Engine(MASS, cg, ((20.0, 0, 0), (0, 30.0, 0), (0, 0, 40.0))), links=(),
                hinges=hinges, excitations=excitations,
                analysis=AnalysisSettings(steps_per_period=80, method=method))


@pytest.fixture(scope="module", params=["frequency", "time"])
def result(request):
    return request.param, run_case(lossy_case(request.param))


@pytest.mark.parametrize("ratio", RATIOS)
def test_loss_factor_transmissibility_matches_closed_form(result, ratio):
    method, mount = result
    run = mount.run(f"r = {ratio:g}")
    expected = closed_form(ratio)
    # exact in the frequency domain; the time domain's equivalent viscous damping is exact at the
    # run's frequency, leaving the integrator's and the steady-state window's errors
    tolerance = 1e-8 if method == "frequency" else 0.005
    assert run.transmissibility[1] == pytest.approx(expected, rel=tolerance)
    assert run.transmissibility[2] == pytest.approx(expected, rel=tolerance)
    assert run.transmissibility[0] < 1e-6
    assert run.steady


def test_card_names_how_and_where_the_loss_factor_holds(result):
    method, mount = result
    detail = next(e for e in mount.model_cards["r = 1.5"].effects if e.name == "hinge loss factor")
    assert detail.on
    if method == "time":
        assert "equivalent viscous damping" in detail.detail and "at 15 Hz" in detail.detail
    else:
        assert "exact at every frequency" in detail.detail


def test_mounted_mode_damping_ratio_is_half_the_loss_factor():
    prepared = prepare(lossy_case("frequency"), lossy_case("frequency").excitations[0])
    with prepared.scene:
        translations = [m for m in prepared.modes if m.mounted and abs(m.frequency_hz - NATURAL_HZ) < 1e-6]
    assert len(translations) == 3
    for mode in translations:
        assert mode.damping_ratio == pytest.approx(ETA / 2, rel=1e-6)


def test_equivalent_viscous_damping_dissipates_the_same_energy_per_cycle():
    """Energy per cycle: pi eta k u^2 (loss factor) = pi d w u^2 (viscous)."""
    k, eta, frequency = 3.0e7, 0.05, 59.0
    d = equivalent_viscous_damping(eta, k, frequency)
    assert math.pi * d * 2 * math.pi * frequency == pytest.approx(math.pi * eta * k)


@pytest.mark.slow
def test_link_loss_factor_equals_its_rayleigh_equivalent_at_one_frequency(coarse_reference):
    """A link loss factor eta (complex modulus on the reduced stiffness, H) and the
    Rayleigh stiffness damping eta / w (Exudyn's own damping matrix, D) give the
    same answer at w, by the two independent routes of the harmonic model."""
    eta = 0.02
    case = dataclasses.replace(coarse_reference, excitations=(LP_ROTOR,))
    omega = 2 * math.pi * LP_ROTOR.frequency

    def with_links(**fields) -> Case:
        return dataclasses.replace(case, links=tuple(dataclasses.replace(link, **fields) for link in case.links))

    answers = []
    for variant in (with_links(loss_factor=eta),
                    with_links(stiffness_damping=case.links[0].stiffness_damping + eta / omega)):
        assert len({link.stiffness_damping for link in case.links}) == 1
        answers.append(run_case(dataclasses.replace(variant, analysis=dataclasses.replace(
            variant.analysis, method="frequency"))).run(LP_ROTOR.name))
    lossy, rayleigh = answers
    plain = run_case(dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method="frequency")))
    # the link damping changes the answer (else the comparison proves nothing) ...
    assert abs(rayleigh.pylon_amplitude - plain.run(LP_ROTOR.name).pylon_amplitude).max() > \
        1e-6 * rayleigh.pylon_amplitude.max()
    # ... and both routes agree
    assert lossy.pylon_amplitude == pytest.approx(rayleigh.pylon_amplitude, rel=1e-6)


@pytest.mark.parametrize("make", [
    lambda: Hinge("h", PYLON, ENGINE, (0, 0, 0), 1e6, loss_factor=-0.01),
    lambda: Hinge("h", PYLON, ENGINE, (0, 0, 0), 1e6, loss_factor="a lot"),
])
def test_bad_hinge_loss_factor_is_named(make):
    with pytest.raises(CaseError, match="loss_factor"):
        make()


def test_bad_link_loss_factor_is_named(coarse_reference):
    link = coarse_reference.links[0]
    with pytest.raises(CaseError, match=f"link '{link.name}'.*loss_factor"):
        Link(link.name, link.end_a, link.end_b, link.model, loss_factor=-1.0)


@pytest.mark.slow
def test_reference_mount_loss_factor_time_domain_agrees_with_the_frequency_domain():
    """The reference mount's hinge loss factor (rigid links, LP rotor): the time domain, with
    the viscous equivalent at 59 Hz, gives the exact frequency-domain T to the time-step error
    (0.4 % at 40 steps per period, docs/reference-mount.md)."""
    from workbook.model.reference import reference_case

    case = dataclasses.replace(reference_case().with_rigid_links(), excitations=(LP_ROTOR,))
    assert all(h.loss_factor > 0 and h.damping == 0 for h in case.hinges)
    exact = run_case(dataclasses.replace(case, analysis=AnalysisSettings(method="frequency"))).run()
    timed = run_case(dataclasses.replace(case, analysis=AnalysisSettings(method="time", steps_per_period=80))).run()
    assert timed.steady
    # x and z; the lateral pylon force nearly cancels (T_y 0.0004), where the step error is no fraction of T
    np.testing.assert_allclose(timed.transmissibility[[0, 2]], exact.transmissibility[[0, 2]], rtol=0.005)
