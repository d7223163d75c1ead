"""The design optimiser (workbook.design.optimise) against closed forms, a brute-force grid and the pipeline."""
import dataclasses
import json

import numpy as np
import pytest
from conftest import COARSE_ELEMENT_SIZE

from workbook.design import optimise as opt
from workbook.design.linear_mount import LinearMount
from workbook.design.sensitivity import design_case
from workbook.errors import InfeasibleProblem, InputError, UnwritableCase
from workbook.model.reference import reference_case

G = 9.81


class _Isolator:
    """A mass m on a spring k with loss factor eta, excited at w: T = sqrt((1 + eta^2) / ((1 - r^2)^2 + eta^2)),
    r = w / sqrt(k / m), static deflection m g / k; the optimiser's scaled problem on it (variable: log k)."""

    def __init__(self, mass, omega, eta, deflection, low, high):
        self.mass, self.omega, self.eta, self.deflection = mass, omega, eta, deflection
        self.variable = opt.Variable("hinge_stiffness", low, high)

    def point(self, x):
        x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
        k = self.variable.value(float(x[0]))
        slope = self.variable.slope(float(x[0]))
        r2 = self.omega ** 2 * self.mass / k
        denominator = (1 - r2) ** 2 + self.eta ** 2
        t = np.sqrt((1 + self.eta ** 2) / denominator)
        dt_dk = -0.5 * t / denominator * 2 * (1 - r2) * r2 / k       # d denominator / dk = 2 (1 - r2) r2 / k
        sag = self.mass * G / k
        slack = (self.deflection * (1 - opt.MARGIN) - sag) / self.deflection
        return opt._Point(x, {"k": k}, None, np.array([[t, t, t]]), np.full((1, 3, 1), dt_dk * slope),
                          [("sag", sag, "")], np.array([slack]), np.array([[sag / k / self.deflection * slope]]))

    def violation(self, point):
        return float(max(0.0, -point.g.min()))


def test_single_dof_isolator_optimum_is_on_the_static_deflection_limit():
    """Above resonance a softer spring isolates better, so the best stiffness is the softest the
    deflection limit allows: k* = m g / delta (closed form), reached from either end of the range."""
    isolator = _Isolator(mass=3000.0, omega=2 * np.pi * 59.0, eta=0.05, deflection=0.004, low=1e6, high=1e9)
    expected = 3000.0 * G / 0.004
    for x0 in (0.05, 0.6):
        history = []
        x, message, _ = opt._run_start(isolator, "worst", np.ones((1, 3)), np.array([x0]), 0, history, 60)
        k = isolator.variable.value(float(x[0]))
        assert k == pytest.approx(expected, rel=1e-5), message
        assert isolator.point(x).measures[0][1] <= 0.004          # never beyond the stated limit
        assert history[-1]["violation"] <= opt.FEASIBLE


def test_constraint_and_variable_texts():
    assert opt.constraint("sag <= 0.005") == opt.Constraint("sag", 0.005)
    assert opt.constraint("modes_outside=50:70") == opt.Constraint("modes_outside", (50.0, 70.0))
    assert opt.constraint("displacement<=2e-3").text == "displacement<=0.002"
    assert opt.constraint("fatigue >= 2").text == "fatigue>=2" and opt.constraint("margin>=0").limit == 0.0
    for bad in ("sag<0.005", "modes_outside=70:50", "weight<=3", "sag<=-1", "fatigue>=0", "margin>=-1", "fatigue<=2"):
        with pytest.raises(InputError, match="expected"):
            opt.constraint(bad)
    with pytest.raises(InputError, match="needs a new preparation"):
        opt.variable("clearance", 0.0, 1e-4)
    with pytest.raises(InputError, match="factor on the links' section > 0"):
        opt.variable("section_scale", 0.0, 1.2)
    assert not opt.variable("section_scale", 0.8, 1.2).log
    with pytest.raises(InputError, match="LOW < HIGH"):
        opt.variable("hinge_stiffness/front", 2e8, 1e7)
    v = opt.variable("hinge_stiffness/front/axial", 1e6, 1e8)
    assert v.log and v.value(0.5) == pytest.approx(1e7) and v.scaled(1e7) == pytest.approx(0.5)
    assert not opt.variable("hinge_loss_factor/thrust", 0.0, 0.2).log


@pytest.fixture(scope="module")
def mount(cache_dir):
    """The reference mount with coarse link meshes, prepared (the checks compare methods on one model)."""
    return LinearMount.prepare(reference_case(element_size=COARSE_ELEMENT_SIZE))


@pytest.mark.slow
def test_engine_static_and_mounted_modes_are_the_pipelines(mount):
    """The fast path's engine displacement is Exudyn's engine node after the preload, its mounted modes the
    pipeline's (a design 1.5 times stiffer than the prepared one, so that nothing is carried over)."""
    from workbook.solve.modes import mounted_modes
    from workbook.solve.pipeline import prepare

    values = {"hinge_stiffness/all": 3e7}
    case = design_case(mount, values)
    problem = opt._Problem(mount, [opt.variable("hinge_stiffness/all", 1e7, 1e8)], [opt.constraint("modes_outside=1:2")])
    point = problem.answer(values, np.zeros(1), np.ones(1))
    # Exudyn's preload solved tighter than its default, so that its own tolerance does not count
    tight = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, equilibrium_tolerance=1e-10))
    prepared = prepare(tight, case.excitations[0])
    with prepared.scene as scene:
        import exudyn as exu

        exact = np.array(scene.mbs.GetNodeOutput(scene.engine.node, exu.OutputVariableType.Coordinates))
    # the expansion is exact to first order in the state's change from the prepared state (0.6 mm here):
    # docs/design-evaluation.md measures about 1e-5 for such a design
    np.testing.assert_allclose(point.answer.engine_static[case.excitations[0].name], exact, rtol=0,
                               atol=2e-5 * np.abs(exact).max())
    pipeline = sorted(m.frequency_hz for m in mounted_modes(prepared.modes))
    solution = mount.solve_items(case)[0]
    fast, _ = opt._mounted_modes(solution, [])
    np.testing.assert_allclose(sorted(fast), pipeline, rtol=2e-3)     # the pipeline's modes include gyroscopics


@pytest.mark.slow
def test_two_variables_optimum_beats_a_brute_force_grid(mount):
    """Front and rear hinge stiffness, worst T with a displacement limit: the optimum is at least as good as
    the best feasible point of a 13 x 13 grid of evaluations and meets the limit."""
    ranges = {"hinge_stiffness/front": (8e6, 6e7), "hinge_stiffness/rear": (8e6, 6e7)}
    limit = 0.0022
    best = np.inf
    for front in np.geomspace(*ranges["hinge_stiffness/front"], 13):
        for rear in np.geomspace(*ranges["hinge_stiffness/rear"], 13):
            answer = mount.evaluate(design_case(mount, {"hinge_stiffness/front": front, "hinge_stiffness/rear": rear}))
            if max(np.linalg.norm(s[:3]) for s in answer.engine_static.values()) <= limit:
                best = min(best, 20 * np.log10(max(run.transmissibility.max() for run in answer.result.runs)))
    result = opt.optimise(mount.case, ranges, constraints=[f"displacement<={limit}"], starts=2, mount=mount)
    table = result.table
    assert table.loc[("objective", "worst T (dB)"), "after"] <= best + 1e-3
    displacement = table.xs("constraint")
    assert (displacement["after"] <= limit).all()
    assert (result.history.groupby("start")["violation"].last() <= opt.FEASIBLE).all()
    # the written case through the pipeline is what the table reports
    t = np.array([run.transmissibility for run in result.result.runs])
    np.testing.assert_allclose(table.xs("T")["after"].to_numpy(), t.reshape(-1), rtol=0, atol=0)
    assert result.fast_difference < 1e-6 * t.max()


@pytest.mark.slow
def test_infeasible_problem_names_the_conflicting_constraint(mount):
    with pytest.raises(InfeasibleProblem, match=r"displacement<=0.0005.*hinge_stiffness/all at its high end") as error:
        opt.optimise(mount.case, {"hinge_stiffness/all": (1e7, 5e7)}, constraints=["displacement<=0.0005"],
                     starts=1, mount=mount)
    assert error.value.exit_code == 2 and len(error.value.violated) == 2      # both excitation items


@pytest.mark.slow
def test_optimise_command_writes_a_case_mountwb_run_reproduces(mount, tmp_path, capsys):
    from openpyxl import load_workbook

    from workbook.cli.main import main
    from workbook.excel.optimise_sheet import OptimiseSheet
    from workbook.excel.reader import read_workbook
    from workbook.model.codec import to_json
    from workbook.studies.parametric import parameter_value

    out, case = tmp_path / "out", tmp_path / "coarse.json"
    case.write_text(to_json(mount.case))
    assert main(["optimise", str(case), "--vary", "hinge_loss_factor/all=0.01:0.2", "--constraint", "displacement<=0.003",
                 "--starts", "1", "--pareto", "worst/LP rotor,worst/HP rotor", "--population", "6",
                 "--generations", "2", "--output", str(out), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert {"optimum.json", "optimum.xlsx", "table.csv", "history.csv", "pareto.csv", "convergence.png"} <= \
        {p.name for p in out.iterdir()}
    assert main(["run", str(out / "optimum.json"), "--json"]) == 0
    runs = json.loads(capsys.readouterr().out)["runs"]
    reported = {row["name"]: row["after"] for row in report["table"] if row["kind"] == "T"}
    for run in runs:
        for d in "xyz":
            assert reported[f"{run['name']} {d}"] == pytest.approx(run["pylon"][d]["transmissibility"], rel=1e-6)
    # optimum.xlsx runs each excitation once, as the optimum was run: its results written into it give that T too
    assert main(["run", str(out / "optimum.xlsx"), "--no-progress"]) == 0
    capsys.readouterr()
    rows = list(load_workbook(out / "optimum.xlsx")["Result efficiency"].iter_rows(min_row=3, values_only=True))
    assert sorted(f"{row[0]} {row[3]}" for row in rows) == sorted(reported)
    for row in rows:
        assert reported[f"{row[0]} {row[3]}"] == pytest.approx(row[5], rel=1e-6)
    # the optimum's Optimise sheet is the problem solved, the optimum its starting design; --pareto it cannot hold
    book = read_workbook(out / "optimum.xlsx")
    assert book.optimise == OptimiseSheet({"hinge_loss_factor/all": (0.01, 0.2)},
                                          (opt.Constraint("displacement", 0.003),), {}, "worst", 1)
    # as the workbook stores it: to the last digit or so
    assert parameter_value(book.case, "hinge_loss_factor/all") == pytest.approx(
        report["values"]["hinge_loss_factor/all"], rel=1e-14)
    assert report["not_held"] == ["--pareto worst/LP rotor,worst/HP rotor"]
    # optimised again from it: the same problem, started at the optimum (its objective before is the one after)
    assert main(["optimise", str(out / "optimum.xlsx"), "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert list(again["values"]) == ["hinge_loss_factor/all"] and len(again["starts"]) == 1
    objective = {row["kind"]: row for row in report["table"]}["objective"]
    assert {row["kind"]: row for row in again["table"]}["objective"]["before"] == pytest.approx(objective["after"],
                                                                                                rel=1e-9)
    assert main(["optimise", "--vary", "clearance=0:1e-4"]) == 2
    assert main(["optimise", str(case), "--vary", "section_scale=0.9:1.1", "--pareto"]) == 2


def test_grid_minimum_finds_the_least_of_unimodal_sequences_asking_each_point_once():
    """Golden-section search on a grid's indices against the brute-force minimum of random unimodal
    sequences; a 21-point grid (0.8:1.2 in steps of 0.02) costs at most 8 points."""
    from workbook.design.section_search import grid_minimum, section_grid

    rng = np.random.default_rng(1)
    for count in range(1, 40):
        for _ in range(20):
            least = int(rng.integers(0, count))
            sequence = np.concatenate([np.sort(rng.random(least))[::-1] + 1, [0.5],
                                       np.sort(rng.random(count - least - 1)) + 1])
            asked: list = []
            assert grid_minimum(count, lambda i, asked=asked, sequence=sequence: asked.append(i) or sequence[i]) == least
            assert len(asked) == len(set(asked)) and (count != 21 or len(asked) <= 8)
    np.testing.assert_allclose(section_grid(0.8, 1.2), np.linspace(0.8, 1.2, 21))
    np.testing.assert_allclose(section_grid(0.8, 1.2, 0.15), np.linspace(0.8, 1.2, 4))    # steps of at most 0.15
    with pytest.raises(InputError, match="positive step"):
        section_grid(0.8, 1.2, 0.0)


@pytest.mark.slow
def test_section_scale_is_the_best_of_a_brute_force_over_its_grid(mount):
    """section_scale 0.8:1.0 in steps of 0.1 with the hinge stiffness on the fast path and a displacement limit:
    the chosen scale is the best of the fast variable's optimum at each of the three scales (each optimised
    alone), the limit is met, and the cost of each scale is reported."""
    from workbook.studies.parametric import parameter

    fast, limit = {"hinge_stiffness/all": (1e7, 5e7)}, 0.002
    result = opt.optimise(mount.case, {"section_scale": (0.8, 1.0), **fast}, constraints=[f"displacement<={limit}"],
                          starts=1, mount=mount, section_step=0.1)
    brute = {scale: opt.optimise(parameter("section_scale").apply(mount.case, scale), fast, starts=1,
                                 constraints=[f"displacement<={limit}"]).table.loc[("objective", "worst T (dB)"), "after"]
             for scale in (0.8, 0.9, 1.0)}
    assert result.values["section_scale"] == min(brute, key=brute.get)
    assert result.table.loc[("objective", "worst T (dB)"), "after"] == pytest.approx(min(brute.values()), abs=1e-6)
    assert (result.table.xs("constraint")["after"] <= limit).all()
    sections = result.sections.set_index("section_scale")
    assert sorted(sections.index) == [0.8, 0.9, 1.0]
    assert (sections.loc[[0.8, 0.9], "distinct link reductions"] > 0).all()
    assert (sections["preparation s"] >= sections["reduction s"]).all()
    with pytest.raises(InfeasibleProblem, match=r"section_scale (0.9|1) \(the least violating of the 2 scales"):
        opt.optimise(mount.case, {"section_scale": (0.9, 1.0), **fast}, constraints=["displacement<=0.0005"],
                     starts=1, mount=mount, section_step=0.1)


def test_the_problem_of_an_optimum_with_a_section_scale_ranges_over_the_same_sections():
    """The optimum's links are the chosen scale's: its problem's section_scale range, on them, gives the sections
    of the range solved on the case's own links; the other ranges, the constraints and starts are the problem's.
    An optimum over speed bands has no case workbook."""
    from workbook.studies.parametric import parameter

    section, case = parameter("section_scale"), reference_case()
    optimum = section.apply(case, 0.9)
    ranges = {"section_scale": (0.8, 1.2), "hinge_stiffness/all": (1e7, 5e7)}
    rules = [opt.constraint("displacement<=0.002")]
    result = opt.OptimisationResult(optimum, case, [opt.variable(name, *bounds) for name, bounds in ranges.items()],
                                    rules, "weighted", {"hinge_stiffness/all": 2e7, "section_scale": 0.9}, None,
                                    None, [], None, 0.0, 0, 0.0, asked_starts=2)
    problem = result.problem()
    assert problem.variables["hinge_stiffness/all"] == (1e7, 5e7)
    assert (problem.constraints, problem.bands, problem.objective, problem.starts) == (tuple(rules), {}, "weighted", 2)
    for relative, absolute in zip(problem.variables["section_scale"], ranges["section_scale"], strict=True):
        for mine, theirs in zip(section.apply(optimum, relative).links, section.apply(case, absolute).links, strict=True):
            for size in ("shank_width", "shank_thickness", "thickness"):
                assert getattr(mine.model.geometry, size) == pytest.approx(getattr(theirs.model.geometry, size),
                                                                         rel=1e-12)
    # a banded rotor is a sweep in the optimum, which its band row could not name: no optimum.xlsx, and why
    with pytest.raises(UnwritableCase, match=r"speed bands \(LP rotor\).*optimum.json holds"):
        dataclasses.replace(result, bands={"LP rotor": (40.0, 62.0)}).workbook()


@pytest.mark.slow
def test_starts_in_two_worker_processes_give_the_serial_optimum(mount):
    ranges = {"hinge_stiffness/all": (1e7, 5e7), "hinge_loss_factor/all": (0.01, 0.2)}
    serial, parallel = (opt.optimise(mount.case, ranges, constraints=["displacement<=0.002"], starts=2, mount=mount,
                                     workers=workers) for workers in (1, 2))
    for name, value in serial.values.items():
        assert parallel.values[name] == pytest.approx(value, rel=1e-9)
    assert [end["objective"] for end in parallel.starts] == pytest.approx([end["objective"] for end in serial.starts],
                                                                          rel=1e-9)
    assert len(parallel.history) == len(serial.history)
