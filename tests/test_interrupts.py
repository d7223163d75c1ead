"""Ctrl-C and SIGTERM anywhere print one line, exit 130 or 143 and change no file."""
import signal

import pytest
from cli_signals import SIGNAL_EXIT, files_in, signal_at, start
from excel_helpers import copy_reference, make_cheap

from workbook.errors import EXIT_INTERRUPTED, EXIT_TERMINATED, Terminated, exit_code, interruption


def _solve_with_interrupt(interrupt: KeyboardInterrupt):
    """A real Exudyn time integration whose Python load function raises *interrupt*
    (as a signal handler does when Ctrl-C arrives inside it); returns what Exudyn raised."""
    import exudyn as exu
    from exudyn.itemInterface import LoadForceVector, MarkerNodePosition, MassPoint, NodePoint

    system = exu.SystemContainer()
    mbs = system.AddSystem()
    node = mbs.AddNode(NodePoint(referenceCoordinates=[0, 0, 0]))
    mbs.AddObject(MassPoint(mass=1.0, nodeNumber=node))
    marker = mbs.AddMarker(MarkerNodePosition(nodeNumber=node))

    def force(mbs, t, load):
        if t > 0.01:
            raise interrupt
        return [1.0, 0.0, 0.0]

    mbs.AddLoad(LoadForceVector(markerNumber=marker, loadVectorUserFunction=force))
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps, settings.timeIntegration.endTime = 100, 0.1
    settings.solution.file.write = False
    try:
        exu.MainSolverImplicitSecondOrder().SolveSystem(mbs, settings)
    except BaseException as error:  # noqa: B036 - what Exudyn raises is the point
        return error
    finally:
        system.Reset()
    raise AssertionError("the integration ended without the interrupt")


@pytest.mark.parametrize("interrupt, code", [(KeyboardInterrupt(), EXIT_INTERRUPTED), (Terminated(), EXIT_TERMINATED)])
def test_an_interrupt_that_exudyn_wraps_is_still_an_interrupt(interrupt, code):
    raised = _solve_with_interrupt(interrupt)
    assert not isinstance(raised, KeyboardInterrupt)  # Exudyn's own error, not the interrupt ...
    assert interruption(raised) is interrupt          # ... with the interrupt behind it
    assert exit_code(raised) == code


def test_an_error_without_an_interrupt_has_none():
    assert interruption(ValueError("bad")) is None


def _one_line(rest: str, signum: int) -> str:
    lines = [line for line in rest.splitlines() if line.strip() and not line.startswith(("INFO", "DEBUG"))]
    assert len(lines) == 1, rest
    assert "Traceback" not in rest
    assert ("terminated (SIGTERM)" if signum == signal.SIGTERM else "interrupted (Ctrl-C)") in lines[0]
    return lines[0]


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_during_the_time_integration(tmp_path, signum):
    process = start("run", "--rigid", "--method", "time", "--no-progress", cwd=tmp_path)
    code, rest = signal_at(process, "steps of", signum)
    assert code == SIGNAL_EXIT[signum]
    _one_line(rest, signum)
    assert files_in(tmp_path) == {}


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_during_a_link_reduction_leaves_no_cache_file_half_written(tmp_path, signum):
    cache = tmp_path / "cache"
    process = start("run", "--no-progress", cwd=tmp_path, env={"MOUNTWB_CACHE": str(cache)})
    code, rest = signal_at(process, "assembled", signum)
    assert code == SIGNAL_EXIT[signum]
    _one_line(rest, signum)
    assert not [name for name in files_in(tmp_path) if name.endswith(".tmp")]


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_during_a_workbook_run_leaves_the_workbook_as_it_was(tmp_path, signum):
    book = copy_reference(tmp_path)
    make_cheap(book)
    before = files_in(tmp_path)
    process = start("run", str(book), "--no-progress", cwd=tmp_path)
    code, rest = signal_at(process, "steps of", signum)
    assert code == SIGNAL_EXIT[signum]
    _one_line(rest, signum)
    assert files_in(tmp_path) == before


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_the_report_is_written_names_the_workbook_already_written(tmp_path, signum):
    """The results are in the case workbook when the signal comes: the line says so, and no report is left."""
    book = copy_reference(tmp_path)
    make_cheap(book)
    process = start("run", str(book), "--no-progress", "--run", "LP rotor", "--report", "report.xlsx", cwd=tmp_path)
    code, rest = signal_at(process, f"saved {book}", signum)
    assert code == SIGNAL_EXIT[signum]
    line = _one_line(rest, signum)
    assert line.endswith(f"; {book} was written before it, no other file was changed"), rest
    assert sorted(files_in(tmp_path)) == ["case.xlsx"]
