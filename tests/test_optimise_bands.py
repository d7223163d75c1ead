"""Speed bands and link fatigue on the fast path (workbook.design.bands, workbook.design.link_fatigue): a
single-DOF isolator's worst T over a band in closed form, the reference mount's band worst against a
brute-force grid, its fatigue factors against the Exudyn pipeline's (solve_fatigue), their derivatives
against differences."""
import dataclasses

import numpy as np
import pytest
from conftest import COARSE_ELEMENT_SIZE

from workbook.design import optimise as opt
from workbook.design.bands import band_case, band_peaks, band_text, with_frequencies
from workbook.design.harmonic_model import Harmonic
from workbook.design.linear_mount import ItemSolution, LinearMount
from workbook.design.sensitivity import design_case
from workbook.errors import InputError
from workbook.model.case import HarmonicForce, Sweep
from workbook.model.reference import reference_case


def _isolator(mass: float, stiffness: float, eta: float) -> ItemSolution:
    """A mass on a spring k (1 + i eta) along z, its force the only (pylon) channel: T = sqrt(1 + eta^2) /
    sqrt((1 - r^2)^2 + eta^2), r = f / f_n, highest at r = 1 exactly (sqrt(1 + eta^2) / eta)."""
    z = np.array([[0.0], [0.0], [1.0]])
    model = Harmonic(np.array([[mass]]), np.array([[stiffness]]), np.zeros((1, 1)), np.array([[eta * stiffness]]),
                      (stiffness * z, 0 * z, eta * stiffness * z), None, {(0.0, 0.0, 0.0): z.T})
    return ItemSolution(None, None, None, model)


@pytest.mark.parametrize("band", [(5.0, 20.0), (12.0, 30.0)])
def test_isolator_worst_over_a_band_is_the_closed_form(band):
    """f_n = 8.75 Hz lies between two points of a coarse 7-point grid of 5-20 Hz (the grid alone misses the
    peak by more than a factor of 3); over 12-30 Hz, above it, the worst is at the band's low end."""
    mass, stiffness, eta = 100.0, 3.02e5, 0.02
    f_n = np.sqrt(stiffness / mass) / (2 * np.pi)
    template = HarmonicForce("rotor", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 1.0, frequency_hz=1.0)
    sweep = Sweep.band("rotor", template, *band, 7, spacing="linear")
    solution = _isolator(mass, stiffness, eta)

    def t(f):
        r2 = (np.asarray(f) / f_n) ** 2
        return np.sqrt((1 + eta ** 2) / ((1 - r2) ** 2 + eta ** 2))

    grid = np.array([[0.0, 0.0, t(f)] for f in sweep.frequencies_hz])
    peak = band_peaks(sweep, solution, [0], grid)[2]
    if band[0] < f_n < band[1]:
        assert peak == pytest.approx(f_n, rel=1e-5)
        assert t(peak) == pytest.approx(np.sqrt(1 + eta ** 2) / eta, rel=1e-8)
        assert grid[:, 2].max() < t(peak) / 3
    else:
        assert peak == band[0]


def test_band_texts_and_cases():
    assert band_text("LP rotor=40:62") == ("LP rotor", (40.0, 62.0))
    for bad in ("LP rotor=62:40", "LP rotor", "=1:2", "LP rotor=a:b"):
        with pytest.raises(InputError, match="EXCITATION=LOW:HIGH"):
            band_text(bad)
    case = reference_case(element_size=COARSE_ELEMENT_SIZE)
    banded = band_case(case, {"LP rotor": (40.0, 62.0)}, 5)
    sweep = banded.excitations[0]
    assert isinstance(sweep, Sweep) and sweep.name == "LP rotor" and sweep.frequencies_hz == (40.0, 45.5, 51.0, 56.5, 62.0)
    assert banded.excitations[1] == case.excitations[1]
    assert with_frequencies(banded, {"LP rotor": [47.25, 51.0]}).excitations[0].frequencies_hz == \
        (40.0, 45.5, 47.25, 51.0, 56.5, 62.0)
    with pytest.raises(InputError, match="'fan'.*LP rotor, HP rotor"):
        band_case(case, {"fan": (40.0, 62.0)})


BANDS = {"LP rotor": (40.0, 62.0), "HP rotor": (200.0, 260.0)}


@pytest.fixture(scope="module")
def band_mount(cache_dir):
    """The coarse reference mount with both rotors over their bands (9 points each), prepared."""
    return LinearMount.prepare(band_case(reference_case(element_size=COARSE_ELEMENT_SIZE), BANDS, 9))


@pytest.mark.slow
def test_band_worst_is_a_brute_force_grids_and_its_gradient_a_difference(band_mount):
    """At hinge stiffness 4e8 N/m a mounted mode sits in the LP band: the worst T per rotor and direction over
    9 points and the peaks between them is the largest of a 401-point evaluation of the band: never below it,
    and above it by at most what the brute-force grid misses of a peak 0.0275 Hz from its nearest point:
    2 (df / f)^2 / eta^2 = 2e-4 at 60 Hz for the mode's loss factor eta of about 0.045 (bound 5e-4); its
    gradient is the central difference of the worst."""
    variables = [opt.variable("hinge_stiffness/all", 1e7, 1e9)]
    problem = opt._Problem(band_mount, variables, [])

    def worst(k):
        x = np.array([variables[0].scaled(k)])
        point = problem.answer({"hinge_stiffness/all": k}, x, np.array([variables[0].slope(x[0])]))
        return point, opt._worst(point.rows, point.t)

    point, found = worst(4e8)
    case = design_case(band_mount, {"hinge_stiffness/all": 4e8})
    fine = dataclasses.replace(case, excitations=tuple(dataclasses.replace(
        e, frequencies_hz=tuple(np.linspace(*BANDS[e.name], 401))) for e in case.excitations))
    runs = band_mount.evaluate(fine).result.runs
    for k, name in enumerate(BANDS):
        brute = np.array([run.transmissibility for run in runs[401 * k:401 * (k + 1)]]).max(axis=0)
        values = np.array([found[name, d] for d in "xyz"])
        assert np.all(values >= brute * (1 - 1e-9)) and np.all(values <= brute * (1 + 5e-4))
    assert found["LP rotor", "z"] > 10                  # a resonance in the band
    # the peaks' gradient (held frequency) against the central difference of the refined worst
    step = 1e-4
    x = variables[0].scaled(4e8)
    sides = [worst(variables[0].value(x + s))[1] for s in (step, -step)]
    rows = np.array(point.rows)
    for name in BANDS:
        for j, d in enumerate("xyz"):
            at = np.flatnonzero(rows == name)[np.argmax(point.t[rows == name, j])]
            assert point.dt[at, j, 0] == pytest.approx((sides[0][name, d] - sides[1][name, d]) / (2 * step),
                                                       rel=2e-3, abs=1e-9)


def _fast_fatigue(mount, values):
    """Per excitation item, the lowest Goodman factor of each link over its points, with its gradient."""
    from workbook.design.linear_mount import points_of
    from workbook.design.link_fatigue import link_fatigue_factors
    from workbook.design.sensitivity import design_sensitivity

    s = design_sensitivity(mount, values)
    found, row = {}, 0
    for item, solution, changes in zip(mount.case.excitations, s.solutions, s.changes, strict=True):
        count = len(points_of(item))
        d_state = np.array([d for _, d in changes]).T
        found[item.name] = {f.link: f for f in link_fatigue_factors(solution, d_state, s.motions[row:row + count])}
        row += count
    return found


@pytest.mark.slow
@pytest.mark.parametrize("stiffness", [2e7, 4e8])
def test_fatigue_factors_are_the_pipelines(band_mount, stiffness):
    """The fast path's lowest Goodman factor of every link over each band equals solve_fatigue's (Exudyn's
    preload and harmonic solve): to 1e-7 (its Newton tolerance) at the prepared design (2e7 N/m), and to the expansion's first-order
    accuracy in the state's change, 2e-4, at hinges 20 times stiffer with a mounted mode in the LP band; its
    derivative is the central difference of the factor."""
    from workbook.solve.fatigue import solve_fatigue

    values = {"hinge_stiffness/all": stiffness}
    fast = _fast_fatigue(band_mount, values)
    slow = solve_fatigue(design_case(band_mount, values))
    for item, links in fast.items():
        points = [e for e in slow.excitations if e.excitation.startswith(f"{item} @ ")]
        assert len(points) == 9
        for name, factor in links.items():
            expected = min(point.links[name].goodman for point in points)
            assert factor.goodman == pytest.approx(expected, rel=1e-7 if stiffness == 2e7 else 2e-4), (item, name)
    step = 1e-4 * stiffness
    sides = [_fast_fatigue(band_mount, {"hinge_stiffness/all": stiffness + s}) for s in (step, -step)]
    for item, links in fast.items():
        for name, factor in links.items():
            difference = (sides[0][item][name].goodman - sides[1][item][name].goodman) / (2 * step)
            assert factor.gradient[0] == pytest.approx(difference, rel=1e-3, abs=1e-6 * factor.goodman / stiffness)


@pytest.mark.slow
def test_link_margins_are_the_load_cases(cache_dir):
    """Under a limit load (pull-up 2.5 g) and a fail-safe one (take-off without rear-middle, 10 mm of engine
    displacement), the fast path's link margins equal solve_load_cases': to 1e-9 at the prepared design, and
    at hinges 1.5 times stiffer to the expansion's first-order accuracy in the state's change (3.4 mm there:
    the peak stresses within 2e-3 of the largest); their derivative is the central difference of the margin."""
    from workbook.design.link_margins import link_margins, load_case_mounts
    from workbook.design.sensitivity import design_sensitivity
    from workbook.model.load_cases import reference_load_cases
    from workbook.solve.load_cases import solve_load_cases

    chosen = [lc for lc in reference_load_cases() if lc.name in ("pull-up 2.5 g", "take-off, rear-middle failed")]
    case = dataclasses.replace(reference_case(element_size=COARSE_ELEMENT_SIZE), load_cases=tuple(chosen))
    mounts = load_case_mounts(case)

    def fast(mount, load_case, stiffness):
        s = design_sensitivity(mount, {"hinge_stiffness/all": stiffness})
        return {m.link: m for m in link_margins(s.solutions[0], np.array([d for _, d in s.changes[0]]).T,
                                                load_case.factor_of_safety)}

    for stiffness in (2e7, 3e7):
        design = dataclasses.replace(case, hinges=design_case(mounts[0][1], {"hinge_stiffness/all": stiffness}).hinges)
        for (load_case, mount), result in zip(mounts, solve_load_cases(design), strict=True):
            found = fast(mount, load_case, stiffness)
            assert set(found) == {name for name, s in result.links.items() if s.yield_margin is not None}
            expected = {name: min(result.links[name].yield_margin, result.links[name].ultimate_margin)
                        for name in found}
            if stiffness == 2e7:
                for name, margin in found.items():
                    assert margin.margin == pytest.approx(expected[name], rel=1e-9), (load_case.name, name)
                continue
            # the peak stress per unit strength, 1 / (1 + margin)
            largest = max(1 / (1 + value) for value in expected.values())
            for name, margin in found.items():
                assert 1 / (1 + margin.margin) == pytest.approx(1 / (1 + expected[name]), abs=2e-3 * largest)
            sides = [fast(mount, load_case, stiffness * (1 + s)) for s in (1e-4, -1e-4)]
            for name, margin in found.items():
                difference = (sides[0][name].margin - sides[1][name].margin) / (2e-4 * stiffness)
                assert margin.gradient[0] == pytest.approx(difference, rel=1e-3, abs=1e-12)
