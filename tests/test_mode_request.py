"""A link's mode request: a count and a cut-off frequency cannot be confused."""
import dataclasses
import json

import pytest

from workbook.errors import CaseError
from workbook.model.case import ModeCutoff
from workbook.model.codec import from_json, to_json
from workbook.model.reference import reference_case


@pytest.fixture(scope="module")
def link():
    return reference_case().links[0]


@pytest.mark.parametrize("asked, kept", [
    (12, 12), ("auto", "auto"), (" Static ", "static"), (ModeCutoff(500.0), ModeCutoff(500.0)),
    ("500 Hz", ModeCutoff(500.0)), ("up to 2e3 hz", ModeCutoff(2000.0)),
])
def test_counts_cutoffs_and_rules_are_kept_as_their_type(link, asked, kept):
    modes = dataclasses.replace(link, modes=asked).modes
    assert modes == kept and type(modes) is type(kept)


@pytest.mark.parametrize("asked, hint", [(12.0, "write 12 for a count or '12 Hz' for a cut-off"), (1.5, "'1.5 Hz'"),
                                         (-1, "whole mode count"), (True, "whole mode count"), ("12", "'500 Hz'"),
                                         (ModeCutoff(0.0), "> 0 Hz")])
def test_an_ambiguous_or_bad_request_names_the_link_and_what_to_write(link, asked, hint):
    with pytest.raises(CaseError, match="modes") as error:
        dataclasses.replace(link, modes=asked)
    assert repr(link.name) in str(error.value) and hint in str(error.value)


def test_json_keeps_counts_and_cutoffs_apart_and_reads_existing_files():
    case = reference_case()
    links = (dataclasses.replace(case.links[0], modes=12), dataclasses.replace(case.links[1], modes="500 Hz"))
    again = from_json(to_json(dataclasses.replace(case, links=links + case.links[2:])))
    assert again.links[0].modes == 12 and type(again.links[0].modes) is int
    assert again.links[1].modes == ModeCutoff(500.0) and type(again.links[1].modes) is ModeCutoff
    # a case file written before the type existed: a number with a fraction was a cut-off in Hz
    data = json.loads(to_json(case))
    data["links"][0]["modes"] = 2000.0
    assert from_json(json.dumps(data)).links[0].modes == ModeCutoff(2000.0)


def test_a_workbook_cutoff_cell_reads_as_a_cutoff_and_a_whole_number_as_a_count(tmp_path):
    from excel_helpers import copy_reference, set_cells

    from workbook.excel.reader import read_workbook

    path = copy_reference(tmp_path)
    set_cells(path, {("Links", "modes", 3): "2 kHz", ("Links", "modes", 4): 6})
    links = read_workbook(path).case.links
    assert links[0].modes == ModeCutoff(2000.0) and type(links[0].modes) is ModeCutoff
    assert links[1].modes == 6 and type(links[1].modes) is int
