"""The fast linear mount with a flexible engine casing against the Exudyn pipeline, the casing's modulus as a
design parameter (its derivative against differences) and fitted to rig records."""
import dataclasses

import numpy as np
import pytest

from workbook import run_case
from workbook.design.linear_mount import LinearMount, keeps_casing_modes
from workbook.design.sensitivity import design_sensitivity, difference_sensitivity
from workbook.model.case import ForceTransducers
from workbook.model.reference import reference_case, reference_casing
from workbook.rig.synthetic import synthetic_records
from workbook.rig.updating import update_model
from workbook.studies.parametric import parameter

#: The true casing is this much softer than the nominal model's.
SOFTER = 0.8


@pytest.fixture(scope="module")
def nominal(cache_dir):
    """The LP rotor on rigid links and a coarse casing with static modes only (the cheapest flexible engine),
    on force transducers; the preload solved to 1e-7 (tighter fails on the casing's stiff bearings)."""
    case = reference_case().with_rigid_links()
    engine = dataclasses.replace(case.engine, casing=reference_casing(element_size=0.12, modes="static"))
    return dataclasses.replace(case, excitations=case.excitations[:1], engine=engine,
                               test_rig=ForceTransducers((1e8,) * 3),
                               analysis=dataclasses.replace(case.analysis, equilibrium_tolerance=1e-7))


@pytest.fixture(scope="module")
def mount(nominal):
    return LinearMount.prepare(nominal)


@pytest.fixture(scope="module")
def softer(nominal):
    """The case with the softer casing and its answers by the Exudyn pipeline (a casing reduced anew)."""
    case = parameter("casing_modulus").apply(nominal, SOFTER * nominal.engine.casing.material.youngs_modulus)
    return case, run_case(case)


def _errors(fast, exact):
    """Normwise relative errors of T and the worst hinge's force amplitudes, per run."""
    for f, e in zip(fast.runs, exact.runs, strict=True):
        assert f.name == e.name
        scale = max(np.abs(e.hinge_amplitudes[name]).max() for name in e.hinge_amplitudes)
        yield (np.abs(f.transmissibility - e.transmissibility).max() / np.abs(e.transmissibility).max(),
               max(np.abs(f.hinge_amplitudes[n] - e.hinge_amplitudes[n]).max() for n in e.hinge_amplitudes) / scale)


@pytest.mark.slow
def test_the_prepared_casing_and_a_softer_one_are_the_pipeline_answers(mount, softer):
    """The core's bearings couple it to the casing in the rest of the scene: without them the excitation
    on the core reached no hinge (T = 0)."""
    prepared = run_case(mount.case)
    for t_error, hinge_error in _errors(mount.evaluate(mount.case).result, prepared):
        assert t_error < 2e-8 and hinge_error < 2e-8
    case, exact = softer
    fast = mount.evaluate(case).result
    assert not np.allclose(fast.runs[0].transmissibility, prepared.runs[0].transmissibility, rtol=0.05)
    for t_error, hinge_error in _errors(fast, exact):
        assert t_error < 2e-8 and hinge_error < 2e-8


@pytest.mark.slow
def test_random_hinge_designs_on_a_flexible_casing_agree_with_the_pipeline(mount):
    """Within 1e-5 of T (found: up to 2.2e-6; the rigid engine 1e-8): springs 1 to 4 times stiffer move the
    engine by about 0.5 mrad, and the expansion of the rest, of second order in the rotations, leaves its
    third-order terms in the stiff bearings and spin restraint between the core (Tait-Bryan angles) and
    the casing (Euler parameters), and first-order ones in the core's mass and the rotors' gyroscopic
    damping."""
    rng = np.random.default_rng(3)
    for _ in range(2):
        hinges = tuple(dataclasses.replace(h, stiffness=tuple(h.values("stiffness") * rng.uniform(1.0, 4.0, 3)),
                                           loss_factor=float(rng.uniform(0.02, 0.1))) for h in mount.case.hinges)
        case = dataclasses.replace(mount.case, hinges=hinges)
        for t_error, hinge_error in _errors(mount.evaluate(case).result, run_case(case)):
            assert t_error < 1e-5 and hinge_error < 1e-5


@pytest.mark.slow
def test_the_casing_modulus_derivative_equals_central_differences(mount):
    modulus = 0.9 * mount.case.engine.casing.material.youngs_modulus
    values = {"casing_modulus": modulus, "hinge_stiffness/front": 3e7}
    direct, differences = design_sensitivity(mount, values), difference_sensitivity(mount, values)
    for j in range(len(values)):
        for a, b in ((direct.gradient, differences.gradient), (direct.hinge_gradient, differences.hinge_gradient)):
            assert np.abs(a[..., j] - b[..., j]).max() < 1e-5 * np.abs(b[..., j]).max()
    assert np.abs(direct.gradient[..., 0]).max() * modulus > 1e-3 * direct.transmissibility.max()


@pytest.mark.slow
def test_updating_recovers_a_softer_casing_within_two_standard_errors(nominal, mount, softer):
    truth, result = softer
    records = synthetic_records(truth, result, (3, 4), noise=0.002)
    e0 = nominal.engine.casing.material.youngs_modulus
    update = update_model(nominal, records, {"casing_modulus": (0.5 * e0, 2.0 * e0)}, mount=mount)
    expected = truth.engine.casing.material.youngs_modulus
    (value,), (error,) = update.values, update.standard_errors
    assert abs(value - expected) < 2 * error, (value, expected, error)
    assert error < 0.1 * value


#: A casing reduced for 59 Hz: first free-free mode 100 Hz, so ``auto`` keeps the fixed-interface modes up to
#: 4 x 59 = 236 Hz and the first one past it.
FREQUENCIES = {"free_free_hz": np.array([100.0]), "fixed_interface_hz": np.array([150.0, 230.0, 260.0])}


@pytest.mark.parametrize("modes, scale, prepared_hz, excitation_hz, kept", [
    ("auto", 1.0, 59.0, 59.0, True),
    ("auto", 1.05, 59.0, 59.0, True),     # 230 Hz x 1.025 = 235.7 Hz: still below the cut-off
    ("auto", 0.8, 59.0, 59.0, False),     # 260 Hz x 0.894 = 232.6 Hz: the cut-off needs a fourth mode
    ("auto", 1.1, 59.0, 59.0, False),     # 230 Hz x 1.049 = 241.2 Hz: two modes reach the cut-off
    ("auto", 1.0, 59.0, 62.0, True),      # a cut-off of 248 Hz: the third mode still the first past it
    ("auto", 1.0, 59.0, 66.0, False),     # a cut-off of 264 Hz: past the last mode kept
    ("auto", 2.0, 20.0, 20.0, True),      # 20 Hz below a quarter of 100 Hz: static modes, and more so stiffer
    ("auto", 0.5, 20.0, 20.0, False),     # a quarter of 70.7 Hz is below 20 Hz: modes wanted
    ("static", 0.3, 59.0, 59.0, True),
    (3, 0.3, 59.0, 59.0, True),
])
def test_a_casing_modulus_keeps_the_prepared_modes_unless_its_selection_changes(modes, scale, prepared_hz,
                                                                              excitation_hz, kept):
    frequencies = FREQUENCIES if modes != "static" else {**FREQUENCIES, "fixed_interface_hz": np.zeros(0)}
    assert keeps_casing_modes(modes, frequencies, scale, prepared_hz, excitation_hz) is kept


@pytest.mark.slow
def test_designs_together_body_by_body_are_the_whole_solve(mount, monkeypatch):
    """The flexible engine (core and casing one body: its bearings join them), rigid links and the rig's
    transducer masses: the casing's block, every block padded to its width, makes the whole matrices cheaper,
    and the mount answers whole. Body by body (forced here), the channel forces of designs together (hinge
    designs, one with a softer casing) equal the solve of the whole matrices to 1e-10, and each design's T
    its own alone."""
    from workbook.design.blocks import BodyLayout
    from workbook.design.linear_mount import _solve_item

    excitation = mount.case.excitations[0]
    assert not mount.items[excitation.name].expansion.layout.by_body
    monkeypatch.setattr(BodyLayout, "by_body", property(lambda self: True))
    rng = np.random.default_rng(5)
    cases = []
    for k in range(3):
        hinges = tuple(dataclasses.replace(h, stiffness=tuple(h.values("stiffness") * rng.uniform(1.0, 4.0, 3)),
                                           loss_factor=float(rng.uniform(0.02, 0.1))) for h in mount.case.hinges)
        case = dataclasses.replace(mount.case, hinges=hinges)
        cases.append(parameter("casing_modulus").apply(case, SOFTER * case.engine.casing.material.youngs_modulus)
                     if k == 2 else case)
    model = _solve_item(mount._designs(cases), mount.items[excitation.name]).model
    assert len(model.coupling.coupled) > 0 and model.layout.width > 7    # bodies joined by channels; the casing's
    omega = 2 * np.pi * rng.uniform(20.0, 300.0, len(cases))
    loads = np.stack([model.load(excitation, k) for k in range(len(cases))])
    forces, singular = model.respond(omega, loads)
    whole, _ = model.dense().respond(omega, model.layout.vector(loads))
    assert not singular.any()
    assert np.abs(forces - whole).max() <= 1e-10 * np.abs(whole).max()
    for together, case in zip(mount.evaluate_many(cases), cases, strict=True):
        alone = mount.evaluate(case).result.runs[0].transmissibility
        assert np.abs(together.result.runs[0].transmissibility - alone).max() <= 1e-8 * np.abs(alone).max()
