"""The four-pole set of a case: its mount's scene prepared by the one
pipeline (:func:`workbook.solve.pipeline.prepare`), then condensed onto the
engine and the pylon pins (:func:`workbook.solve.four_pole.condense`)."""
from __future__ import annotations

from workbook.model.case import Case, HarmonicForce
from workbook.solve.four_pole import REPORT_GRID, FourPole, checked_frequencies, condense, frequency_grid, mount_case
from workbook.solve.pipeline import prepare

__all__ = ["four_pole", "report_four_pole"]


def four_pole(case: Case, frequencies_hz, *, points=()) -> FourPole:
    """The four-pole set of the mount of *case* at *frequencies_hz*, about
    its preloaded equilibrium.

    Parameters
    ----------
    case : Case
        Its links are reduced for the highest frequency. Test-rig
        transducers are not part of the mount (give them as a pylon
        impedance).
    frequencies_hz, points
        As :func:`~workbook.solve.four_pole.condense` takes them.

    Raises
    ------
    workbook.errors.CaseError
        A hinge with a clearance law, no pylon-side hinge, or no frequency.
    workbook.errors.SimulationError
        A mechanism or a failed equilibrium (preload); a singular set
        (:class:`~workbook.errors.FourPoleError`).
    """
    frequencies = checked_frequencies(frequencies_hz)
    probe = HarmonicForce("four-pole probe", point=case.engine.center_of_mass, direction=(1.0, 0.0, 0.0),
                          amplitude=1.0, frequency_hz=float(frequencies.max()))
    prepared = prepare(mount_case(case), probe)
    with prepared.scene:
        return condense(prepared.model, case, frequencies, points=points)


def report_four_pole(case: Case) -> FourPole:
    """The four-pole set of *case* on the default grid (:data:`~workbook.solve.four_pole.REPORT_GRID`),
    for the report workbook's Four-pole sheet."""
    return four_pole(case, frequency_grid(*REPORT_GRID))
