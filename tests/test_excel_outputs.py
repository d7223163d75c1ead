"""Outputs never replace or lose a user's work: the case workbook as a user saves it, other runs' results,
files changed or protected meanwhile, and every output path a command is given.

The user's files are saved by LibreOffice headless (open and save as .xlsx), as
a user's Excel or LibreOffice writes them (shared strings, its own document
properties); those tests are skipped, with the reason, when ``soffice`` is not
on PATH.
"""
from __future__ import annotations

import dataclasses
import os
import shutil
import stat
from pathlib import Path

import pytest
from cli_signals import start
from excel_helpers import SOFFICE, copy_reference, make_cheap, save_in_libreoffice, set_cells, sha256
from openpyxl import load_workbook
from openpyxl.chart import BarChart, Reference
from openpyxl.comments import Comment

from workbook.cli.main import main
from workbook.errors import EXIT_BAD_INPUT
from workbook.model.codec import to_json
from workbook.model.reference import LP_ROTOR, reference_case

needs_libreoffice = pytest.mark.skipif(SOFFICE is None, reason="LibreOffice (soffice) is not on PATH: "
                                                                "apt-get install libreoffice-calc-nogui")


@pytest.fixture
def folder(tmp_path):
    """A folder of its own for the user's files (LibreOffice's profile stays outside it)."""
    path = tmp_path / "work"
    path.mkdir()
    return path


def _cheap_case(folder, name="case.xlsx"):
    path = copy_reference(folder, name)
    make_cheap(path)
    return path


def _names(folder):
    return sorted(p.name for p in folder.iterdir())


def _result_runs(path, sheet="Result efficiency"):
    return {row[0] for row in load_workbook(path)[sheet].iter_rows(min_row=3, values_only=True)}


@needs_libreoffice
def test_a_workbook_saved_by_libreoffice_gets_its_results_written_into_it(folder, tmp_path, capsys):
    """Saved by LibreOffice (shared strings, an empty custom-properties part, its own comment box), run, saved
    again, run again."""
    path = _cheap_case(folder)
    wb = load_workbook(path)
    wb["Hinges"]["A4"].comment = Comment("supplier's drawing rev. C", "J. Doe")
    wb.save(path)
    save_in_libreoffice(path, tmp_path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    assert f"results written to {path}" in capsys.readouterr().out
    assert _names(folder) == ["case.xlsx"] and _result_runs(path) == {"LP rotor"}
    save_in_libreoffice(path, tmp_path)
    assert main(["run", str(path), "--no-progress", "--run", "HP rotor"]) == 0
    assert f"results written to {path}" in capsys.readouterr().out
    assert _names(folder) == ["case.xlsx"] and "HP rotor" in _result_runs(path)
    assert load_workbook(path)["Hinges"]["A4"].comment.text.startswith("supplier's drawing rev. C")


@needs_libreoffice
def test_a_chart_the_user_made_still_keeps_the_workbook_from_being_rewritten(folder, tmp_path, capsys):
    path = _cheap_case(folder)
    wb = load_workbook(path)
    chart = BarChart()
    chart.add_data(Reference(wb["Links"], min_col=3, min_row=3, max_row=6))
    wb["Links"].add_chart(chart, "H2")
    wb.save(path)
    save_in_libreoffice(path, tmp_path)
    digest = sha256(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    assert "content this program cannot keep (charts" in capsys.readouterr().out
    assert sha256(path) == digest and len(_names(folder)) == 2


def _rows(path, sheet):
    return list(load_workbook(path)[sheet].iter_rows(min_row=3, values_only=True))


@needs_libreoffice
def test_a_run_of_one_row_keeps_the_results_of_the_other_runs(folder, tmp_path):
    """HP rotor and the sweep, saved by LibreOffice, then LP rotor alone: the others' rows and cards stay."""
    path = copy_reference(folder)
    make_cheap(path, sweep_points=2)
    assert main(["run", str(path), "--no-progress", "--run", "HP rotor", "--run", "sweep"]) == 0
    save_in_libreoffice(path, tmp_path)
    before = {sheet: _rows(path, sheet) for sheet in ("Result efficiency", "Result hinges", "Result sweep")}
    note = load_workbook(path)["Result sweep"]["A1"].value
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    assert _names(folder) == ["case.xlsx"]
    wb = load_workbook(path)
    assert wb["Result sweep"]["A1"].value == note and _rows(path, "Result sweep") == before["Result sweep"]
    for sheet in ("Result efficiency", "Result hinges"):
        rows = _rows(path, sheet)
        assert [row for row in rows if row[0] != "LP rotor"] == before[sheet]
        assert {row[0] for row in rows} == {"LP rotor", "HP rotor", "sweep"}
    assert "the results of 'HP rotor', 'sweep' are from an earlier run" in wb["Result efficiency"]["A1"].value
    card = [cell.value for cell in wb["Result model card"]["A"]]
    assert [line for line in card if str(line).startswith("Run '")] == ["Run 'HP rotor'", "Run 'sweep'",
                                                                         "Run 'LP rotor'"]


def _mountwb(*args):
    """``mountwb ARGS`` in a process of its own (stderr with the -v log, line by line)."""
    return start(*map(str, args))


@needs_libreoffice
def test_two_runs_at_once_keep_both_results(folder, tmp_path):
    """The second to write finds the workbook changed and writes its results beside it, and says so."""
    path = save_in_libreoffice(_cheap_case(folder), tmp_path)
    processes = {run: _mountwb("run", path, "--no-progress", "--run", run) for run in ("LP rotor", "HP rotor")}
    outputs = {run: process.communicate(timeout=300) for run, process in processes.items()}
    assert all(process.returncode == 0 for process in processes.values()), outputs
    into = [run for run, (out, _) in outputs.items() if f"results written to {path}\n" in out]
    beside = [run for run, (out, _) in outputs.items() if "case.xlsx was not overwritten: it changed on disk" in out]
    assert len(into) == 1 and len(beside) == 1, outputs
    assert _result_runs(path) == set(into)
    side = [p for p in folder.iterdir() if p.name.startswith("case-results-")]
    assert len(side) == 1 and _result_runs(side[0]) == set(beside)


@needs_libreoffice
def test_a_save_that_lands_while_the_results_are_built_is_kept(folder, tmp_path):
    """The user saves the workbook (an edited copy LibreOffice saved, renamed over it) while mountwb builds the
    new file: the check just before the rename finds it, the user's save stays and the results go beside."""
    path = _cheap_case(folder)
    edited = tmp_path / "edited" / "case.xlsx"
    edited.parent.mkdir()
    shutil.copyfile(path, edited)
    set_cells(edited, {("Engine", "mass", 3): 3600})
    save_in_libreoffice(edited, tmp_path)
    digest = sha256(edited)
    process = _mountwb("run", path, "--no-progress", "--run", "LP rotor")
    for line in process.stderr:
        if "building the new case.xlsx" in line:
            os.replace(edited, path)
            break
    out, _ = process.communicate(timeout=300)
    assert process.returncode == 0
    assert "case.xlsx was not overwritten: it changed on disk while the results were being written" in out
    assert sha256(path) == digest
    side = [p for p in folder.iterdir() if p.name.startswith("case-results-")]
    assert len(side) == 1 and _result_runs(side[0]) == {"LP rotor"}


@needs_libreoffice
def test_a_read_only_workbook_is_not_replaced(folder, tmp_path, capsys):
    path = save_in_libreoffice(_cheap_case(folder), tmp_path)
    report = folder / "report.xlsx"
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor", "--report", str(report)]) == 0
    for protected in (path, report):
        os.chmod(protected, 0o444)
    digests = [sha256(path), sha256(report)]
    capsys.readouterr()
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor", "--report", str(report)]) == 0
    out = capsys.readouterr().out
    assert "case.xlsx was not overwritten: it is read-only (mode 444)" in out
    assert f"{report} was not overwritten: it is read-only (mode 444)" in out
    assert [sha256(path), sha256(report)] == digests
    assert all(stat.S_IMODE(p.stat().st_mode) == 0o444 for p in (path, report))
    assert len([p for p in folder.iterdir() if p.name.startswith("case-results-")]) == 1
    assert len([p for p in folder.iterdir() if p.name.startswith("report-report-")]) == 1


# -- outputs never replace the user's files ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def saved_case(tmp_path_factory):
    """A cheap case workbook as the user saved it in LibreOffice."""
    folder = tmp_path_factory.mktemp("saved-case")
    return save_in_libreoffice(_cheap_case(folder), folder / "scratch")


@pytest.fixture
def user_case(saved_case, folder):
    """A copy of the user's case workbook in a folder of its own."""
    return Path(shutil.copyfile(saved_case, folder / "case.xlsx"))


def _json_case(folder):
    path = folder / "case.json"
    path.write_text(to_json(dataclasses.replace(reference_case().with_rigid_links(), excitations=(LP_ROTOR,))))
    return path


@needs_libreoffice
@pytest.mark.parametrize("argv, option, expected", [
    (["four-pole", "{case}", "--csv", "{case}"], "--csv", ".csv"),
    (["run-up", "{case}", "--csv", "{case}"], "--csv", ".csv"),
    (["four-pole", "{case}", "--plot", "plot.pdf"], "--plot", ".png"),
    (["four-pole", "{case}", "--xlsx", "table.csv"], "--xlsx", ".xlsx"),
    (["run", "{case}", "--report", "report.pdf"], "--report", ".xlsx"),
    (["run", "{case}", "--report", "report.ods"], "--report", ".xlsx"),
    (["layout", "{case}", "-o", "{case}"], "--output", ".png"),
    (["template", "case.ods"], "output", ".xlsx or .xlsm"),
    (["rig", "synthesize", "{case}", "{case}"], "output", ".csv or .uff or .unv"),
    (["rig", "plot", "{case}", "--output", "plot.pdf"], "--output", ".png"),
])
def test_an_output_with_the_wrong_ending_is_refused_before_anything_runs(user_case, folder, capsys, argv, option,
                                                                         expected):
    digest = sha256(user_case)
    argv = [arg.format(case=user_case) if "{" in arg else str(folder / arg) if "." in arg else arg for arg in argv]
    assert main(argv) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"{option} " in err and f"expected a file ending in {expected}, found" in err
    assert sha256(user_case) == digest and _names(folder) == ["case.xlsx"]


@needs_libreoffice
def test_the_report_may_not_be_the_case_workbook(user_case, folder, capsys):
    digest = sha256(user_case)
    assert main(["run", str(user_case), "--run", "LP rotor", "--report", str(user_case)]) == EXIT_BAD_INPUT
    assert f"--report {user_case}: that is an input of this command" in capsys.readouterr().err
    assert sha256(user_case) == digest and _names(folder) == ["case.xlsx"]


@needs_libreoffice
def test_a_report_the_user_annotated_is_kept(user_case, folder, tmp_path, capsys):
    """A report saved in LibreOffice keeps its keywords, but it is the user's now: the next report goes beside it."""
    report = folder / "report.xlsx"
    assert main(["run", str(user_case), "--no-progress", "--run", "LP rotor", "--report", str(report)]) == 0
    wb = load_workbook(report)
    wb["Summary"]["A30"] = "checked against the rig on Monday"
    wb.save(report)
    save_in_libreoffice(report, tmp_path)
    assert "mountwb report" in str(load_workbook(report).properties.keywords)
    digest = sha256(report)
    capsys.readouterr()
    assert main(["run", str(user_case), "--no-progress", "--run", "LP rotor", "--report", str(report)]) == 0
    out = capsys.readouterr().out
    assert f"{report} was not overwritten: report.xlsx exists and is not a report this program wrote, or was " \
           "changed since" in out
    assert sha256(report) == digest
    beside = [p for p in folder.iterdir() if p.name.startswith("report-report-")]
    assert len(beside) == 1 and f"report written to {beside[0]}" in out


@needs_libreoffice
def test_four_pole_outputs_keep_existing_files(folder, tmp_path, capsys):
    """The user's workbook and table of the same names are kept; the four-pole workbook it wrote is replaced."""
    workbook = save_in_libreoffice(_cheap_case(folder, "table.xlsx"), tmp_path)
    table = folder / "table.csv"
    table.write_text("the user's own table\n")
    digests = [sha256(workbook), sha256(table)]
    argv = ["four-pole", "--rigid", "--points", "3", "--xlsx", str(workbook), "--csv", str(table)]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "table.xlsx was not overwritten" in out and "table.csv was not overwritten: table.csv exists" in out
    assert [sha256(workbook), sha256(table)] == digests
    ours = [p for p in folder.iterdir() if p.name.startswith("table-four-pole-") and p.suffix == ".xlsx"]
    assert len(ours) == 1 and len(_names(folder)) == 4
    assert main(["four-pole", "--rigid", "--points", "3", "--xlsx", str(ours[0])]) == 0
    assert f"workbook written to {ours[0]}" in capsys.readouterr().out and len(_names(folder)) == 4


def test_a_second_study_keeps_the_first(folder, capsys):
    case = _json_case(folder)
    output = folder / "out"
    argv = ["study", "params", str(case), "--output", str(output), "--workers", "1", "--vary=hinge_stiffness=1e7,2e7"]
    assert main(argv) == 0
    first = {name: sha256(output / name) for name in _names(output)}
    assert sorted(first) == ["parameter-study.csv", "parameter-study.png", "parameter-study.xlsx"]
    assert main(argv[:-1] + ["--vary=hinge_stiffness=3e7,4e7"]) == 0
    assert {name: sha256(output / name) for name in first} == first
    assert _names(output) == sorted([*first, "parameter-study-2.csv", "parameter-study-2.png",
                                     "parameter-study-2.xlsx"])
    assert str(output / "parameter-study-2.csv") in capsys.readouterr().out


@pytest.mark.parametrize("argv", [
    ["study", "accuracy", "--output", "{file}"],
    ["study", "params", "--vary", "hinge_stiffness=1e7,2e7", "--output", "{file}"],
    ["study", "uq", "--param", "hinge_stiffness=uniform:1e7:2e7", "--output", "{file}"],
    ["update", "--record", "rig.csv", "--vary", "hinge_stiffness/front=1e7:5e7", "--output", "{file}"],
    ["optimise", "--vary", "hinge_stiffness/all=1e7:5e7", "--output", "{file}"],
    ["links", "--export", "{file}"],
    ["stress", "--vtu", "{file}"],
    ["stress", "--png", "{file}"],
], ids=lambda argv: " ".join(argv[:2]))
def test_an_output_folder_that_is_a_file_is_refused_before_anything_runs(folder, capsys, argv):
    notes = folder / "notes.txt"
    notes.write_text("the user's notes\n")
    with pytest.raises(SystemExit) as stopped:
        main([str(notes) if arg == "{file}" else arg for arg in argv])
    assert stopped.value.code == EXIT_BAD_INPUT
    assert f"argument {argv[-2]}: {notes} is a file; expected a folder" in capsys.readouterr().err
    assert notes.read_text() == "the user's notes\n" and _names(folder) == ["notes.txt"]


def test_workbook_options_are_refused_for_a_json_case(folder, capsys):
    case = _json_case(folder)
    assert main(["run", str(case), "--report", str(folder / "R.xlsx"), "--run", "LP rotor"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "--run and --report are for a case workbook (.xlsx)" in err and "nothing was run" in err
    assert _names(folder) == ["case.json"]
