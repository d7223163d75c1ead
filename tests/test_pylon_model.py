"""The pylon model interface: one ``Case.pylon`` field, earlier case files and keywords still read.

``tests/data/pylon_beam_case_0.1.0.json`` was written by version 0.1.0
(``to_json`` of ``test_pylon_beam._vertical_case()``), whose cases held the
pylon in three fields, ``pylon_impedance``, ``pylon_beam`` and ``pylon_mesh``.
"""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from test_pylon_beam import FREQUENCIES, _vertical_case
from test_sdof import STIFFNESS, sdof_case

from workbook.errors import CaseError, CaseFileError
from workbook.model.case import AnalysisSettings, HarmonicForce
from workbook.model.codec import from_dict, from_json, to_dict, to_json
from workbook.model.pylon import PinDynamics, PylonModel
from workbook.model.pylon_impedance import PylonImpedance
from workbook.solve.pipeline import run_case

OLD_FILE = Path(__file__).parent / "data" / "pylon_beam_case_0.1.0.json"


def test_a_case_file_of_the_three_pylon_fields_reads_as_its_pylon():
    case = _vertical_case()
    old = json.loads(OLD_FILE.read_text())
    assert old["pylon_beam"] is not None and "pylon" not in old
    assert from_dict(old) == case
    written = to_dict(case)
    assert written["pylon"]["type"] == "BoxBeamPylon"
    assert not {"pylon_impedance", "pylon_beam", "pylon_mesh"} & set(written)
    assert from_json(to_json(case)) == case
    two = dict(old, pylon_impedance=to_dict(_table(case, 1e6)))
    with pytest.raises(CaseFileError, match="one pylon model"):
        from_dict(two)


def test_the_pylon_keywords_of_earlier_versions_are_deprecated_aliases():
    case = _vertical_case()
    beam = case.pylon
    with pytest.warns(DeprecationWarning, match="Case.pylon_beam is deprecated"):
        assert dataclasses.replace(case, pylon=None, pylon_beam=beam) == case
    with pytest.warns(DeprecationWarning):
        assert case.pylon_beam == beam and case.pylon_impedance is None
    with pytest.warns(DeprecationWarning):
        assert dataclasses.replace(case, pylon_mesh=None).pylon == beam      # None clears only its own kind
    with pytest.warns(DeprecationWarning):
        assert dataclasses.replace(case, pylon_beam=None).pylon is None
    with pytest.raises(CaseError, match="field 'pylon'"):
        dataclasses.replace(case, pylon="a box beam")


def _table(case, stiffness):
    pins = [hinges[0] for _, hinges in case.pylon_pins()]
    values = np.broadcast_to(stiffness * (1 + 0.02j) * np.eye(3), (2, len(pins), 3, 3))
    return PylonImpedance.from_array("table", [1.0, 100.0], pins, values)


@dataclasses.dataclass(frozen=True)
class _Springs(PylonModel):
    """A user's pylon model: a spring with loss factor per pin and direction, its compliance uncoupled."""

    effect = "flexible pylon (springs)"
    noun = "pylon springs"
    time_domain_note = "a test model"

    stiffness: float

    @property
    def label(self) -> str:
        return "springs"

    def describe(self) -> str:
        return f"{self.stiffness:g} N/m per pin and direction"

    def pins_at(self, pins, frequencies_hz, highest_hz) -> PinDynamics:
        per_pin = np.eye(3 * len(pins)) / (self.stiffness * (1 + 0.02j))
        return PinDynamics(None, np.stack([per_pin] * len(frequencies_hz)), self.describe())


def test_any_pylon_model_closes_the_set_as_an_impedance_table_of_the_same_stiffness():
    """A model given as a compliance and a table of the same constant stiffness give one answer, both
    between the rigid pylon and the softer pylon's."""
    base = sdof_case(())
    cg = base.engine.center_of_mass
    excitations = tuple(HarmonicForce(f"{f:g} Hz", point=cg, direction=(0.0, 0.0, 1.0), amplitude=1000.0,
                                      frequency_hz=f) for f in FREQUENCIES)
    case = dataclasses.replace(base, excitations=excitations, analysis=AnalysisSettings(method="auto"))
    stiffness = 5 * STIFFNESS
    by_model = run_case(dataclasses.replace(case, pylon=_Springs(stiffness)))
    by_table = run_case(dataclasses.replace(case, pylon=_table(case, stiffness)))
    rigid = run_case(case)
    for run in rigid.runs:
        np.testing.assert_allclose(by_model.run(run.name).transmissibility,
                                   by_table.run(run.name).transmissibility, rtol=1e-9)
        assert not np.allclose(by_model.run(run.name).transmissibility, run.transmissibility, rtol=1e-3)
    effects = [e.name for e in by_model.model_cards[rigid.runs[0].name].effects]
    assert "flexible pylon (springs)" in effects
    with pytest.raises(CaseError, match="no pylon springs in the time domain"):
        run_case(dataclasses.replace(case, pylon=_Springs(stiffness), analysis=AnalysisSettings(method="time")))


def test_an_impedance_table_on_the_command_line_is_refused_beside_another_pylon_model(capsys):
    from workbook.cli.main import main
    from workbook.errors import EXIT_BAD_INPUT

    table = Path(__file__).parents[1] / "docs" / "pylon-impedance-example.csv"
    before = OLD_FILE.read_bytes()
    assert main(["run", str(OLD_FILE), "--pylon-impedance", str(table)]) == EXIT_BAD_INPUT
    error = capsys.readouterr().err
    assert "already has a pylon beam" in error and "one pylon model" in error
    assert OLD_FILE.read_bytes() == before
