"""`mountwb links`: what each link of the reference mount became, and why."""
import numpy as np
import pytest

from flexbodies.selection import LOW_FREQUENCY_RATIO
from workbook.answers.link_table import link_table
from workbook.cli.main import main
from workbook.model.codec import to_json
from workbook.scene.build import reduce_links


@pytest.fixture(scope="module")
def coarse_case_file(coarse_reference, tmp_path_factory):
    """The coarse reference mount as a JSON case: these tests are about the table and the cache, not the mesh."""
    path = tmp_path_factory.mktemp("links") / "coarse.json"
    path.write_text(to_json(coarse_reference))
    return path


def test_link_table_follows_the_low_frequency_rule(coarse_reference):
    case = coarse_reference
    table = link_table(case, reduce_links(case))
    assert list(table.index) == [link.name for link in case.links]
    rule_met = table["f_exc/f1"] < LOW_FREQUENCY_RATIO
    assert (table.loc[rule_met, "fixed-interface modes"] == 0).all()
    assert (table.loc[~rule_met, "fixed-interface modes"] > 0).all()
    # a flexible link: 6 rigid-body DOF, 6 elastic static modes, the fixed-interface modes
    np.testing.assert_array_equal(table["DOF in scene"], 12 + table["fixed-interface modes"])
    # pinned at both eyes a beam vibrates lower than free-free (9.87 against 22.4 / L^2 for a uniform beam)
    assert (table["f1 mounted [Hz]"] < table["f1 free-free [Hz]"]).all()
    assert table["why"].str.contains("rule met|rule not met").all()


def test_links_command_prints_every_link_and_reuses_the_cache(coarse_reference, coarse_case_file, capsys, tmp_path):
    assert main(["links", str(coarse_case_file), "--export", str(tmp_path)]) == 0
    output = capsys.readouterr().out
    case = coarse_reference
    for link in case.links:
        assert f"{link.name}: low-frequency rule" in output
        assert (tmp_path / f"{link.name}.npz").is_file()
    exported = {path.name: path.read_bytes() for path in tmp_path.glob("*.npz")}
    assert main(["links", str(coarse_case_file), "--export", str(tmp_path)]) == 0    # a second export keeps the first
    assert f"{case.links[0].name}.npz was not overwritten" in capsys.readouterr().out
    assert {name: (tmp_path / name).read_bytes() for name in exported} == exported
    assert len(list(tmp_path.glob("*.npz"))) == 2 * len(exported)
    assert main(["links", str(coarse_case_file)]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.split()[:1] in ([link.name] for link in case.links)]
    assert len(rows) == len(case.links) and all(row.rstrip().endswith("hit") for row in rows)


def test_link_table_gives_the_ratio_for_every_excitation(coarse_reference):
    case = coarse_reference
    table = link_table(case, reduce_links(case))
    for excitation in case.excitations:
        column = f"f_exc/f1 {excitation.name} ({excitation.frequency:g} Hz)"
        np.testing.assert_allclose(table[column], excitation.frequency / table["f1 mounted [Hz]"], rtol=1e-6)


@pytest.mark.slow
def test_links_verify_prints_json_and_a_plot_per_distinct_design(coarse_reference, coarse_case_file, capsys, tmp_path):
    import json

    plot = tmp_path / "verify.png"
    assert main(["links", str(coarse_case_file), "--verify", "--modes", "0,3", "--frequencies", "500",
                 "--basis", "orthonormal", "--json", "--plot", str(plot)]) == 0
    captured = capsys.readouterr()
    answer = json.loads(captured.out)
    designs = {link.model for link in coarse_reference.links}
    assert len(answer["links"]) == len(designs)
    for item in answer["links"]:
        assert [row["model"] for row in item["rows"]] == ["full FE", "orthonormal 0", "orthonormal 3"]
        assert abs(item["rows"][-1]["static error [%]"]) < 1e-6      # all modes kept: exact
        assert all(row["wall time [s]"] > 0 for row in item["rows"])
    assert plot.stat().st_size > 0 and "plot written" in captured.err


@pytest.mark.parametrize("options, named", [(["--verify", "--modes", "2,x"], "--modes"),
                                            (["--verify", "--frequencies", "0"], "--frequencies"),
                                            (["--json"], "--json"),
                                            (["--verify", "--plot", "out.pdf"], "--plot")])
def test_links_verify_refuses_bad_options(coarse_case_file, capsys, options, named):
    assert main(["links", str(coarse_case_file), *options]) == 2
    assert named in capsys.readouterr().err
