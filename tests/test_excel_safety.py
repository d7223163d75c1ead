"""Case workbooks: a user's work is never misread, lost or overwritten.

Every test builds real .xlsx files (openpyxl, or by editing the zip parts as
Excel and LibreOffice write them) and runs the real commands on them.
"""
from __future__ import annotations

import datetime
import os
import resource
import shutil
import signal
import stat
import subprocess
import sys
import time
import zipfile

import pytest
from excel_helpers import ROOT, copy_reference, give_cached_value, make_cheap, sha256
from openpyxl import Workbook, load_workbook
from openpyxl.cell.rich_text import CellRichText, TextBlock
from openpyxl.cell.text import InlineFont
from openpyxl.comments import Comment
from openpyxl.workbook.defined_name import DefinedName

from workbook.cli.main import main
from workbook.errors import WorkbookError
from workbook.excel.files import lost_parts, unsupported_content, workbook_bytes
from workbook.excel.reader import read_workbook
from workbook.excel.sheets import MAX_UNPACKED_BYTES


@pytest.fixture(scope="module")
def cheap_ran(tmp_path_factory, cache_dir):
    """A cheap copy of the reference workbook after one run of 'LP rotor'."""
    path = copy_reference(tmp_path_factory.mktemp("safety"), "ran.xlsx")
    make_cheap(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    return path


def _copy(source, folder, name="case.xlsx"):
    target = folder / name
    shutil.copyfile(source, target)
    return target


def test_copied_and_renamed_result_sheets_are_the_users(cheap_ran, tmp_path):
    path = _copy(cheap_ran, tmp_path)
    wb = load_workbook(path)
    copy = wb.copy_worksheet(wb["Result efficiency"])
    copy.title = "Result efficiency (2)"
    copy["A1"] = "kept for the design review"
    wb["Result hinges"].title = "Result LP baseline"
    wb.save(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    wb = load_workbook(path)
    assert {"Result efficiency (2)", "Result LP baseline", "Result efficiency", "Result hinges"} <= set(wb.sheetnames)
    assert wb["Result efficiency (2)"]["A1"].value == "kept for the design review"
    assert wb["Result LP baseline"].max_row == wb["Result hinges"].max_row
    assert sum(n == "Result efficiency" for n in wb.sheetnames) == 1


def _note_column(wb):
    wb["Result efficiency"].cell(2, 11, "reviewed")
    wb["Result efficiency"].cell(3, 11, "OK, see review 12")


def _note_row(wb):
    ws = wb["Result hinges"]
    ws.cell(ws.max_row + 2, 1, "hinge forces below the supplier's limit")


def _changed_note(wb):
    wb["Result model card"]["A1"] = "the baseline of the design review"


@pytest.mark.parametrize("edit, sheet", [(_note_column, "Result efficiency"), (_note_row, "Result hinges"),
                                         (_changed_note, "Result model card")])
def test_a_result_sheet_the_user_annotated_is_not_written_over(cheap_ran, tmp_path, capsys, edit, sheet):
    path = _copy(cheap_ran, tmp_path)
    wb = load_workbook(path)
    edit(wb)
    wb.save(path)
    before = sha256(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    assert f"its result sheets '{sheet}' were changed after mountwb wrote them" in capsys.readouterr().out
    assert sha256(path) == before and len(list(tmp_path.iterdir())) == 2


def test_a_result_sheet_written_before_its_marker_held_a_digest_is_written_again(cheap_ran, tmp_path):
    path = _copy(cheap_ran, tmp_path)
    wb = load_workbook(path)
    wb["Result efficiency"]["Z1"] = "mountwb result sheet: Result efficiency"
    wb["Result efficiency"].cell(3, 11, "a note")
    wb.save(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.xlsx"]


# -- files changed only as asked ---------------------------------------------------------------------------------

_XLSX_MAIN = "application/vnd.openxmlformats-officedocument.spreadsheetml.sheet.main+xml"
_XLSM_MAIN = "application/vnd.ms-excel.sheet.macroEnabled.main+xml"


def _content_types(path):
    with zipfile.ZipFile(path) as archive:
        return archive.read("[Content_Types].xml").decode()


def _rezip(path, edit):
    """Rewrite the zip parts of *path*: ``edit(name, text) -> text`` for XML parts."""
    with zipfile.ZipFile(path) as archive:
        parts = {name: archive.read(name) for name in archive.namelist()}
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in parts.items():
            if name.endswith((".xml", ".rels", ".vml")):
                data = edit(name, data.decode()).encode()
            archive.writestr(name, data)


def test_a_macro_free_xlsm_stays_macro_enabled_and_keeps_its_permissions(tmp_path):
    path = copy_reference(tmp_path, "case.xlsm")
    make_cheap(path)
    _rezip(path, lambda name, text: text.replace(_XLSX_MAIN, _XLSM_MAIN))
    os.chmod(path, 0o640)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    assert _XLSM_MAIN in _content_types(path) and _XLSX_MAIN not in _content_types(path)
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    assert "Result efficiency" in load_workbook(path).sheetnames
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.xlsm"]


def test_template_never_replaces_a_file_unless_asked(tmp_path, capsys):
    path = copy_reference(tmp_path)
    digest = sha256(path)
    assert main(["template", str(path)]) == 0
    out = capsys.readouterr().out
    assert sha256(path) == digest
    beside = [p for p in tmp_path.iterdir() if p.name.startswith("case-template-")]
    assert len(beside) == 1 and f"template written to {beside[0]}" in out and "case.xlsx exists" in out
    assert main(["template", str(path), "--replace"]) == 0
    assert sha256(path) != digest and "Result efficiency" not in load_workbook(path).sheetnames


def test_a_workbook_open_in_libreoffice_is_not_overwritten(cheap_ran, tmp_path, capsys):
    path = _copy(cheap_ran, tmp_path)
    report = tmp_path / "report.xlsx"
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor", "--report", str(report)]) == 0
    for name in ("case.xlsx", "report.xlsx"):
        (tmp_path / f".~lock.{name}#").write_text(",engineer,host,22.11.2026 21:00,file:///home/engineer/.config;")
    digests = [sha256(path), sha256(report)]
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor", "--report", str(report)]) == 0
    out = capsys.readouterr().out
    assert "open in LibreOffice (lock file .~lock.case.xlsx# present)" in out
    assert "open in LibreOffice (lock file .~lock.report.xlsx# present)" in out
    assert [sha256(path), sha256(report)] == digests
    assert len([p for p in tmp_path.iterdir() if p.name.startswith("case-results-")]) == 1
    assert len([p for p in tmp_path.iterdir() if p.name.startswith("report-report-")]) == 1


def test_a_report_replaces_only_a_report(cheap_ran, tmp_path, capsys):
    path = _copy(cheap_ran, tmp_path)
    notes = tmp_path / "notes.xlsx"
    Workbook().save(notes)
    digest = sha256(notes)
    report = tmp_path / "report.xlsx"
    for target in (notes, report, report):
        assert main(["run", str(path), "--no-progress", "--run", "LP rotor", "--report", str(target)]) == 0
    assert sha256(notes) == digest
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names[:1] == ["case.xlsx"] and names[-2:] == ["notes.xlsx", "report.xlsx"] and len(names) == 4
    assert names[1].startswith("notes-report-")
    assert load_workbook(report).sheetnames[0] == "Summary"


_SAVE_FOREVER = """
import sys
from openpyxl import Workbook
from workbook.excel.files import save_atomic
wb = Workbook()
for row in range(1, 4001):
    wb.active.append([row, row * 0.5, "some text in a cell", row * 2.0, "more text"])
open(sys.argv[2], "w").close()
while True:
    save_atomic(wb, sys.argv[1])
"""


@pytest.mark.slow
def test_a_kill_during_a_save_leaves_no_file_behind(tmp_path):
    path = copy_reference(tmp_path)
    ready = tmp_path.parent / f"{tmp_path.name}-ready"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    for delay in (0.3, 0.7, 1.1):
        ready.unlink(missing_ok=True)
        process = subprocess.Popen([sys.executable, "-c", _SAVE_FOREVER, str(path), str(ready)], env=env)
        while not ready.exists():
            time.sleep(0.05)
        time.sleep(delay)
        process.send_signal(signal.SIGKILL)
        process.wait()
        assert sorted(p.name for p in tmp_path.iterdir()) == ["case.xlsx"]
        load_workbook(path)


# -- bounded reading, messages -----------------------------------------------------------------------------------


def test_merged_cells_are_one_problem_not_many(tmp_path):
    path = copy_reference(tmp_path)
    wb = load_workbook(path)
    wb["Links"].merge_cells("C3:G5")
    wb.save(path)
    with pytest.raises(WorkbookError) as error:
        read_workbook(path)
    assert [(p.sheet, p.cell) for p in error.value.problems] == [("Links", "C3:G5")]


def _limited(megabytes):
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (megabytes * 2**20, megabytes * 2**20))
    return limit


def _mountwb(*args, memory_mb=1500):
    """``mountwb ARGS`` in a process of its own, with at most *memory_mb* of address space."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
               OPENBLAS_NUM_THREADS="1")
    return subprocess.run([sys.executable, "-m", "workbook.cli.main", *map(str, args)], env=env, text=True,
                          capture_output=True, preexec_fn=_limited(memory_mb))


def test_a_stray_cell_in_the_last_row_costs_nothing(tmp_path):
    """One note in row 1,048,576 of an input sheet and one of the Instructions: read and written back bounded."""
    path = copy_reference(tmp_path)
    make_cheap(path)
    wb = load_workbook(path)
    wb["Hinges"].cell(1, 30, "# remarks")
    wb["Hinges"].cell(1048576, 30, "stray note")
    wb["Instructions"].cell(1048576, 12, "stray note")
    wb.save(path)
    checked = _mountwb("check", path, memory_mb=1200)
    assert checked.returncode == 0, checked.stderr
    ran = _mountwb("run", path, "--no-progress", "--run", "LP rotor", memory_mb=1500)
    assert ran.returncode == 0, ran.stderr
    with zipfile.ZipFile(path) as archive:
        rows = {name: archive.read(name).count(b"<row ") for name in archive.namelist()
                if name.startswith("xl/worksheets/sheet")}
    assert max(rows.values()) < 1000
    wb = load_workbook(path)
    assert wb["Hinges"].cell(1048576, 30).value == "stray note" and "Result efficiency" in wb.sheetnames


def test_a_workbook_too_large_to_read_is_refused(tmp_path):
    path = copy_reference(tmp_path)
    with zipfile.ZipFile(path, "a", zipfile.ZIP_DEFLATED) as archive, archive.open("xl/media/filler.bin", "w",
                                                                                    force_zip64=True) as member:
        for _ in range(MAX_UNPACKED_BYTES // 2**24 + 1):
            member.write(bytes(2**24))
    assert path.stat().st_size < 2_000_000
    checked = _mountwb("check", path, memory_mb=1200)
    assert checked.returncode == 2
    assert "parts that unpack to" in checked.stderr and "at most 250,000,000 bytes" in checked.stderr


def test_a_refusal_is_printed_once(cheap_ran, tmp_path):
    path = _copy(cheap_ran, tmp_path)
    (tmp_path / "~$case.xlsx").write_bytes(b"engineer")
    ran = _mountwb("run", path, "--no-progress", "--run", "LP rotor")
    assert ran.returncode == 0, ran.stderr
    assert (ran.stdout + ran.stderr).count("open in Excel (lock file ~$case.xlsx present)") == 1


# -- what a write-back keeps, and what makes it refuse -------------------------------------------------------------


def test_rich_text_and_the_cached_values_of_date_formulas_are_kept(cheap_ran, tmp_path):
    path = _copy(cheap_ran, tmp_path)
    wb = load_workbook(path)
    hinges = wb["Hinges"]
    hinges.cell(1, 30, "# checked on")
    hinges.cell(3, 30, "=DATE(2026,11,1)").number_format = "yyyy-mm-dd"
    hinges.cell(4, 30, CellRichText(["bearing ", TextBlock(InlineFont(b=True), "replaced"), " in 2025"]))
    wb.save(path)
    sheet = f"xl/worksheets/sheet{wb.sheetnames.index('Hinges') + 1}.xml"
    give_cached_value(path, sheet, "AD3", 46327)
    assert load_workbook(path, data_only=True)["Hinges"]["AD3"].value == datetime.datetime(2026, 11, 1)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.xlsx"]
    assert load_workbook(path, data_only=True)["Hinges"]["AD3"].value == datetime.datetime(2026, 11, 1)
    rich = load_workbook(path, rich_text=True)["Hinges"]["AD4"].value
    assert isinstance(rich, CellRichText) and str(rich) == "bearing replaced in 2025"
    assert [block.font.b for block in rich if isinstance(block, TextBlock)] == [True]


def test_formulas_on_the_results_do_not_keep_the_earlier_results(cheap_ran, tmp_path):
    """A formula of the user's that takes a result is saved without a value, for Excel and LibreOffice to
    calculate: the value it had is that of the earlier results. The others keep theirs."""
    path = _copy(cheap_ran, tmp_path)
    wb = load_workbook(path)
    notes = wb.create_sheet("My notes")
    formulas = {"A1": "='Result efficiency'!H3", "A2": "=A1*2", "A3": "=ETA_x", "A4": 'INDIRECT("\'Result model card\'!A1")',
                "A5": "=SUM('MY NOTES'!A1:A2)", "B1": "=Engine!A3*2", "B2": "=B1+SUM(A6:A9)"}
    for cell, formula in formulas.items():
        notes[cell] = formula if formula.startswith("=") else f"={formula}"
    wb.defined_names["eta_x"] = DefinedName("eta_x", attr_text="'Result efficiency'!$H$3")
    wb.save(path)
    sheet = f"xl/worksheets/sheet{wb.sheetnames.index('My notes') + 1}.xml"
    for cell in formulas:
        give_cached_value(path, sheet, cell, 7136 if cell.startswith("B") else -29.5)
    assert load_workbook(path, data_only=True)["My notes"]["A2"].value == -29.5
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    notes = load_workbook(path, data_only=True)["My notes"]
    assert {cell: notes[cell].value for cell in formulas} == {"A1": None, "A2": None, "A3": None, "A4": None,
                                                              "A5": None, "B1": 7136, "B2": 7136}


def test_result_sheets_written_again_keep_their_place_among_the_sheets(cheap_ran, tmp_path):
    path = _copy(cheap_ran, tmp_path)
    wb = load_workbook(path)
    wb.move_sheet("Result efficiency", -wb.sheetnames.index("Result efficiency"))
    wb.create_sheet("My notes")
    wb.active = wb.sheetnames.index("My notes")
    wb.save(path)
    order = wb.sheetnames
    assert order[0] == "Result efficiency" and order[-1] == "My notes"
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    wb = load_workbook(path)
    assert (wb.sheetnames, wb.active.title) == (order, "My notes")


def _add_part(path, name, content_type, data=b"<x/>"):
    """Add a zip part with its content type, as Excel writes a feature openpyxl does not know."""
    _rezip(path, lambda member, text: text.replace(
        "</Types>", f'<Override PartName="/{name}" ContentType="{content_type}"/></Types>')
        if member == "[Content_Types].xml" else text)
    with zipfile.ZipFile(path, "a") as archive:
        archive.writestr(name, data)


def _company(path):
    _rezip(path, lambda name, text: text.replace("</Properties>", "<Company>Acme Aero</Company></Properties>")
           if name == "docProps/app.xml" else text)


def _resized_comment(path):
    wb = load_workbook(path)
    wb["Hinges"]["A5"].comment = Comment("see the supplier's drawing", "J. Doe", height=200, width=400)
    wb.save(path)


def _shown_comment(path):
    _rezip(path, lambda name, text: text.replace("visibility:hidden", "visibility:visible")
           if name.endswith(".vml") else text)


@pytest.mark.parametrize("change, found", [
    (lambda p: _add_part(p, "xl/threadedComments/threadedComment1.xml",
                         "application/vnd.ms-excel.threadedcomments+xml"), "threaded comments"),
    (lambda p: _add_part(p, "xl/metadata.xml", "application/vnd.openxmlformats-officedocument.spreadsheetml."
                                               "sheetMetadata+xml"), "dynamic-array formulas (cell metadata)"),
    (_company, "document properties (Company)"),
    (_resized_comment, "comment boxes resized or always shown"),
    (lambda p: (_resized_comment(p), _shown_comment(p)), "comment boxes resized or always shown"),
])
def test_content_openpyxl_would_drop_is_detected(tmp_path, change, found):
    path = copy_reference(tmp_path)
    wb = load_workbook(path)
    wb["Hinges"]["A4"].comment = Comment("a comment of the default size is kept", "J. Doe")
    wb.save(path)
    assert unsupported_content(path) == []
    change(path)
    assert unsupported_content(path) == [found]


def test_any_kind_of_part_a_rewrite_would_lose_is_found(tmp_path):
    path = copy_reference(tmp_path)
    before = path.read_bytes()
    assert lost_parts(before, workbook_bytes(load_workbook(path), path)) == []
    _add_part(path, "xl/feature/part1.xml", "application/vnd.example.feature+xml")
    assert unsupported_content(path) == []
    assert lost_parts(path.read_bytes(), workbook_bytes(load_workbook(path), path)) == [
        "xl/feature/part1.xml (application/vnd.example.feature+xml)"]


def test_a_part_the_rewrite_would_lose_sends_the_results_beside(cheap_ran, tmp_path, capsys):
    path = _copy(cheap_ran, tmp_path)
    _add_part(path, "xl/feature/part1.xml", "application/vnd.example.feature+xml")
    digest = sha256(path)
    assert main(["run", str(path), "--no-progress", "--run", "LP rotor"]) == 0
    out = capsys.readouterr().out
    assert "cannot keep (xl/feature/part1.xml (application/vnd.example.feature+xml))" in out
    assert sha256(path) == digest
    assert len([p for p in tmp_path.iterdir() if p.name.startswith("case-results-")]) == 1


def test_a_workbook_named_through_a_link_stays_linked(cheap_ran, tmp_path):
    target = _copy(cheap_ran, tmp_path, "stored.xlsx")
    link = tmp_path / "case.xlsx"
    link.symlink_to(target.name)
    assert main(["run", str(link), "--no-progress", "--run", "HP rotor"]) == 0
    assert link.is_symlink() and sorted(p.name for p in tmp_path.iterdir()) == ["case.xlsx", "stored.xlsx"]
    rows = load_workbook(target)["Result efficiency"].iter_rows(min_row=3, values_only=True)
    assert {row[0] for row in rows} == {"LP rotor", "HP rotor"}
