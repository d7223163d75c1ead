"""Workbook files on disk: atomic saves and the checks made before overwriting one.

A save writes the whole new file, with the type (``.xlsx`` or macro-enabled
``.xlsm``) and the permissions of the file it replaces, and then renames it
over the old one in one step: a reader, or a kill at any moment, sees the
old file or the new one. Where the system allows (Linux), the new file has
no name until it is complete, so a kill during the save leaves nothing
behind.

A file the user cannot write (no write permission, e.g. mode 444) is never
replaced, even where the folder would allow it. A save that is told what
the file held when it was read checks it again just before the rename and
replaces nothing when the file changed meanwhile (:class:`ChangedOnDisk`);
:func:`held` makes the ``mountwb`` processes writing one workbook take
turns.

openpyxl rewrites a whole workbook from what it understood; content it does
not understand is dropped silently. :func:`unsupported_content` looks inside
the .xlsx (a zip archive) for such content, so that a run can refuse to
overwrite the file and write its results elsewhere instead.
"""
from __future__ import annotations

import datetime
import errno
import hashlib
import io
import logging
import os
import re
import stat
import zipfile
from contextlib import contextmanager
from pathlib import Path
from typing import Callable
from xml.sax.saxutils import escape

from openpyxl.utils.datetime import to_excel

from flexbodies.atomic import replacing
from workbook.answers.saving import record_written
from workbook.errors import MountwbError

try:
    import fcntl
except ImportError:  # Windows: no advisory locks
    fcntl = None  # type: ignore[assignment]

__all__ = ["save_atomic", "lock_file", "lock_message", "unsupported_content", "restore_formula_values",
           "name_beside", "workbook_bytes", "new_file_target", "bounded_file_problem", "lost_parts", "write_atomic",
           "ChangedOnDisk", "held", "read_only_message", "signed", "untouched"]

log = logging.getLogger(__name__)

#: Zip members (by name prefix or exact name) openpyxl drops or may mangle, and what they are.
_MEMBERS = (
    ("xl/charts/", "charts"),
    ("xl/chartsheets/", "chart sheets"),
    ("xl/media/", "images"),
    ("xl/pivotTables/", "pivot tables"),
    ("xl/pivotCache/", "pivot caches"),
    ("xl/vbaProject.bin", "macros (VBA)"),
    ("xl/externalLinks/", "external links"),
    ("xl/slicers/", "slicers"),
    ("xl/slicerCaches/", "slicers"),
    ("xl/timelines/", "timelines"),
    ("xl/ctrlProps/", "form controls"),
    ("xl/activeX/", "ActiveX controls"),
    ("xl/embeddings/", "embedded objects"),
    ("xl/model/", "a data model"),
    ("xl/queryTables/", "queries"),
    ("xl/connections.xml", "data connections"),
    ("customXml/", "custom XML parts"),
    ("xl/threadedComments/", "threaded comments"),
    ("xl/persons/", "threaded comments"),
    ("xl/metadata.xml", "dynamic-array formulas (cell metadata)"),
    ("xl/richData/", "pictures or data types in cells"),
    ("xl/webextensions/", "add-ins"),
    ("xl/namedSheetViews/", "sheet views"),
)
#: Document properties (docProps/app.xml) openpyxl does not keep, when they hold text.
_APP_PROPERTIES = ("Company", "Manager", "HyperlinkBase")
_APP_PROPERTY = re.compile(rb"<(?:\w+:)?(" + b"|".join(p.encode() for p in _APP_PROPERTIES) + rb")>([^<]+)</")
#: A comment box in a legacy drawing: its style (size, visibility).
_NOTE = re.compile(rb'<(?:\w+:)?shape\b[^>]*?style="([^"]*)"[^>]*>(?:(?!</(?:\w+:)?shape>).)*?ObjectType="Note"', re.S)
#: Box of a comment as openpyxl writes it (Excel's default too): 144 x 79 px = 108 x 59.25 pt, hidden.
_NOTE_BOX_PT = (108.0, 59.25)
#: Parts whose loss is harmless: Excel rebuilds the calculation chain and the thumbnail, the
#: printer-driver settings are device data (the page setup itself is kept), and the shared-strings
#: table (Excel and LibreOffice write one) is rewritten into the cells as their text.
_REBUILT_TYPES = ("calcChain+xml", "printerSettings", "image/jpeg", "sharedStrings+xml")
#: Custom document properties: openpyxl keeps them; a part without any (LibreOffice writes one) holds nothing.
_CUSTOM_PROPERTIES = "custom-properties+xml"
_CUSTOM_PROPERTY = re.compile(rb"<(?:\w+:)?property\b")
#: Worksheet extensions (extLst) openpyxl drops.
_EXTENSIONS = (
    (re.compile(rb"<x14:dataValidations?\b"), "data-validation extensions (lists from other sheets)"),
    (re.compile(rb"<x14:conditionalFormattings?\b"), "conditional-formatting extensions"),
    (re.compile(rb"<x14:sparklineGroups?\b"), "sparklines"),
)
_SHEET = re.compile(r"^xl/worksheets/[^/]+\.xml$")
#: Shapes in a drawing (text boxes, arrows) are dropped even when images are kept.
_SHAPE = re.compile(rb"<xdr:sp\b")


def unsupported_content(path: str | Path) -> list[str]:
    """What in the workbook at *path* openpyxl would drop on saving (empty: nothing).

    Parameters
    ----------
    path : str or Path
        An .xlsx or .xlsm file.

    Returns
    -------
    list of str
        Plain-word descriptions, e.g. ``["charts", "macros (VBA)"]``.
    """
    found = []
    with zipfile.ZipFile(path) as archive:
        names = archive.namelist()
        for prefix, what in _MEMBERS:
            if any(name == prefix or name.startswith(prefix) for name in names) and what not in found:
                found.append(what)
        for name in names:
            if name.startswith("xl/drawings/") and name.endswith(".xml") and "_rels" not in name:
                if _SHAPE.search(archive.read(name)) and "drawn shapes" not in found:
                    found.append("drawn shapes")
            if _SHEET.match(name):
                data = archive.read(name)
                for pattern, what in _EXTENSIONS:
                    if what not in found and pattern.search(data):
                        found.append(what)
            if name.endswith(".vml") and "comment boxes resized or always shown" not in found:
                if any(_custom_note(style) for style in _NOTE.findall(archive.read(name))):
                    found.append("comment boxes resized or always shown")
        if "docProps/app.xml" in names:
            given = [key.decode() for key, text in _APP_PROPERTY.findall(archive.read("docProps/app.xml"))
                     if text.strip()]
            if given:
                found.append(f"document properties ({', '.join(given)})")
    return found


def _custom_note(style: bytes) -> bool:
    """True if a comment box's VML style is not the default size, or the comment is always shown."""
    fields = dict(item.split(":", 1) for item in style.decode().replace(" ", "").split(";") if ":" in item)
    if fields.get("visibility", "hidden") != "hidden":
        return True
    for key, default in zip(("width", "height"), _NOTE_BOX_PT, strict=True):
        text = fields.get(key, "")
        match = re.fullmatch(r"([0-9.]+)(pt|px|in|cm|mm)?", text)
        if not match:
            return True
        scale = {"pt": 1.0, "px": 0.75, "in": 72.0, "cm": 72 / 2.54, "mm": 72 / 25.4, None: 1.0}[match.group(2)]
        if abs(float(match.group(1)) * scale - default) > 0.5:
            return True
    return False


def _content_types(data: bytes) -> dict[str, str]:
    """Content type of each part of the zip archive *data*, by part name."""
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        names = [name for name in archive.namelist() if not name.endswith("/")]
        xml = archive.read("[Content_Types].xml").decode("utf-8")
    defaults = dict(re.findall(r'<Default\s+Extension="([^"]+)"\s+ContentType="([^"]+)"', xml))
    defaults = {key.lower(): value for key, value in defaults.items()}
    overrides = {name.lstrip("/"): kind for name, kind in
                 re.findall(r'<Override\s+PartName="([^"]+)"\s+ContentType="([^"]+)"', xml)}
    return {name: overrides.get(name) or defaults.get(name.rsplit(".", 1)[-1].lower(), "unknown")
            for name in names if name != "[Content_Types].xml"}


def lost_parts(before: bytes, after: bytes) -> list[str]:
    """Parts of the workbook *before* of a kind the rewritten workbook *after* no longer has.

    A safety net under :func:`unsupported_content`: any kind of part (by
    content type) that the rewrite dropped, except those Excel rebuilds, the
    shared strings (their text is kept in the cells) and custom document
    properties that hold none.

    Returns
    -------
    list of str
        ``"<part name> (<content type>)"`` for each part lost.
    """
    kept = set(_content_types(after).values())
    with zipfile.ZipFile(io.BytesIO(before)) as archive:
        return [f"{name} ({kind})" for name, kind in _content_types(before).items()
                if kind not in kept and not any(harmless in kind for harmless in _REBUILT_TYPES)
                and not (kind.endswith(_CUSTOM_PROPERTIES) and not _CUSTOM_PROPERTY.search(archive.read(name)))]


def lock_file(path: str | Path) -> Path | None:
    """The lock file beside *path* if present: the workbook is open in Excel or LibreOffice.

    Excel writes ``~$<name>``, LibreOffice ``.~lock.<name>#``.
    """
    path = Path(path)
    for lock in (path.with_name("~$" + path.name), path.with_name(f".~lock.{path.name}#")):
        if lock.exists():
            return lock
    return None


def lock_message(lock: Path) -> str:
    """Plain words for a lock file found by :func:`lock_file`."""
    application = "LibreOffice" if lock.name.startswith(".~lock.") else "Excel"
    return f"it is open in {application} (lock file {lock.name} present); close it and run again to write into it"


class ChangedOnDisk(MountwbError):
    """The file changed on disk after it was read (another save landed): it was not replaced (exit 1)."""


def read_only_message(path: str | Path) -> str | None:
    """Why the existing file at *path* may not be replaced (None: it may be, or it does not exist).

    A file without any write permission (mode 444) is read-only even for a
    user the system would let write it (the owner of the folder, root).
    """
    try:
        mode = stat.S_IMODE(Path(path).stat().st_mode)
    except FileNotFoundError:
        return None
    if mode & 0o222 and os.access(path, os.W_OK):
        return None
    return f"it is read-only (mode {mode:o}); make it writable to write into it"


@contextmanager
def held(path: str | Path):
    """Hold an exclusive lock on the file at *path* while it is checked and replaced.

    Another ``mountwb`` process writing the same file waits for the lock,
    then finds the file changed. The lock is advisory: Excel and LibreOffice
    do not take it (their saves are caught by the check before the rename).
    Where the system has no locks, nothing is held.
    """
    try:
        handle = os.open(path, os.O_RDONLY)
    except OSError:
        handle = None
    try:
        if handle is not None and fcntl is not None:
            try:
                fcntl.flock(handle, fcntl.LOCK_EX)
            except OSError as error:  # a file system without locks
                log.info("cannot lock %s (%s); writing without the lock", path, error)
        yield
    finally:
        if handle is not None:
            os.close(handle)


def _still(path: Path, sha256: str | None) -> None:
    """Raise :class:`ChangedOnDisk` unless the file at *path* still has the SHA-256 *sha256* (None: no check)."""
    if sha256 is not None and hashlib.sha256(path.read_bytes()).hexdigest() != sha256:
        raise ChangedOnDisk(f"{path.name} changed on disk after it was read")


def name_beside(path: str | Path, label: str, suffix: str = ".xlsx") -> Path:
    """A new file name beside *path*: ``<stem>-<label>-<date-time><suffix>`` (``-2``, ``-3``... if taken)."""
    path = Path(path)
    stamp = datetime.datetime.now().strftime("%Y%m%d-%H%M%S")
    candidate = path.with_name(f"{path.stem}-{label}-{stamp}{suffix}")
    number = 1
    while candidate.exists():
        number += 1
        candidate = path.with_name(f"{path.stem}-{label}-{stamp}-{number}{suffix}")
    return candidate


def _members_digest(archive: zipfile.ZipFile) -> str:
    """SHA-256 of the names, sizes and CRCs of the members of *archive*: any save by another program changes it."""
    text = "\n".join(f"{info.filename} {info.file_size} {info.CRC:08x}" for info in archive.infolist())
    return hashlib.sha256(text.encode()).hexdigest()


def signed(data: bytes, label: str) -> bytes:
    """The workbook *data* (a zip archive) with a comment saying this program wrote it as a *label*.

    The comment holds a digest of the archive's members: a file another
    program saved (Excel, LibreOffice), or that was edited, no longer
    matches it (:func:`untouched`).
    """
    buffer = io.BytesIO(data)
    with zipfile.ZipFile(buffer, "a") as archive:
        archive.comment = f"mountwb {label} {_members_digest(archive)}".encode()
    return buffer.getvalue()


def untouched(path: str | Path, label: str) -> bool:
    """True if the file at *path* is a *label* this program wrote (:func:`signed`) and nobody saved it since."""
    try:
        with zipfile.ZipFile(path) as archive:
            return archive.comment.decode("ascii", "replace") == f"mountwb {label} {_members_digest(archive)}"
    except (OSError, zipfile.BadZipFile):
        return False


def bounded_file_problem(path: Path, limit: int) -> str | None:
    """Why the file a workbook names at *path* is not read (None: it may be read).

    Only a regular file of at most *limit* bytes is read: a device
    (``/dev/zero``), a pipe or a folder never ends or is not a file; a
    name the system cannot look up (too long) is not read either.
    """
    try:
        if not path.exists():
            return f"{path} does not exist"
        if not path.is_file():
            return f"{path} is not a regular file (a device, a pipe or a folder)"
        size = path.stat().st_size
    except OSError as error:    # a name too long for the file system, a folder that cannot be entered
        return f"{path} cannot be looked at: {error.strerror}"
    if size > limit:
        return f"{path} has {size:,} bytes; at most {limit:,} are read"
    return None


def new_file_target(path: str | Path, label: str, replaceable: Callable[[Path], bool] | None = None):
    """Where a new file the user named goes: *path*, or a new name beside it, and why.

    An existing file is replaced only when ``replaceable(path)`` says it may
    be (a report this package wrote, :func:`untouched`; None: no file may
    be), it is not open in
    Excel or LibreOffice and it is not read-only; otherwise the new file goes
    to :func:`name_beside`, with the ending of *path*.

    Returns
    -------
    (Path, str or None)
        The file to write and the reason it is not *path* (None: it is).
    """
    path = Path(path)
    lock = lock_file(path)
    if lock is not None:
        return name_beside(path, label), lock_message(lock)
    refused = read_only_message(path)
    if refused is not None:
        return name_beside(path, label, path.suffix), refused
    if path.exists() and replaceable is None:
        return name_beside(path, label, path.suffix), f"{path.name} exists; it is kept"
    if path.exists() and replaceable is not None and not replaceable(path):
        return name_beside(path, label, path.suffix), (f"{path.name} exists and is not a {label} this program "
                                                       "wrote, or was changed since; it is kept")
    return path, None


def _cached(value) -> tuple[str, str] | None:
    """(type attribute, text) of a cached formula value; None for a type not restored."""
    if isinstance(value, bool):
        return ' t="b"', "1" if value else "0"
    if isinstance(value, (int, float)):
        return "", repr(float(value)) if isinstance(value, float) else str(value)
    if isinstance(value, str):
        return ' t="str"', escape(value)
    if isinstance(value, (datetime.datetime, datetime.date, datetime.time)):
        return "", repr(float(to_excel(value)))
    return None


def restore_formula_values(data: bytes, cached: dict[int, dict[str, object]]) -> bytes:
    """Put the cached values of formula cells back into an .xlsx openpyxl wrote.

    openpyxl keeps formulas but writes them without the value Excel last
    calculated; a reader of the saved file (this package's included) would
    find none until Excel opened and saved it again.

    Parameters
    ----------
    data : bytes
        The .xlsx written by openpyxl.
    cached : dict of int to dict of str to value
        Per sheet number (1-based position in the workbook), cell -> value.

    Returns
    -------
    bytes
        The .xlsx with the values (*data* itself when there are none).
    """
    if not any(cached.values()):
        return data

    def edit(name: str, xml: bytes) -> bytes:
        match = re.match(r"^xl/worksheets/sheet(\d+)\.xml$", name)
        if not match or int(match.group(1)) not in cached:
            return xml
        text = xml.decode("utf-8")
        for cell, value in cached[int(match.group(1))].items():
            typed = _cached(value)
            if typed is None:
                continue
            pattern = re.compile(rf'<c r="{cell}"([^>]*)>(<f\b[^>]*/>|<f\b[^>]*>.*?</f>)<v\s*/>(</c>)', re.S)

            def filled(m: re.Match, cell: str = cell, typed: tuple = typed) -> str:
                return f'<c r="{cell}"{m.group(1)}{typed[0]}>{m.group(2)}<v>{typed[1]}</v></c>'

            text = pattern.sub(filled, text)
        return text.encode("utf-8")

    return _edit_members(data, edit)


def _edit_members(data: bytes, edit: Callable[[str, bytes], bytes]) -> bytes:
    """The zip archive *data* with each member replaced by ``edit(name, content)``."""
    output = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(data)) as source, zipfile.ZipFile(output, "w", zipfile.ZIP_DEFLATED) as target:
        for info in source.infolist():
            target.writestr(info, edit(info.filename, source.read(info.filename)))
    return output.getvalue()


_XLSX_MAIN = b"application/vnd.openxmlformats-officedocument.spreadsheetml.sheet.main+xml"
_XLSM_MAIN = b"application/vnd.ms-excel.sheet.macroEnabled.main+xml"


def _macro_enabled(name: str, xml: bytes) -> bytes:
    """The content types of a macro-enabled workbook (.xlsm), which openpyxl writes as .xlsx."""
    return xml.replace(_XLSX_MAIN, _XLSM_MAIN) if name == "[Content_Types].xml" else xml


def workbook_bytes(workbook, path: str | Path) -> bytes:
    """The file openpyxl writes for *workbook*, typed by the ending of *path* (.xlsx or .xlsm)."""
    buffer = io.BytesIO()
    workbook.save(buffer)
    data = buffer.getvalue()
    return _edit_members(data, _macro_enabled) if Path(path).suffix.lower() == ".xlsm" else data


def _mode(path: Path) -> int:
    """Permissions of the file at *path*, or those a new file gets under the umask."""
    try:
        return stat.S_IMODE(path.stat().st_mode)
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def _replace_unnamed(path: Path, data: bytes, mode: int, unchanged: str | None) -> bool:
    """Write *data* to a file without a name, then name it *path* (False: the system cannot).

    *unchanged*: the SHA-256 *path* must still have just before the rename (None: no check).
    """
    flag = getattr(os, "O_TMPFILE", None)
    if flag is None:
        return False
    folder = os.open(path.parent, os.O_RDONLY | os.O_DIRECTORY)
    try:
        try:
            handle = os.open(path.parent, flag | os.O_WRONLY, mode)
        except OSError:
            return False
        try:
            with os.fdopen(handle, "wb", closefd=False) as stream:
                stream.write(data)
            os.fchmod(handle, mode)
            os.fsync(handle)
            linked = f".~{path.name}.{os.getpid()}.saving"
            os.link(f"/proc/self/fd/{handle}", linked, dst_dir_fd=folder, follow_symlinks=True)
        finally:
            os.close(handle)
        try:
            _still(path, unchanged)
            os.replace(linked, path.name, src_dir_fd=folder, dst_dir_fd=folder)
        except BaseException:
            os.unlink(linked, dir_fd=folder)
            raise
    finally:
        os.close(folder)
    return True


def write_atomic(path: str | Path, data: bytes, unchanged: str | None = None) -> Path:
    """Write *data* to *path* all at once, with the permissions of the file it replaces.

    A symbolic link stays a link: the file it points to is replaced.

    Parameters
    ----------
    path : str or Path
    data : bytes
    unchanged : str, optional
        SHA-256 (hex) the file at *path* must still have just before the
        rename: the content it had when it was read.

    Returns
    -------
    Path

    Raises
    ------
    PermissionError
        *path* is read-only (:func:`read_only_message`); nothing is written.
    ChangedOnDisk
        *path* no longer has the SHA-256 *unchanged*; nothing is replaced.
    """
    path = Path(path).resolve()
    refused = read_only_message(path)
    if refused is not None:
        raise PermissionError(errno.EACCES, f"{path.name}: {refused}")
    path.parent.mkdir(parents=True, exist_ok=True)
    mode = _mode(path)
    if not _replace_unnamed(path, data, mode, unchanged):
        with replacing(path, suffix=".saving") as temporary:
            temporary.write_bytes(data)
            _still(path, unchanged)
    record_written(path)
    log.info("saved %s", path)
    return path


def save_atomic(workbook, path: str | Path, finish: Callable[[bytes], bytes] | None = None) -> Path:
    """Save an openpyxl workbook to *path* atomically.

    The file is built in memory, written whole beside *path* and renamed
    over it, so *path* is never half-written; it keeps the permissions of
    the workbook it replaces, and an .xlsm stays a macro-enabled workbook.

    Parameters
    ----------
    workbook : openpyxl.Workbook
    path : str or Path
    finish : callable, optional
        Post-processes the file's bytes before they are written.

    Returns
    -------
    Path
    """
    path = Path(path)
    data = workbook_bytes(workbook, path)
    if finish is not None:
        data = finish(data)
    return write_atomic(path, data)
