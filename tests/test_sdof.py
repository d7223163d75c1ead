"""A rigid mass on symmetric spring-dampers against the single-DOF closed form.

Four identical isotropic hinges join the mass to the pylon at (+-a, +-b, 0)
about its centre of gravity, so a force at the centre of gravity drives pure
translation: m x'' + 4 d x' + 4 k x = F. The force transmitted to the pylon
then has the closed-form transmissibility

    T(r) = sqrt(1 + (2 zeta r)^2) / sqrt((1 - r^2)^2 + (2 zeta r)^2),

r = f / f_n, f_n = sqrt(4 k / m) / 2 pi, zeta = 4 d / (2 sqrt(4 k m)).
"""
import dataclasses
import math

import numpy as np
import pytest

from workbook.answers.results import PYLON_SUM
from workbook.model.case import ENGINE, PYLON, AnalysisSettings, Case, Engine, Hinge, RotatingForce
from workbook.solve.pipeline import run_case

MASS = 500.0              # kg
NATURAL_HZ = 10.0
ZETA = 0.05
STIFFNESS = MASS * (2 * math.pi * NATURAL_HZ) ** 2 / 4      # per hinge, N/m
DAMPING = 2 * ZETA * math.sqrt(4 * STIFFNESS * MASS) / 4      # per hinge, N s/m


def closed_form(ratio: float) -> float:
    damping = (2 * ZETA * ratio) ** 2
    return math.sqrt((1 + damping) / ((1 - ratio ** 2) ** 2 + damping))


def sdof_case(ratios) -> Case:
    cg = (0.2, -0.1, 0.3)
    hinges = tuple(
        Hinge(f"hinge {i}", PYLON, ENGINE, (cg[0] + sx * 0.4, cg[1] + sy * 0.3, cg[2]), STIFFNESS, DAMPING)
        for i, (sx, sy) in enumerate([(1, 1), (1, -1), (-1, 1), (-1, -1)]))
    excitations = tuple(RotatingForce(f"r = {r:g}", point=cg, frequency_hz=r * NATURAL_HZ, amplitude=1000.0)
                        for r in ratios)
    # 80 steps per period: near resonance (r = 1.5) the generalized-alpha
    # period error of 40 steps (about 0.2 %) is amplified to 0.7 % in T.
    return Case("single DOF", Engine(MASS, cg, ((20.0, 0, 0), (0, 30.0, 0), (0, 0, 40.0))), links=(),
                hinges=hinges, excitations=excitations, analysis=AnalysisSettings(steps_per_period=80, method="time"))


RATIOS = (0.5, 1.5, 3.0)


@pytest.fixture(scope="module")
def result():
    return run_case(sdof_case(RATIOS))


@pytest.mark.parametrize("ratio", RATIOS)
def test_transmissibility_matches_closed_form(result, ratio):
    run = result.run(f"r = {ratio:g}")
    expected = closed_form(ratio)
    # the rotating force excites y and z alike; x is not excited
    assert run.transmissibility[1] == pytest.approx(expected, rel=0.005)
    assert run.transmissibility[2] == pytest.approx(expected, rel=0.005)
    assert run.transmissibility[0] < 1e-6
    assert run.steady


def test_hinges_share_the_pylon_force_equally(result):
    run = result.run("r = 3")
    amplitudes = np.array([run.hinge_amplitudes[f"hinge {i}"] for i in range(4)])
    np.testing.assert_allclose(amplitudes[:, 1:], np.tile(run.pylon_amplitude[1:] / 4, (4, 1)), rtol=1e-6)


def test_efficiency_and_level_follow_from_transmissibility(result):
    table = result.to_pandas("efficiency")
    run = result.run("r = 3")
    assert table.loc["r = 3", "eta % z"] == pytest.approx((1 - run.transmissibility[2]) * 100)
    assert result.to_pandas("db").loc["r = 3", "dB z"] == pytest.approx(20 * math.log10(run.transmissibility[2]))


def test_former_table_names_warn_and_give_the_same_tables(result):
    """The names of version 0.1 (table, table_text, to_frame, static_frame) still answer, with a warning."""
    with pytest.warns(DeprecationWarning, match=r"MountResult.table\(\) is now to_pandas"):
        old = result.table("db")
    assert old.equals(result.to_pandas("db"))
    with pytest.warns(DeprecationWarning, match="to_frame"):
        assert result.to_frame().equals(result.to_pandas("all"))
    with pytest.warns(DeprecationWarning, match="table_text"):
        assert result.table_text("db") == result.to_text("db")
    with pytest.warns(DeprecationWarning, match="static_frame"):
        assert result.static_frame("r = 3").equals(result.preloads["r = 3"].to_pandas())
    long = result.to_pandas("all")
    pylon = long[(long["run"] == "r = 3") & (long["location"] == PYLON_SUM)].set_index("direction")
    assert pylon.loc["z", "dB"] == pytest.approx(result.to_pandas("db").loc["r = 3", "dB z"])


def test_clearance_gap_adds_to_the_static_sag():
    """Hinges with a radial gap g: the mass sinks through the gap, then
    compresses the contact springs; inside the gap only the small residual
    stiffness k_r acts: 4 (k_r u + k_c (u - g)) = W."""
    import exudyn as exu

    from workbook.model.case import Gravity
    from workbook.scene.build import build_scene
    from workbook.scene.hinge_law import CLEARANCE, RESIDUAL_STIFFNESS_RATIO
    from workbook.solve.preload import solve_preload

    gap = 0.5e-3
    case = sdof_case(())
    hinges = tuple(dataclasses.replace(h, radial_clearance=gap) for h in case.hinges)
    case = dataclasses.replace(case, hinges=hinges, static_loads=(Gravity(),))
    scene = build_scene(case)
    preload = solve_preload(scene)
    assert all(items.hinge_law is CLEARANCE for items in scene.hinges.values())
    sag = -scene.mbs.GetNodeOutput(scene.engine.node, exu.OutputVariableType.Displacement)[2]
    weight = MASS * 9.81
    expected = (weight / 4 + STIFFNESS * gap) / (STIFFNESS * (1 + RESIDUAL_STIFFNESS_RATIO))
    assert sag == pytest.approx(expected, rel=1e-6)
    assert sag > gap
    np.testing.assert_allclose(preload.pylon_force, [0, 0, -weight], atol=1e-6 * weight)
