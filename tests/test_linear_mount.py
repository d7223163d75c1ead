"""The design evaluation in NumPy (workbook.design) against the Exudyn pipeline it replaces."""
import dataclasses

import numpy as np
import pytest

from workbook import run_case
from workbook.design.equilibrium import ChordStiffness
from workbook.design.linear_mount import LinearMount, channel_springs
from workbook.errors import OutsideDesignModel
from workbook.model.reference import reference_case

pytestmark = pytest.mark.slow


def _tight(case):
    # the Exudyn reference solves its preload to 1e-13 of the loads, so that its own tolerance does not count
    return dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, equilibrium_tolerance=1e-10))


@pytest.fixture(scope="module")
def mount():
    return LinearMount.prepare(_tight(reference_case()))


def _design(case, rng):
    hinges = tuple(dataclasses.replace(h, stiffness=tuple(h.values("stiffness") * rng.uniform(1.0, 4.0, 3)),
                                       loss_factor=float(rng.uniform(0.02, 0.1)))
                   for h in case.hinges)
    return dataclasses.replace(case, hinges=hinges)


def _normwise(fast, exact):
    return np.abs(fast - exact).max() / np.abs(exact).max()


def _compare(mount, case):
    """Per excitation item: the largest normwise differences of T, of the hinge force amplitudes and of the
    static hinge forces of the design evaluation from the pipeline's."""
    answer = mount.evaluate(case)
    exact = run_case(case)
    for f, e in zip(answer.result.runs, exact.runs, strict=True):
        assert f.name == e.name
        static, preload = answer.static_hinge_forces[f.name], e.preload.hinge_forces
        yield _normwise(f.transmissibility, e.transmissibility), max(
            _normwise(f.hinge_amplitudes[name], e.hinge_amplitudes[name]) for name in e.hinge_amplitudes), \
            max(np.abs(static[name] - preload[name]).max() for name in preload) / max(
                np.abs(force).max() for force in preload.values())


def test_prepared_design_is_the_pipeline_answer(mount):
    for t_error, hinge_error, static_error in _compare(mount, mount.case):
        assert t_error < 1e-7 and hinge_error < 1e-7 and static_error < 1e-10


def test_random_hinge_designs_agree_with_the_pipeline(mount):
    """Hinge springs 1 to 4 times stiffer: the preload moves, and both paths follow it with the derivative
    of Exudyn's equations (its own Jacobian left the static forces 1e-5 and T 1e-6 apart)."""
    rng = np.random.default_rng(25)
    for _ in range(2):
        for t_error, hinge_error, static_error in _compare(mount, _design(mount.case, rng)):
            assert t_error < 1e-7 and hinge_error < 2e-7 and static_error < 2e-8


def test_engine_mass_and_excitation_amplitude(mount):
    case = mount.case
    engine = dataclasses.replace(case.engine, mass=1.1 * case.engine.mass,
                                 inertia=tuple(tuple(1.2 * v for v in row) for row in case.engine.inertia))
    excitations = tuple(dataclasses.replace(e, amplitude=2.0 * e.amplitude) for e in case.excitations)
    for t_error, hinge_error, static_error in _compare(mount, dataclasses.replace(case, engine=engine,
                                                                                  excitations=excitations)):
        assert t_error < 1e-7 and hinge_error < 2e-7 and static_error < 2e-8


def test_many_designs_at_once_are_each_design_alone(mount):
    """A batch mixing hinge designs, a heavier engine under larger excitations, a change the mount cannot follow
    and an engine so heavy that the chord iteration does not bring it to rest: each answer is that design's alone (to the preload solves' tolerance:
    one design is solved by Newton, designs together by the chord iteration), the heavier one is the pipeline's,
    and the two it cannot answer have their errors in their places."""
    case = mount.case
    rng = np.random.default_rng(7)
    heavier = dataclasses.replace(case, engine=dataclasses.replace(case.engine, mass=1.2 * case.engine.mass),
                                  excitations=tuple(dataclasses.replace(e, amplitude=3.0 * e.amplitude)
                                                    for e in case.excitations))
    moved = dataclasses.replace(case, engine=dataclasses.replace(case.engine, center_of_mass=(-0.5, 0.0, -0.03)))
    sinking = dataclasses.replace(case, engine=dataclasses.replace(case.engine, mass=300 * case.engine.mass))
    batch = [_design(case, rng), moved, heavier, sinking, _design(case, rng)]
    answers = mount.evaluate_many(batch)
    assert isinstance(answers[1], OutsideDesignModel)
    assert isinstance(answers[3], OutsideDesignModel) and "does not bring to rest" in str(answers[3])
    for k in (0, 2, 4):
        alone = mount.evaluate(batch[k])
        for together, single in zip(answers[k].result.runs, alone.result.runs, strict=True):
            assert _normwise(together.transmissibility, single.transmissibility) < 1e-8
            for name, amplitude in single.hinge_amplitudes.items():
                assert _normwise(together.hinge_amplitudes[name], amplitude) < 1e-8
        for item, forces in alone.static_hinge_forces.items():
            for name, force in forces.items():
                assert _normwise(answers[k].static_hinge_forces[item][name], force) < 1e-8
    exact = run_case(heavier)
    for fast, e in zip(answers[2].result.runs, exact.runs, strict=True):
        assert _normwise(fast.transmissibility, e.transmissibility) < 1e-7


def _limp(case, stiffness):
    """*case* with every hinge of *stiffness* (N/m): nothing holds the engine up."""
    return dataclasses.replace(case, hinges=tuple(dataclasses.replace(h, stiffness=stiffness) for h in case.hinges))


def _scaled(case, factor):
    """*case* with every hinge's stiffness times *factor*."""
    return dataclasses.replace(case, hinges=tuple(dataclasses.replace(h, stiffness=tuple(factor * h.values("stiffness")))
                                                  for h in case.hinges))


def test_a_design_whose_preload_moves_beyond_its_reach_is_left_to_the_pipeline(mount):
    """Hinges of 1e-3 N/m: a mechanism, whose "equilibrium" of the expansion lies kilometres away; hinges ten
    times softer: the engine moves 14 mm from the prepared preload (T drifts 3e-4 from the pipeline's); 4 times:
    2.3 mm. The first three are refused, alone and together, the last answered; a batch none of whose designs
    solves is no defect."""
    case = mount.case
    soft = [_limp(case, 1e-3), _limp(case, 2e-3), _scaled(case, 0.1), _scaled(case, 0.25)]
    answers = mount.evaluate_many(soft)
    for answer in answers[:3]:
        assert isinstance(answer, OutsideDesignModel) and "from the prepared design's (it follows up to 10 mm" \
            in str(answer), answer
    assert answers[3].result.runs[0].transmissibility.max() > 0
    with pytest.raises(OutsideDesignModel, match="does not bring to rest|moves the engine"):
        mount.evaluate(soft[0])
    assert all(isinstance(answer, OutsideDesignModel) for answer in mount.evaluate_many(soft[:2]))


def test_a_change_it_cannot_follow_is_named(mount):
    case = mount.case
    moved = dataclasses.replace(case.engine, center_of_mass=(-0.5, 0.0, -0.03))
    with pytest.raises(OutsideDesignModel, match="a new preparation"):
        mount.evaluate(dataclasses.replace(case, engine=moved))


def test_study_rows_on_the_prepared_mount_equal_the_pipeline_rows(mount):
    """A Latin-hypercube study over hinge stiffness and loss factor: each row answered by the prepared
    mount equals the same row through Exudyn; a row it does not follow (a link removed) goes through Exudyn."""
    from workbook.studies.parallel import EXUDYN_PATH, NUMPY_PATH, run_rows
    from workbook.studies.parametric import latin_hypercube, row_case, study_cases

    rows = latin_hypercube({"hinge_stiffness": (5e7, 1.6e9), "hinge_loss_factor": (0.0, 0.1)}, 2, seed=3)
    cases = study_cases(mount.case, rows) + [row_case(mount.case, {"removed_link": "rear-middle"}, 2)]
    fast = run_rows(cases, design_model=mount)
    exact = run_rows(cases)
    assert [o.path for o in fast] == [NUMPY_PATH, NUMPY_PATH, EXUDYN_PATH]
    assert {o.path for o in exact} == {EXUDYN_PATH}
    for f, e in zip(fast, exact, strict=True):
        assert f.status == e.status == "ok" and len(f.runs) == len(e.runs) == 2
        for f_run, e_run in zip(f.runs, e.runs, strict=True):
            t_fast = np.array([f_run[f"T {d}"] for d in "xyz"])
            t_exact = np.array([e_run[f"T {d}"] for d in "xyz"])
            assert _normwise(t_fast, t_exact) < 1e-7


def test_design_derivatives_equal_differences_of_evaluations(mount):
    """dT/dp and d|F|/dp by the direct method against central differences of whole evaluations, for
    parameters that reach the preload (stiffness, engine mass), the stress stiffening and the harmonic
    answer only (loss factor, damping)."""
    from workbook.design.sensitivity import design_sensitivity, difference_sensitivity

    values = {"hinge_stiffness/front": 5e7, "hinge_stiffness/rear/axial": 3e7, "hinge_loss_factor/thrust": 0.05,
              "engine_mass": 2300.0, "hinge_damping/all": 200.0}
    direct, differences = design_sensitivity(mount, values), difference_sensitivity(mount, values)
    np.testing.assert_allclose(direct.transmissibility, differences.transmissibility, rtol=1e-12)
    for j in range(len(values)):
        assert _normwise(direct.gradient[..., j], differences.gradient[..., j]) < 1e-5
        assert _normwise(direct.hinge_gradient[..., j], differences.hinge_gradient[..., j]) < 1e-5
    assert np.all(np.abs(direct.gradient).max(axis=(0, 1)) > 0)
    assert direct.to_pandas().shape == (6, 5)


@pytest.mark.parametrize("hinge_damping", [True, False])
def test_springs_of_designs_together_are_the_hinge_laws(hinge_damping):
    """The springs of designs together are each hinge law's own matrices, design by design: hinges
    anisotropic in their frames, isotropic ones, and without hinge damping neither damping nor loss."""
    from workbook.design.linear_mount import designs_springs, hinge_frames
    from workbook.scene.hinge_laws import law_of

    base = reference_case()
    base = dataclasses.replace(base, effects=dataclasses.replace(base.effects, hinge_damping=hinge_damping))
    rng = np.random.default_rng(5)
    designs = []
    for _ in range(3):
        hinges = []
        for k, hinge in enumerate(base.hinges):
            if k % 2:
                hinge = dataclasses.replace(hinge, stiffness=tuple(rng.uniform(1e7, 1e8, 3)),
                                            damping=tuple(rng.uniform(0.0, 500.0, 3)),
                                            loss_factor=tuple(rng.uniform(0.0, 0.1, 3)))
            else:
                hinge = dataclasses.replace(hinge, stiffness=float(rng.uniform(1e7, 1e8)),
                                            damping=float(rng.uniform(0.0, 500.0)), loss_factor=0.05)
            hinges.append(hinge)
        designs.append(dataclasses.replace(base, hinges=tuple(hinges)))
    names = [hinge.name for hinge in base.hinges]
    springs = designs_springs(designs, names, hinge_frames(base))
    for b, case in enumerate(designs):
        for c, hinge in enumerate(case.hinges):
            stiffness, damping, loss = law_of(case, hinge).matrices(case, hinge)
            scale = np.abs(stiffness).max()
            assert np.abs(springs.stiffness[b, c] - stiffness).max() <= 1e-12 * scale
            expected_damping = damping if hinge_damping else np.zeros((3, 3))
            expected_structural = loss @ stiffness if hinge_damping else np.zeros((3, 3))
            assert np.abs(springs.damping[b, c] - expected_damping).max() <= 1e-12 * max(np.abs(damping).max(), 1.0)
            assert np.abs(springs.structural[b, c] - expected_structural).max() <= 1e-12 * scale


def _dense_blocks(matrix, slope, local, weight=1.0):
    """``matrix + weight slope . local`` per block and state, from the dense slope (B, b, b, b)."""
    return matrix + weight * np.einsum("kijl,dkl->dkij", slope, local)


def _full(rest, blocks, size):
    """The blocks (states, B, b, b) of *rest* added into full matrices (states, N, N)."""
    out = np.zeros((len(blocks), size + 1, size + 1))
    for d in range(len(blocks)):
        for k, coordinates in enumerate(rest.coordinates):
            out[d][np.ix_(coordinates, coordinates)] += blocks[d, k]
    return out[:, :size, :size]


def test_sparse_slopes_are_the_dense_expansion(mount):
    """The rest's M, K, D and force change from the sparse slope operators equal the dense expansion of
    the stored slopes and curvature (``M + M' dq``, ``K + K' dq + K'' dq dq / 2``, ``(K + K' dq / 2 +
    K'' dq dq / 6) dq``), for several states at once and one alone."""
    rng = np.random.default_rng(7)
    for item in mount.items.values():
        rest = item.expansion.rest
        size = len(item.expansion.state)
        dq = 1e-3 * rng.standard_normal((3, size))
        local = np.concatenate([dq, np.zeros((3, 1))], axis=1)[:, rest.coordinates]          # (3, B, b)
        padded = np.concatenate([local, np.zeros(local.shape[:-1] + (1,))], axis=-1)
        turned = padded[:, np.arange(len(rest.coordinates))[:, None], rest.turning]           # (3, B, S)
        curvature = np.einsum("kijst,dks,dkt->dkij", rest.stiffness_curvature, turned, turned)
        expected = {
            "mass": _full(rest, _dense_blocks(rest.mass, rest.mass_slope, local), size),
            "damping": _full(rest, _dense_blocks(rest.damping, rest.damping_slope, local), size),
            "stiffness": _full(rest, _dense_blocks(rest.stiffness, rest.stiffness_slope, local) + 0.5 * curvature,
                               size),
        }
        for name, matrices in expected.items():
            got = rest.full(rest.at(name, dq))
            assert np.abs(got - matrices).max() <= 1e-12 * np.abs(matrices).max(), name
            alone = rest.full(rest.at(name, dq[1]))
            assert np.abs(alone - matrices[1]).max() <= 1e-12 * np.abs(matrices).max(), name
        secant = _dense_blocks(rest.stiffness, rest.stiffness_slope, local, 0.5) + curvature / 6.0
        change = np.zeros((3, size + 1))
        np.add.at(change, (np.arange(3)[:, None, None], rest.coordinates[None]),
                  np.einsum("dkij,dkj->dki", secant, local))
        got = rest.force_change(dq)
        assert np.abs(got - change[:, :size]).max() <= 1e-12 * np.abs(change).max()
        assert np.abs(got).max() > 0.0


@pytest.mark.parametrize("varied", ["all", "front"])
def test_chord_is_the_prepared_tangent_with_each_designs_springs(mount, varied):
    """The chord iteration's matrix of designs together, solved by the Woodbury identity, is the prepared
    tangent plus every channel's ``J_c^T (S_c - S_0,c) J_c`` on the prepared Jacobian, summed here channel by
    channel and solved densely; a design whose chord was renewed is solved with its own inverse. Designs that
    change only the front hinges update only their channels' coordinates."""
    rng = np.random.default_rng(3)
    cases = [_design(mount.case, rng) for _ in range(3)]
    if varied == "front":
        cases = [dataclasses.replace(case, hinges=tuple(h if h.name.startswith("front") else base for h, base in
                                                        zip(case.hinges, mount.case.hinges, strict=True)))
                 for case in cases]
    designs = mount._designs(cases)
    moved = [c for c, name in enumerate(mount.channels) if varied == "all" or name.startswith("front")]
    for item in mount.items.values():
        prepared = item.tangent
        size = len(prepared.inverse)
        chord = ChordStiffness.of(prepared, designs.springs)
        assert np.array_equal(chord.changed, (3 * np.array(moved)[:, None] + np.arange(3)).ravel())
        residual = rng.standard_normal((3, size))
        channels = prepared.jacobian.reshape(-1, 3, size)
        expected = []
        for k in range(3):
            matrix = np.linalg.inv(prepared.inverse)
            for jacobian, change in zip(channels, designs.springs.stiffness[k] - prepared.springs, strict=True):
                matrix = matrix + jacobian.T @ change @ jacobian
            expected.append(np.linalg.solve(matrix, residual[k]))
        got = chord.solve(np.arange(3), residual)
        assert np.abs(got - expected).max() <= 1e-9 * np.abs(expected).max()
        own = rng.standard_normal((size, size))
        chord.own[1] = own
        got = chord.solve(np.array([2, 1]), residual[[2, 1]])
        assert np.allclose(got[0], expected[2], rtol=0, atol=1e-9 * np.abs(expected).max())
        assert np.array_equal(got[1], own @ residual[1])


def test_a_design_whose_chord_is_singular_starts_with_its_own_tangent(mount):
    """A design whose chord (the prepared tangent with its springs) is singular is solved with its own
    tangent instead, to the same preload as the others' chords give it."""
    from workbook.design.equilibrium import static_state
    from workbook.design.linear_mount import _state_loads

    rng = np.random.default_rng(5)
    designs = mount._designs([_design(mount.case, rng) for _ in range(3)])
    for item in mount.items.values():
        loads = _state_loads(designs, item, np.zeros((3, len(item.links))))
        start = np.zeros((3, item.size))
        plain = static_state(item.expansion, designs.springs, item.base_force, loads, start,
                             ChordStiffness.of(item.tangent, designs.springs))
        chord = ChordStiffness.of(item.tangent, designs.springs)
        chord.singular[1] = True
        solved = static_state(item.expansion, designs.springs, item.base_force, loads, start, chord)
        assert list(chord.own) == [1] and not solved.failures and not plain.failures
        assert np.abs(solved.dq - plain.dq).max() <= 1e-7 * np.abs(plain.dq).max()


def test_channels_tangent_is_the_derivative_of_their_forces(mount):
    """The channels' tangent stiffness in full coordinates, ``J^T S J`` plus the markers' curvature summed
    onto the bodies' blocks in place, is the derivative of their generalised force ``J^T S d``: central differences
    along random directions, to 1e-6 of its largest entry."""
    rng = np.random.default_rng(11)
    for item in mount.items.values():
        expansion = item.expansion
        channels = expansion.channels
        springs = channel_springs(mount.case, mount.channels).stiffness
        q = expansion.reference + expansion.state
        state = channels.state(q)
        jacobian = channels.jacobian(state)
        blocks = np.zeros((channels.count, 3, channels.count, 3))
        blocks[np.arange(channels.count), :, np.arange(channels.count), :] = springs
        tangent = jacobian.T @ blocks.reshape(3 * channels.count, -1) @ jacobian
        bodies = np.zeros(expansion.rest.stiffness.shape)
        expansion.layout.add_curvature(bodies, channels.curvature(state, springs))
        curvature = expansion.rest.full(bodies)
        assert np.abs(curvature).max() > 1e-6 * np.abs(tangent).max()      # the curvature term counts
        tangent += curvature
        step = 1e-6
        for _ in range(3):
            direction = rng.standard_normal(len(q))
            forces = [channels.force(channels.state(q + sign * step * direction, second=False), springs)
                      for sign in (1.0, -1.0)]
            difference = (forces[0] - forces[1]) / (2 * step)
            assert np.abs(tangent @ direction - difference).max() <= 1e-6 * np.abs(tangent).max()


def test_body_by_body_response_is_the_whole_solve(mount, monkeypatch):
    """Designs together are answered body by body (each body held by its channels to the ground, the channels
    between bodies by the Woodbury identity): their channel forces equal the solve of the whole matrices to
    1e-10 (1e-8 at 0.5 Hz, where the engine is held by its inertia alone), and the designs the body-by-body
    solve does not trust go to that whole solve."""
    import workbook.design.blocks as blocks
    from workbook.design.linear_mount import _solve_item

    rng = np.random.default_rng(13)
    designs = mount._designs([_design(mount.case, rng) for _ in range(4)])
    for item in mount.case.excitations:
        model = _solve_item(designs, mount.items[item.name]).model
        loads = rng.standard_normal(model.mass.shape[:2] + model.mass.shape[-1:]) * (
            model.layout.padding.diagonal(axis1=-2, axis2=-1) == 0)
        # the engine, on no channel to the ground, is held by its inertia alone: at 0.5 Hz barely
        for omega, within in ((2 * np.pi * rng.uniform(20.0, 300.0, 4), 1e-10), (np.full(4, np.pi), 1e-8)):
            forces, singular = model.respond(omega, loads.astype(complex))
            whole, _ = model.dense().respond(omega, model.layout.vector(loads).astype(complex))
            assert not singular.any()
            assert _normwise(forces, whole) < within
        monkeypatch.setattr(blocks, "BACKWARD_ERROR", -1.0)      # every design to the whole solve
        again, _ = model.respond(omega, loads.astype(complex))
        monkeypatch.undo()
        assert np.array_equal(again, whole)
