"""The hinge-law registry: each hinge gets the first law that applies, and a
new law is one class registered in :data:`workbook.scene.hinge_laws.HINGE_LAWS`.

The registered test law is a linear spring ``F = s k u + d v`` recorded as a
symbolic user function on a connector that keeps the hinge's own stiffness k:
the single-DOF mount of tests/test_sdof.py built with it must answer as the
same mount with hinges of stiffness ``s k`` (plain spring-dampers), and
differently from the mount without it.
"""
import dataclasses

import numpy as np
import pytest
from test_sdof import STIFFNESS, sdof_case

from workbook.design.linear_mount import LinearMount
from workbook.errors import CaseError, OutsideDesignModel
from workbook.model.case import Hinge
from workbook.scene import hinge_laws
from workbook.scene.bearing import PER_DIRECTION
from workbook.scene.hinge_law import CLEARANCE
from workbook.scene.hinge_law_base import SPRING_DAMPER, Connector, HingeLaw
from workbook.solve.four_pole import mount_case
from workbook.solve.method import TIME, choose_method
from workbook.solve.pipeline import run_case

SCALE = 2.25      # the test law's stiffness over the hinge's: f_n 10 Hz -> 15 Hz
RATIOS = (0.8, 1.5, 2.5)     # f / 10 Hz: below, at and above the stiffened resonance


class ScaledSpring(HingeLaw):
    """A linear spring SCALE times the hinge's stiffness, as a symbolic user function."""

    name = "scaled hinge spring"

    def applies(self, case, hinge: Hinge) -> bool:
        return hinge.name.startswith("hinge")

    def connector(self, case, hinge, stiffness, damping, loss_time) -> Connector:
        def spring_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
            return [SCALE * stiffness[i] * displacement[i] + damping[i] * velocity[i] for i in range(3)]

        return Connector(stiffness, damping + loss_time * stiffness, spring_force)

    def force(self, case, hinge, displacement, velocity, loss_time=0.0) -> np.ndarray:
        return SCALE * hinge.values("stiffness") * displacement + hinge.values("damping") * velocity

    def card_entry(self, case):
        return True, f"{SCALE:g} k on every hinge"


class NonlinearSpring(ScaledSpring):
    name = "test nonlinear law"
    nonlinear = True
    linearised = "the test laws are linearised about the preload"
    time_domain_note = "the time domain resolves them"


def _frequency_case(**changes):
    case = sdof_case(RATIOS)
    return dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method="frequency"), **changes)


def _transmissibility(result) -> np.ndarray:
    return np.array([result.run(f"r = {r:g}").transmissibility[2] for r in RATIOS])


def test_a_registered_law_builds_the_hinges_and_answers_as_its_stiffness(monkeypatch):
    plain = _transmissibility(run_case(_frequency_case()))
    stiffened = _frequency_case(hinges=tuple(dataclasses.replace(h, stiffness=SCALE * STIFFNESS)
                                             for h in sdof_case(()).hinges))
    expected = _transmissibility(run_case(stiffened))
    monkeypatch.setattr(hinge_laws, "HINGE_LAWS", (ScaledSpring(), *hinge_laws.HINGE_LAWS))
    result = run_case(_frequency_case())
    card = result.model_cards["r = 1.5"]
    assert {e.name: e.detail for e in card.effects}["scaled hinge spring"] == "2.25 k on every hinge"
    np.testing.assert_allclose(_transmissibility(result), expected, rtol=1e-6)
    # the stiffened resonance is at 15 Hz (r = 1.5), the plain one at 10 Hz: the answers differ by far
    assert np.all(np.abs(expected / plain - 1) > 0.3)


def test_a_registered_nonlinear_law_sends_the_case_to_the_time_domain_and_is_refused(monkeypatch):
    monkeypatch.setattr(hinge_laws, "HINGE_LAWS", (NonlinearSpring(), *hinge_laws.HINGE_LAWS))
    case = sdof_case((1.0,))
    case = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method="auto"))
    chosen = choose_method(case)
    assert chosen.method == TIME
    assert chosen.reason == ("auto: test nonlinear law on 'hinge 0', 'hinge 1', 'hinge 2', 'hinge 3' makes the "
                             "scene nonlinear; the time domain resolves them")
    assert "the test laws are linearised about the preload, an approximation" in \
        choose_method(_frequency_case()).reason
    with pytest.raises(CaseError, match="hinge 'hinge 0'.*law.*test nonlinear law.*a linear hinge law"):
        mount_case(case)


def test_each_hinge_takes_the_first_law_that_applies():
    case = sdof_case(())
    gapped, anisotropic, plain = (dataclasses.replace(case.hinges[0], radial_clearance=1e-4),
                                  dataclasses.replace(case.hinges[1], stiffness=(STIFFNESS, STIFFNESS, 0.5 * STIFFNESS)),
                                  case.hinges[2])
    case = dataclasses.replace(case, hinges=(gapped, anisotropic, plain, case.hinges[3]))
    assert [hinge_laws.law_of(case, h) for h in case.hinges[:3]] == [CLEARANCE, PER_DIRECTION, SPRING_DAMPER]
    assert list(hinge_laws.nonlinear_hinges(case)) == [CLEARANCE]
    off = dataclasses.replace(case, effects=dataclasses.replace(case.effects, clearance=False))
    assert hinge_laws.law_of(off, gapped) is SPRING_DAMPER and not hinge_laws.nonlinear_hinges(off)


def test_the_linear_mount_refuses_a_clearance_answered_in_the_frequency_domain():
    case = _frequency_case()
    case = dataclasses.replace(case, hinges=(dataclasses.replace(case.hinges[0], radial_clearance=1e-4),
                                             *case.hinges[1:]))
    with pytest.raises(OutsideDesignModel, match=r"hinge clearance laws \(a nonlinear scene\)"):
        LinearMount.prepare(case)
