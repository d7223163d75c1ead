"""Test data from a rig record: a row of the Test data sheet naming a record file.

The record is measured like a simulation (:func:`workbook.rig.correlation.measure`,
windows of the run's ``measured_periods`` periods) and becomes one test
point per direction at the pylon sum, with the amplitude ``T_test,d x
|F_exc|`` of the run's own excitation: the result sheets' error
``(sim - test) / test x 100 %`` is then the error of T whatever force the
rig applied.
"""
from __future__ import annotations

from pathlib import Path

from workbook.answers.results import PYLON_SUM
from workbook.errors import RecordError
from workbook.excel.files import bounded_file_problem
from workbook.excel.runs import TestPoint
from workbook.model.case import DIRECTIONS, Case, Sweep
from workbook.rig.correlation import measure
from workbook.rig.records import read_record

__all__ = ["record_test_points", "MAX_RECORD_BYTES"]

#: Largest rig record read, bytes.
MAX_RECORD_BYTES = 200_000_000


def record_test_points(path: Path, run_name: str, case: Case) -> list[TestPoint]:
    """Test points of the pylon sum from the rig record at *path*.

    Parameters
    ----------
    path : Path
        The record (CSV).
    run_name : str
        The workbook run it is compared with.
    case : Case
        The run's case (:func:`workbook.excel.runs.case_for_run`).

    Raises
    ------
    RecordError
        A bad record, a path that is not a regular file of at most
        :data:`MAX_RECORD_BYTES`, transducers that do not match the case's pylon-side
        hinges, a sweep run, or a record of another rotor frequency.
    """
    if len(case.excitations) != 1 or isinstance(case.excitations[0], Sweep):
        raise RecordError(path, f"run {run_name!r} is not a single-frequency run; a record measures one frequency")
    excitation = case.excitations[0]
    problem = bounded_file_problem(path, MAX_RECORD_BYTES)
    if problem is not None:
        raise RecordError(path, problem)
    record = read_record(path)
    record.check_hinges([h.name for h in case.pylon_hinges])
    if abs(record.nominal_hz - excitation.frequency) > 0.02 * excitation.frequency:
        raise RecordError(path, f"nominal frequency {record.nominal_hz:g} Hz is not run {run_name!r}'s "
                                f"{excitation.frequency:g} Hz")
    measurement = measure(record, case.analysis.measured_periods, nominal_hz=excitation.frequency)
    amplitude = excitation.force_amplitude
    return [TestPoint(run_name, PYLON_SUM, axis, None, float(t) * amplitude)
            for axis, t in zip(DIRECTIONS, measurement.transmissibility, strict=True)]
