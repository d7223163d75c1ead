"""Craig-Bampton reduction of the test link against its full FE model."""
import numpy as np
import pytest

from flexbodies import STEEL, CraigBamptonBasis, LinkGeometry, LinkModel, build_fe_model, craig_bampton, decide_modes, elastic_modes
from flexbodies.eigen import factorize, free_dofs
from flexbodies.frequencies import free_free_frequencies, mounted_frequencies
from flexbodies.reduction import couple
from flexbodies.validation import harmonic_response_check

#: The test link of the measured-facts sheet: steel, eyes 0.30 m apart.
TEST_LINK = LinkGeometry(
    length=0.30, eye_outer_radius=0.030, bore_radius=0.015, thickness=0.025,
    shank_width=0.040, shank_thickness=0.025,
)


@pytest.fixture(scope="module")
def fe_model():
    fe, _ = build_fe_model(LinkModel(geometry=TEST_LINK, material=STEEL))
    return fe


@pytest.fixture(scope="module", params=["RBE2", pytest.param("RBE3", marks=pytest.mark.slow)])
def coupled(request, fe_model):
    return couple(fe_model, request.param)


def _flexibility_at_b(stiffness, clamped, loaded):
    """6x6 flexibility of the loaded DOF with the clamped DOF held."""
    keep = free_dofs(stiffness.shape[0], clamped)
    positions = np.searchsorted(keep, loaded)
    loads = np.zeros((len(keep), len(loaded)))
    loads[positions, np.arange(len(loaded))] = 1.0
    return factorize(stiffness[keep][:, keep]).solve(loads)[positions]


#: Static exactness holds to round-off. RBE3's elimination of six bore DOF in
#: favour of the master couples every bore DOF and leaves a measured floor of
#: about 7e-8 (iterative refinement does not lower it); RBE2 reaches 1e-10.
STATIC_TOLERANCE = {"RBE2": 1e-8, "RBE3": 1e-6}


def test_static_stiffness_between_interfaces_is_exact(coupled):
    masters = coupled.coupling.master_dofs
    full = _flexibility_at_b(coupled.stiffness, masters[0], masters[1])
    cb = craig_bampton(coupled.stiffness, coupled.mass, coupled.coupling.boundary, count=0)
    K_r = cb.project(coupled.stiffness)
    reduced = np.linalg.inv(K_r[6:12, 6:12])  # eye A's static modes held
    scale = np.sqrt(np.outer(np.diag(full), np.diag(full)))  # unit-free: m/N and rad/(N m) mixed
    assert np.max(np.abs(reduced - full) / scale) <= STATIC_TOLERANCE[coupled.coupling.kind]
    # the axial stiffness is that of the 40x25 mm steel shank over 0.30 m, give or take the eyes
    axial = 1.0 / full[0, 0]
    bar = STEEL.youngs_modulus * 0.040 * 0.025 / 0.30
    assert 0.7 * bar < axial < 1.3 * bar


def test_rbe3_is_softer_than_rbe2(fe_model):
    axial = {}
    for kind in ("RBE2", "RBE3"):
        c = couple(fe_model, kind)
        masters = c.coupling.master_dofs
        axial[kind] = 1.0 / _flexibility_at_b(c.stiffness, masters[0], masters[1])[0, 0]
    assert axial["RBE3"] < axial["RBE2"]


@pytest.mark.slow
def test_craig_bampton_frequencies_converge_to_full_fe(coupled):
    full = free_free_frequencies(coupled.stiffness, coupled.mass, count=3)
    largest = craig_bampton(coupled.stiffness, coupled.mass, coupled.coupling.boundary, count=20)
    errors = []
    for count in (0, 2, 6, 12, 20):  # the lowest `count` fixed-interface modes of the same solve
        cb = CraigBamptonBasis(largest.vectors[:, : 12 + count], largest.boundary, largest.fixed_interface_hz[:count])
        _, reduced = elastic_modes(cb, coupled.stiffness, coupled.mass)
        errors.append((reduced[:3] - full) / full)
    errors = np.array(errors)
    assert np.all(errors > -1e-9), "a Ritz basis cannot undershoot the full model"
    assert np.all(np.diff(errors, axis=0) <= 1e-9), "adding modes must not make a frequency worse"
    assert np.all(errors[3] < 0.005), f"12 modes: errors {errors[3]}"
    assert errors[0].max() > 0.05, "static modes alone should be far off in free-free frequency"


def test_mounted_fundamental_of_the_test_link(fe_model):
    # Measured in the prototypes: 641 Hz pinned-pinned at spherical bearings, spin restrained.
    c = couple(fe_model, "RBE2")
    f1 = mounted_frequencies(c.stiffness, c.mass, c.coupling)[0]
    assert f1 == pytest.approx(641.0, rel=0.03)
    assert decide_modes("auto", f1, 59.0).count == 0
    assert decide_modes("auto", f1, 248.5).cutoff_hz == pytest.approx(994.0)


@pytest.mark.parametrize("direction", ["axial", "in-plane"])
def test_static_modes_keep_the_response_below_a_quarter_of_f1(fe_model, direction):
    check = harmonic_response_check(couple(fe_model, "RBE2"), direction, ratios=(0.05, 0.1, 0.25))
    assert np.all(check.static_modes_error < 0.005), check.rows()
    # without inertia the same spring is about 6 % off at f1/4 (1/16 of the dynamic amplification)
    assert 0.04 < check.quasi_static_error[-1] < 0.08, check.rows()
    assert np.all(check.static_modes_error < check.quasi_static_error)


#: Agreement of the reference frequencies from one factorisation with the independent solves. RBE3's
#: shifted free-free factorisation leaves eigenvectors with residuals of ~1e-3 and frequencies up to
#: 1.8e-6 high (measured; their Rayleigh quotients agree with the one-factorisation frequencies to 1e-9).
FREQUENCY_TOLERANCE = {"RBE2": 1e-6, "RBE3": 3e-6}


@pytest.mark.slow
def test_one_factorisation_gives_the_frequencies_of_the_independent_solves(coupled):
    from flexbodies.interior import InteriorSolver
    from flexbodies.reduction import reference_frequencies

    solver = InteriorSolver(coupled.stiffness, coupled.mass, coupled.coupling)
    independent = reference_frequencies(coupled)  # each with a factorisation of its own
    # with the fixed-interface modes made beside them, every solve of the three Lanczos runs shared
    for name, values in solver.reference_frequencies(fixed_modes=6).items():
        np.testing.assert_allclose(values, independent[name], rtol=FREQUENCY_TOLERANCE[coupled.coupling.kind],
                                   err_msg=name)
    fixed_hz, fixed = solver.fixed_interface_modes(6)
    cb = craig_bampton(coupled.stiffness, coupled.mass, coupled.coupling.boundary, count=6)
    np.testing.assert_allclose(fixed_hz, cb.fixed_interface_hz, rtol=1e-9)
    np.testing.assert_allclose(solver.static_modes(), cb.vectors[:, :12], atol=1e-9)
    # each fixed-interface mode is mass-normalised and holds every master DOF
    np.testing.assert_allclose(np.einsum("ij,ij->j", fixed, coupled.mass @ fixed), 1.0, rtol=1e-9)
    assert not fixed[coupled.coupling.boundary].any()


def test_solves_made_together_are_those_of_each_party_alone():
    """Threads' single solves made as one block solve per round: each party gets its own answer,
    whichever number of solves each asks for; a party that fails does not hold the others up."""
    import scipy.sparse as sp

    from flexbodies.eigen import solved_together
    from flexbodies.errors import LinkModelError

    n = 300
    rng = np.random.default_rng(1)
    a = sp.random(n, n, density=0.02, random_state=1)
    matrix = (a @ a.T + sp.identity(n)).tocsc()
    factor = factorize(matrix)
    loads = rng.standard_normal((3, 5, n))

    def asking(party, count):
        return lambda solver: [solver.solve_plain(load) for load in loads[party, :count]]

    def failing(solver):
        solver.solve_plain(loads[2, 0])
        raise LinkModelError("a party that fails")

    for party, answers in enumerate(solved_together(factor, [asking(0, 5), asking(1, 2), asking(2, 4)])):
        assert len(answers) == (5, 2, 4)[party]
        for answer, load in zip(answers, loads[party], strict=False):
            np.testing.assert_allclose(answer, factor.solve_plain(load), rtol=1e-12, atol=1e-12 * np.abs(answer).max())
    with pytest.raises(LinkModelError, match="fails"):
        solved_together(factor, [asking(0, 5), failing, asking(1, 3)])


def test_a_block_solve_that_fails_reaches_every_party_of_its_round():
    """A factorisation whose block solve raises (say, out of memory) makes every party of that round raise,
    instead of leaving the others waiting for answers that never come."""
    import threading

    import scipy.sparse as sp

    from flexbodies.eigen import solved_together

    factor = factorize(sp.identity(50, format="csc") * 2.0)

    class Failing:
        shape = factor.shape

        def solve_plain(self, rhs):
            if rhs.ndim == 2:
                raise MemoryError("no room for the block")
            return factor.solve_plain(rhs)

    outcome: list = []

    def run():
        try:
            solved_together(Failing(), [lambda solver: solver.solve_plain(np.ones(50))] * 3)
        except MemoryError as error:
            outcome.append(error)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(timeout=30)
    assert not thread.is_alive() and len(outcome) == 1


@pytest.mark.slow
def test_one_reduction_serves_every_excitation():
    from flexbodies import reduce_link, reduce_link_set

    model = LinkModel(geometry=TEST_LINK, material=STEEL)
    low, high = reduce_link_set(model, "auto", [59.0, 248.5], use_cache=False)
    assert low.n_fixed_interface == 0 and "59 Hz" in low.decision.reason
    kept = high.frequencies["fixed_interface_hz"]
    assert kept.size >= 1 and kept[-1] >= 4 * 248.5 and np.all(kept[:-1] < 4 * 248.5), kept
    # the same links as reduced one excitation at a time
    alone = reduce_link(model, "auto", 248.5, use_cache=False)
    np.testing.assert_allclose(high.frequencies["reduced_hz"], alone.frequencies["reduced_hz"], rtol=1e-9)
    np.testing.assert_allclose(high.ffrf["stiffnessMatrixReduced"], alone.ffrf["stiffnessMatrixReduced"], rtol=1e-7,
                               atol=1e-9 * np.abs(alone.ffrf["stiffnessMatrixReduced"]).max())
    # the static reduction is the first block of the one with modes: its free-free frequencies lie above
    assert np.all(low.frequencies["reduced_hz"][:3] > high.frequencies["reduced_hz"][:3])


def test_invariants_are_exudyns(fe_model):
    """The floating-frame invariants equal those of Exudyn's own ObjectFFRFreducedOrderInterface."""
    from flexbodies.invariants import ffrf_invariants
    from flexbodies.reduced import FFRF_KEYS
    from flexbodies.validation import exudyn_invariants

    coupled = couple(fe_model, "RBE2")
    cb = craig_bampton(coupled.stiffness, coupled.mass, coupled.coupling.boundary, count=4)
    modes_q, _ = elastic_modes(cb, coupled.stiffness, coupled.mass)
    basis = coupled.coupling.transform @ modes_q
    ours = ffrf_invariants(fe_model.nodes, fe_model.mass, fe_model.stiffness, basis)
    exudyns = exudyn_invariants(fe_model.nodes, fe_model.mass, fe_model.stiffness, basis, fe_model.surface_triangles)
    # round-off scale: the elastic modes carry no momentum, so mPhitTPsi is ~1e-16 against sqrt(m) of a
    # mass-normalised mode's products
    scale = np.sqrt(float(exudyns["totalMass"]))
    for key in FFRF_KEYS:
        assert ours[key].shape == exudyns[key].shape, key
        np.testing.assert_allclose(ours[key], exudyns[key], rtol=0, atol=1e-12 * max(np.abs(exudyns[key]).max(), scale),
                                   err_msg=key)
    for key in ("massMatrixReduced", "stiffnessMatrixReduced"):
        assert np.array_equal(ours[key] == 0, exudyns[key] == 0), f"{key}: other entries rounded to zero"
