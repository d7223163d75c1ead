"""A sweep's responses from one eigen-decomposition equal the direct solve at every frequency,
with viscous damping and with loss factors (a complex stiffness)."""
import dataclasses

import numpy as np
import pytest

from workbook.solve.harmonic import excitation_phasor
from workbook.solve.pipeline import prepare
from workbook.solve.response_sweep import ROUND_OFF, modal_motions, respond_many


def _with_loss_factors(case):
    """*case* with hinge loss factor 0.05 instead of its viscous dampers, and link loss factor 0.002."""
    return dataclasses.replace(
        case, hinges=tuple(dataclasses.replace(h, damping=0.0, loss_factor=0.05) for h in case.hinges),
        links=tuple(dataclasses.replace(link, loss_factor=0.002) for link in case.links))


@pytest.mark.parametrize("damping", ["viscous", "loss factors"])
def test_every_frequency_equals_the_direct_solve(coarse_reference, damping):
    case = coarse_reference if damping == "viscous" else _with_loss_factors(coarse_reference)
    excitation = case.excitations[0]
    prepared = prepare(case, excitation)
    with prepared.scene:
        model = prepared.model
        assert (model.linearization.structural is not None) == (damping == "loss factors")
        force = excitation_phasor(excitation)
        # log-spaced through the mounted modes and the links' first modes, plus the modes themselves
        resonances = [mode.frequency_hz for mode in prepared.modes if 1.0 < mode.frequency_hz < 500.0]
        frequencies = np.sort(np.concatenate([np.geomspace(1.0, 500.0, 300), resonances]))
        # the eigen-decomposition answers every one of them (no direct solve behind its back)
        _, errors = modal_motions(model, 2 * np.pi * frequencies, model.input_matrix(excitation.point) @ force)
        assert errors.max() <= ROUND_OFF, errors.max()
        many = respond_many(model, frequencies, force, excitation.point)
        for index, frequency in enumerate(frequencies):
            response = many.response(index)
            direct = model.respond(frequency, force, excitation.point)
            assert response.frequency_hz == frequency
            scale = np.abs(direct.pylon_force).max()
            np.testing.assert_allclose(response.pylon_force, direct.pylon_force, rtol=0, atol=1e-9 * scale,
                                       err_msg=f"{frequency} Hz")
            for name, value in direct.hinge_forces.items():
                np.testing.assert_allclose(response.hinge_forces[name], value, rtol=0,
                                           atol=1e-9 * np.abs(value).max(), err_msg=f"{name} at {frequency} Hz")
