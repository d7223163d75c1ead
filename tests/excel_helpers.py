"""Helpers of the Excel-layer tests: edit case workbooks cell by header."""
from __future__ import annotations

import hashlib
import shutil
import subprocess
import zipfile
from pathlib import Path

from openpyxl import load_workbook

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "cases" / "reference.xlsx"
TEMPLATE = ROOT / "templates" / "case-template.xlsx"
#: LibreOffice's command line, or None when it is not installed.
SOFFICE = shutil.which("soffice")


def column_of(ws, header: str) -> int:
    """Column number of *header* in row 1."""
    for cell in ws[1]:
        if cell.value == header:
            return cell.column
    raise KeyError(header)


def set_cells(path: Path, edits: dict) -> None:
    """Apply ``{(sheet, header, row): value}`` to the workbook at *path*."""
    wb = load_workbook(path)
    for (sheet, header, row), value in edits.items():
        wb[sheet].cell(row, column_of(wb[sheet], header)).value = value
    wb.save(path)


def copy_reference(folder: Path, name: str = "case.xlsx") -> Path:
    target = folder / name
    shutil.copyfile(REFERENCE, target)
    return target


#: Short settings that make a run take about a second (answers within tens of %).
CHEAP_SETTINGS = {"steps per period": 20, "ramp periods": 2, "settle time": 0.05, "measured periods": 4,
                  "steady tolerance": 0.5, "method": "time"}


def make_cheap(path: Path, sweep_points: int = 4) -> None:
    """Short settings, coarse rigid links and a short sweep in the workbook at *path*."""
    wb = load_workbook(path)
    for header, value in CHEAP_SETTINGS.items():
        wb["Case"].cell(3, column_of(wb["Case"], header), value)
    links = wb["Links"]
    for row in range(3, links.max_row + 1):
        links.cell(row, column_of(links, "element size"), 30)
    runs = wb["Runs"]
    for row in range(3, runs.max_row + 1):
        runs.cell(row, column_of(runs, "fidelity"), "rigid")
    excitations = wb["Excitations"]
    for row in range(3, excitations.max_row + 1):
        if excitations.cell(row, column_of(excitations, "sweep points")).value is not None:
            excitations.cell(row, column_of(excitations, "sweep points"), sweep_points)
    wb.save(path)


def give_cached_value(path: Path, member: str, cell: str, value, error: bool = False) -> None:
    """Store *value* as the cached result of the formula in *cell* of zip *member* (as Excel would).

    *error*: the value is a formula error such as ``#VALUE!`` (cell type ``e``).
    """
    with zipfile.ZipFile(path) as archive:
        contents = {name: archive.read(name) for name in archive.namelist()}
    xml = contents[member].decode()
    start = xml.index(f'<c r="{cell}"')
    end = xml.index("</c>", start)
    cell_xml = xml[start:end].replace("<v></v>", "").replace("<v />", "")
    if error:
        cell_xml = cell_xml.replace(f'<c r="{cell}"', f'<c r="{cell}" t="e"', 1)
    contents[member] = (xml[:start] + cell_xml + f"<v>{value}</v>" + xml[end:]).encode()
    with zipfile.ZipFile(path, "w") as archive:
        for name, data in contents.items():
            archive.writestr(name, data)


def sha256(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def compound_file(streams: dict) -> bytes:
    """A Microsoft compound file (OLE2, the container of .xls and of password-protected workbooks).

    Parameters
    ----------
    streams : dict of str to int
        Stream name -> size in bytes (a multiple of 512, at least 4096: kept
        out of the mini stream). At most three streams.
    """
    import struct

    end, free, fat_sector, no_stream = 0xFFFFFFFE, 0xFFFFFFFF, 0xFFFFFFFD, 0xFFFFFFFF
    fat = [fat_sector, end]             # sector 0: the FAT, sector 1: the directory
    starts, data = [], b""
    for size in streams.values():
        starts.append(len(fat))
        count = size // 512
        fat += [len(fat) + i + 1 for i in range(count - 1)] + [end]
        data += bytes(size)
    fat += [free] * (128 - len(fat))
    header = struct.pack("<8s16sHHHHH6sIIIIIIIII", bytes.fromhex("d0cf11e0a1b11ae1"), bytes(16), 0x3E, 3, 0xFFFE,
                         9, 6, bytes(6), 0, 1, 1, 0, 4096, end, 0, end, 0)
    header += struct.pack("<I", 0) + struct.pack("<I", free) * 108

    def entry(name, kind, left, right, child, start, size):
        encoded = (name + "\0").encode("utf-16-le")
        return struct.pack("<64sHBBIII16sIQQIQ", encoded, len(encoded), kind, 1, left, right, child, bytes(16), 0,
                           0, 0, start, size)

    names = list(streams)
    entries = [entry("Root Entry", 5, no_stream, no_stream, 1, end, 0)]
    for i, name in enumerate(names, start=1):
        entries.append(entry(name, 2, no_stream, i + 1 if i < len(names) else no_stream, no_stream,
                             starts[i - 1], streams[name]))
    directory = b"".join(entries) + bytes(128) * (4 - len(entries))
    return header + struct.pack("<128I", *fat) + directory + data


def soffice_convert(folder: Path, target: str, *files, outdir) -> None:
    """``soffice --headless --convert-to TARGET`` with a profile of its own in *folder*."""
    profile = (Path(folder) / "lo-profile").as_uri()
    result = subprocess.run([SOFFICE, "--headless", f"-env:UserInstallation={profile}", "--convert-to", target,
                             "--outdir", str(outdir), *map(str, files)], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr


def save_in_libreoffice(path: Path, scratch: Path) -> Path:
    """Open the workbook at *path* in LibreOffice and save it in place as .xlsx, as a user would.

    LibreOffice's profile and its output go to the folder *scratch* (not beside *path*).
    """
    path = Path(path)
    outdir = Path(scratch) / "libreoffice-saved"
    soffice_convert(scratch, "xlsx", path, outdir=outdir)
    shutil.move(outdir / path.name, path)
    return path


def saved_by_libreoffice(*paths: Path) -> None:
    """Open each workbook in LibreOffice Calc (headless) and save it as .xlsx in its place, as a user who
    edits a case in LibreOffice does; one LibreOffice start for all of *paths* (in one folder).

    Skips the calling test when ``soffice`` is not on PATH.
    """
    import pytest

    if SOFFICE is None:
        pytest.skip("LibreOffice (soffice) is not on PATH: apt-get install libreoffice-calc-nogui")
    folder = Path(paths[0]).parent
    out = folder / "saved-by-libreoffice"
    soffice_convert(folder, "xlsx:Calc MS Excel 2007 XML", *paths, outdir=out)
    for path in paths:
        shutil.move(out / Path(path).name, path)
    shutil.rmtree(out)
    shutil.rmtree(folder / "lo-profile", ignore_errors=True)
