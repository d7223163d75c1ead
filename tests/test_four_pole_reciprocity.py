"""Reciprocity of the four-pole set: what must hold, and why it is not exact.

The condensation keeps the symmetry of the linearisation it is given: from
the symmetric part of the harmonic model the set is reciprocal to round-off.
The model's own skew part comes from the preload (the derivative of Exudyn's
equations in the bodies' Euler parameters at a loaded state); it is what
makes K12 and K21^T differ, by an amount that varies between machines (the
measured mismatch is 9.4e-8; 1.2e-6 with Exudyn's own Jacobian, for which a
test that asked for 1e-6 failed on some machines).
"""
import dataclasses

import numpy as np
import pytest

from workbook.model.case import HarmonicForce
from workbook.model.reference import LP_ROTOR
from workbook.solve.four_pole import condense, mount_case
from workbook.solve.pipeline import prepare


def _skew(matrix):
    return np.abs(matrix - matrix.T).max() / np.abs(matrix).max()


def _sets(case, frequency):
    """The set from the harmonic model, the set from its symmetric part, and K's skew part."""
    probe = HarmonicForce("four-pole probe", point=tuple(case.engine.center_of_mass), direction=(1.0, 0.0, 0.0),
                          amplitude=1.0, frequency_hz=frequency)
    prepared = prepare(mount_case(case), probe)
    with prepared.scene:
        model = prepared.model
        lin = model.linearization
        symmetric = dataclasses.replace(lin, stiffness=(lin.stiffness + lin.stiffness.T) / 2,
                                        damping=(lin.damping + lin.damping.T) / 2)
        return (condense(model, case, [frequency]),
                condense(dataclasses.replace(model, linearization=symmetric), case, [frequency]),
                _skew(lin.stiffness))


def _mismatch(pole):
    return np.abs(pole.k12 - np.transpose(pole.k21, (0, 2, 1))).max() / np.abs(pole.k21).max()


@pytest.fixture(scope="module")
def preloaded(coarse_reference):
    return _sets(coarse_reference, LP_ROTOR.frequency)


def test_the_condensation_keeps_the_symmetry_it_is_given(preloaded):
    """From the symmetric part of the model: reciprocal to 1e-12 (measured 1.2e-14)."""
    _, symmetric, _ = preloaded
    assert _mismatch(symmetric) < 1e-12


def test_the_mismatch_is_the_preloaded_linearisation_s_skew_part(preloaded, coarse_reference):
    """The actual set lies within 1e-4 of its largest entry of the symmetric
    one (measured 9.4e-8, so T is unaffected to that order); its skew part
    comes with the preload: K's skew part falls from 3.4e-6 to 1.6e-12
    (measured) without the static loads."""
    actual, symmetric, skew = preloaded
    for name in ("k11", "k12", "k21", "k22"):
        difference = np.abs(getattr(actual, name) - getattr(symmetric, name)).max()
        assert difference <= 1e-4 * np.abs(getattr(symmetric, name)).max(), name
    assert _mismatch(actual) < 1e-4
    unloaded = dataclasses.replace(coarse_reference, static_loads=())
    assert _sets(unloaded, LP_ROTOR.frequency)[2] < skew / 100
