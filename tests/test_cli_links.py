"""`mountwb links`: what each link of the reference mount became, and why."""
import numpy as np

from flexbodies.selection import LOW_FREQUENCY_RATIO
from workbook.answers.link_table import link_table
from workbook.cli.main import main
from workbook.model.reference import reference_case
from workbook.scene.build import reduce_links


def test_link_table_follows_the_low_frequency_rule(cache_dir):
    case = reference_case()
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


def test_links_command_prints_every_link_and_reuses_the_cache(cache_dir, capsys, tmp_path):
    assert main(["links", "--export", str(tmp_path)]) == 0
    output = capsys.readouterr().out
    case = reference_case()
    for link in case.links:
        assert f"{link.name}: low-frequency rule" in output
        assert (tmp_path / f"{link.name}.npz").is_file()
    assert main(["links"]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.split()[:1] in ([link.name] for link in case.links)]
    assert len(rows) == len(case.links) and all(row.rstrip().endswith("hit") for row in rows)
