"""The on-disk store of reduced bodies: verified entries, a lock per body, and no run stopped by it.

The links, the engine casing and the mesh pylon share it. Three kinds of
entry, each named by its key (a hash of every input it depends on):

- ``fe-<key>.json``: the reference frequencies of a body's FE model;
- ``link-<key>.npz``: a reduced free body, a link or the casing
  (:class:`~flexbodies.reduced.ReducedBody`; the name is the files' since
  the first release);
- ``clamped-<key>.npz``: a reduced clamped body, the mesh pylon
  (:class:`~flexbodies.reduced.ClampedReduction`).

Beside them, :mod:`flexbodies.geometric_stiffness` keeps a link's geometric
stiffness (``stiffening-<key>.npz``) and its projections on mode bases
(``stiffening-<key>-<basis>.npy``); the store lists, checks (readable) and
clears them too.

The reduced bodies carry their own key and a SHA-256 checksum of their content. An entry
whose stored key is not the key of its name, whose checksum does not match,
or that cannot be read is *corrupt*: it is reported once (naming the file),
never used, and replaced by the recomputed entry.

The store never stops a run: a folder that cannot be created, read or
written (read-only, full, or ``MOUNTWB_CACHE`` naming a file) gives one
warning naming the folder and the reason, and the run goes on without the
store. Two processes that need the same body compute it once: the first
holds a lock file (``.<key>.lock``) while it computes, the second waits for
it (at most :func:`lock_timeout` s, then computes on its own with a warning)
and loads the result. Temporary files that a killed process left behind
are removed by the next process that finds them older than
:data:`STALE_SECONDS`.
"""
from __future__ import annotations

import hashlib
import json
import logging
import os
import time
import zipfile
from collections import OrderedDict
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from workbook._renamed import renamed, renamed_names

from .atomic import replacing
from .reduced import (
    ClampedReduction,
    ReducedBody,
    ReducedBodyFileError,
    load_clamped_reduction,
    load_reduced_body,
    save_clamped_reduction,
    save_reduced_body,
)

try:  # POSIX; elsewhere processes do not share work, each computes its own entries
    import fcntl
except ImportError:  # pragma: no cover - not on the platforms tested
    fcntl = None  # type: ignore[assignment]

__all__ = ["BodyCache", "default_cache_dir", "lock_timeout", "STALE_SECONDS", "SUMMARY_SCHEMA", "EntryReport"]

log = logging.getLogger(__name__)

SUMMARY_SCHEMA = "mountwb-fe-summary"
#: A temporary file of the store older than this (s) belongs to a killed process.
STALE_SECONDS = 600.0
#: Default wait for another process's lock, s (``MOUNTWB_CACHE_LOCK_TIMEOUT`` overrides).
DEFAULT_LOCK_TIMEOUT = 900.0
#: Reduced bodies kept in memory per process (a parameter study reuses them across rows).
MEMORY_ENTRIES = 16
_POLL_SECONDS = 0.1

#: Problems already reported in this process (a folder's trouble, a corrupt file): each once.
_reported: set = set()
#: Folders found unusable (not even readable) or unwritable in this process, with the reason.
_unusable: dict = {}
_unwritable: dict = {}
#: Folders whose stale temporary files were looked for in this process.
_swept: set = set()
#: Entry file -> (ReducedBody or ClampedReduction, signature of the file when remembered), most recent last.
_memory: OrderedDict = OrderedDict()


def default_cache_dir() -> Path:
    """Cache folder: ``$MOUNTWB_CACHE``, else ``~/.cache/mountwb``."""
    return Path(os.environ.get("MOUNTWB_CACHE") or Path.home() / ".cache" / "mountwb")


def lock_timeout() -> float:
    """How long a process waits for another one's lock, s (``$MOUNTWB_CACHE_LOCK_TIMEOUT``, default 900)."""
    text = os.environ.get("MOUNTWB_CACHE_LOCK_TIMEOUT")
    try:
        return float(text) if text else DEFAULT_LOCK_TIMEOUT
    except ValueError:
        _warn_once(("timeout", text), "MOUNTWB_CACHE_LOCK_TIMEOUT=%r is not a number of seconds; using %g s",
                   text, DEFAULT_LOCK_TIMEOUT)
        return DEFAULT_LOCK_TIMEOUT


def _warn_once(key, message, *args) -> None:
    if key not in _reported:
        _reported.add(key)
        log.warning(message, *args)


def _reason(error: OSError) -> str:
    return error.strerror or str(error)


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


@dataclass(frozen=True)
class EntryReport:
    """One entry of the store as :meth:`BodyCache.verify` found it.

    Attributes
    ----------
    path : Path
    size : int
        Bytes.
    problem : str or None
        Why the entry cannot be used, or None for a sound entry.
    """

    path: Path
    size: int
    problem: str | None


class BodyCache:
    """The store in one folder, or no store at all.

    Parameters
    ----------
    folder : str or Path, optional
        Default :func:`default_cache_dir`.
    enabled : bool
        False gives a store that holds nothing (every read misses, writes are dropped).
    """

    def __init__(self, folder=None, enabled: bool = True):
        self.folder = Path(folder) if folder is not None else default_cache_dir()
        self.enabled = enabled

    # -- the folder -------------------------------------------------------------------------

    def usable(self) -> bool:
        """True when the folder exists (it is created) and can be read."""
        if not self.enabled:
            return False
        if self.folder in _unusable:
            return False
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            if not self.folder.is_dir():
                raise NotADirectoryError(20, "not a folder")
        except OSError as error:
            _unusable[self.folder] = _reason(error)
            self._warn(error, "cannot be used")
            return False
        self._sweep()
        return True

    def writable(self) -> bool:
        """True when the folder can be used and no write to it has failed in this process."""
        return self.usable() and self.folder not in _unwritable

    def _give_up(self, error: OSError) -> None:
        """Stop writing to the folder in this process, with one warning."""
        _unwritable[self.folder] = _reason(error)
        self._warn(error, "cannot be written")

    def _warn(self, error: OSError, what: str) -> None:
        _warn_once(("folder", self.folder), "reduced-body cache %s %s (%s); going on without caching",
                   self.folder, what, _reason(error))

    def _sweep(self) -> None:
        """Remove temporary files of the store that a killed process left (once per folder and process)."""
        if self.folder in _swept:
            return
        _swept.add(self.folder)
        for path in self.stale_temporaries():
            try:
                path.unlink()
                log.info("removed %s, left by an interrupted process", path)
            except OSError:
                pass

    def stale_temporaries(self, age: float = STALE_SECONDS) -> list:
        """Temporary files of the store older than ``age`` s."""
        now = time.time()
        found = []
        for pattern in (".fe-*.tmp", ".link-*.tmp", ".clamped-*.tmp", ".stiffening-*.tmp"):
            for path in self.folder.glob(pattern):
                try:
                    if now - path.stat().st_mtime > age:
                        found.append(path)
                except OSError:
                    pass
        return sorted(found)

    def write(self, path: Path, write) -> bool:
        """Write the entry *path* of the folder atomically by ``write(temporary_path)``; False (with the
        store's one warning) when the folder cannot be written."""
        if not self.writable():
            return False
        try:
            with replacing(path) as temporary:
                write(temporary)
        except OSError as error:
            self._give_up(error)
            return False
        return True

    # -- frequency summaries ----------------------------------------------------------------

    def summary_path(self, key: str) -> Path:
        return self.folder / f"fe-{key}.json"

    def read_summary(self, key: str) -> dict | None:
        """The reference frequencies stored under ``key``, Hz, or None (missing or corrupt)."""
        if not self.usable():
            return None
        path = self.summary_path(key)
        try:
            return read_summary_file(path, key)
        except FileNotFoundError:
            return None
        except (OSError, ReducedBodyFileError) as error:
            self.report_corrupt(path, error)
            return None

    def write_summary(self, key: str, frequencies: dict) -> None:
        """Store reference frequencies (Hz) under ``key``."""
        if not self.writable():
            return
        values = {name: np.asarray(v, dtype=float).tolist() for name, v in frequencies.items()}
        record = {"schema": SUMMARY_SCHEMA, "key": key, "frequencies": values,
                  "checksum": _digest(json.dumps(values, sort_keys=True))}
        self.write(self.summary_path(key), lambda temporary: temporary.write_text(json.dumps(record)))

    # -- reduced bodies ---------------------------------------------------------------------

    def body_path(self, key: str) -> Path:
        return self.folder / f"link-{key}.npz"

    def load_body(self, key: str) -> ReducedBody | None:
        """The reduced body stored under ``key``, or None (missing or corrupt)."""
        return self._load(self.body_path(key), key, load_reduced_body)

    def save_body(self, key: str, body: ReducedBody) -> None:
        """Store a reduced body under ``key`` (also in this process's memory)."""
        self._save(self.body_path(key), body, save_reduced_body)

    def clamped_path(self, key: str) -> Path:
        return self.folder / f"clamped-{key}.npz"

    def load_clamped(self, key: str) -> ClampedReduction | None:
        """The clamped reduction stored under ``key``, or None (missing or corrupt)."""
        return self._load(self.clamped_path(key), key, load_clamped_reduction)

    def save_clamped(self, key: str, reduction: ClampedReduction) -> None:
        """Store a clamped reduction under ``key`` (also in this process's memory)."""
        self._save(self.clamped_path(key), reduction, save_clamped_reduction)

    def _load(self, path: Path, key: str, read):
        """The entry *read* from *path* (in memory while its file is unchanged), or None (missing or corrupt)."""
        if not self.enabled:
            return None
        remembered = _memory.get(path)
        if remembered is not None and remembered[1] == file_signature(path):
            _memory.move_to_end(path)
            return remembered[0]
        if not self.usable() or not path.exists():
            return None
        try:
            entry = read(path, key=key)
        except ReducedBodyFileError as error:
            self.report_corrupt(path, error)
            return None
        self._remember(path, entry)
        return entry

    def _save(self, path: Path, entry, write) -> None:
        if not self.enabled:
            return
        if self.writable():
            self.write(path, lambda temporary: write(entry, temporary))
        self._remember(path, entry)

    def _remember(self, path: Path, entry) -> None:
        """Keep an entry in memory while its file stays as it is now (or absent, without a store)."""
        _memory[path] = (entry, file_signature(path))
        _memory.move_to_end(path)
        while len(_memory) > MEMORY_ENTRIES:
            _memory.popitem(last=False)

    load_link = renamed("load_link", "load_body()", load_body)
    save_link = renamed("save_link", "save_body()", save_body)
    link_path = renamed("link_path", "body_path()", body_path)

    def report_corrupt(self, path: Path, error: Exception) -> None:
        """Warn once that an entry cannot be used; it will be recomputed and replaced."""
        _warn_once(("corrupt", path, path.stat().st_mtime_ns if path.exists() else 0),
                   "corrupt cache entry %s (%s); recomputing and replacing it", path, error)

    # -- one process computes ---------------------------------------------------------------

    @contextmanager
    def lock(self, key: str):
        """Hold the lock of ``key`` while computing its entries.

        Waits for another process that holds it, at most :func:`lock_timeout`
        s; after that, warns and goes on without the lock (the entries are then
        computed twice, never wrongly: every write is atomic).
        """
        if fcntl is None or not self.writable():
            yield
            return
        path = self.folder / f".{key}.lock"
        try:
            handle = open(path, "a+")
        except OSError as error:
            self._give_up(error)
            yield
            return
        with handle:
            locked = self._acquire(handle, path)
            try:
                yield
            finally:
                if locked:
                    fcntl.flock(handle, fcntl.LOCK_UN)

    def _acquire(self, handle, path: Path) -> bool:
        timeout = lock_timeout()
        start = time.monotonic()
        waiting = False
        while True:
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
                return True
            except BlockingIOError:
                pass
            except OSError as error:  # a file system without locks
                _warn_once(("lock", self.folder), "cannot lock %s (%s); going on without sharing work", path, _reason(error))
                return False
            if not waiting:
                waiting = True
                log.info("waiting for another process computing the same body (%s)", path)
            if time.monotonic() - start > timeout:
                log.warning("waited %g s for %s, held by another process computing the same body; computing it here "
                            "as well (MOUNTWB_CACHE_LOCK_TIMEOUT sets the wait)", timeout, path)
                return False
            time.sleep(_POLL_SECONDS)

    # -- the command line's view ------------------------------------------------------------

    def entries(self) -> list:
        """Every entry file in the folder, summaries first, the links' geometric stiffness last."""
        if not self.folder.is_dir():
            return []
        return (sorted(self.folder.glob("fe-*.json")) + sorted(self.folder.glob("link-*.npz"))
                + sorted(self.folder.glob("clamped-*.npz")) + self.stiffening_files())

    def stiffening_files(self) -> list:
        """The files of the links' geometric stiffness and its projections in the folder."""
        return sorted(self.folder.glob("stiffening-*.npz")) + sorted(self.folder.glob("stiffening-*.npy"))

    def verify(self) -> list:
        """Check every entry's key and checksum (a geometric stiffness file: that it reads); a list of
        :class:`EntryReport`."""
        reports = []
        for path in self.entries():
            key = path.stem.split("-", 1)[1]
            try:
                if path.name.startswith("stiffening-"):
                    _read_arrays(path)
                elif path.suffix == ".json":
                    read_summary_file(path, key)
                elif path.name.startswith("clamped-"):
                    load_clamped_reduction(path, key=key)
                else:
                    load_reduced_body(path, key=key)
                problem = None
            except (OSError, ReducedBodyFileError) as error:
                problem = str(error)
            reports.append(EntryReport(path, path.stat().st_size, problem))
        return reports

    def clear(self) -> int:
        """Remove every entry, lock file and temporary file of the store; the number of files removed."""
        if not self.folder.is_dir():
            return 0
        files = self.entries() + sorted(self.folder.glob(".*.lock")) + self.stale_temporaries(age=0.0)
        for path in files:
            path.unlink(missing_ok=True)
        for path in [p for p in _memory if p.parent == self.folder]:
            del _memory[path]
        return len(files)


def _read_arrays(path: Path) -> None:
    """Read every array of the NumPy file *path* (``.npz`` or ``.npy``).

    Raises
    ------
    ReducedBodyFileError
        It cannot be read.
    """
    try:
        if path.suffix == ".npz":
            with np.load(path, allow_pickle=False) as data:
                for name in data.files:
                    data[name]
        else:
            np.load(path, allow_pickle=False)
    except (ValueError, EOFError, zipfile.BadZipFile) as error:
        raise ReducedBodyFileError(f"{path}: cannot be read ({error})") from None


def file_signature(path: Path):
    """What tells whether a file changed: inode, size and modification time, or None when absent."""
    try:
        stat = path.stat()
    except OSError:
        return None
    return stat.st_ino, stat.st_size, stat.st_mtime_ns


def read_summary_file(path: Path, key: str | None = None) -> dict:
    """Read and verify a frequency summary.

    Parameters
    ----------
    path : Path
    key : str, optional
        The key the entry must carry.

    Returns
    -------
    dict of str to ndarray
        ``free_free_hz`` and ``mounted_hz``, Hz.

    Raises
    ------
    FileNotFoundError
    ReducedBodyFileError
        Not a summary, another key's, or altered.
    """
    try:
        record = json.loads(path.read_text())
        values = record["frequencies"]
        stored_key, checksum = record["key"], record["checksum"]
        if record["schema"] != SUMMARY_SCHEMA:
            raise ValueError(f"schema {record['schema']!r}")
        frequencies = {name: np.asarray(values[name], dtype=float) for name in ("free_free_hz", "mounted_hz")}
    except FileNotFoundError:
        raise
    except (ValueError, KeyError, TypeError) as error:
        raise ReducedBodyFileError(f"{path}: not a frequency summary ({error})") from None
    if key is not None and stored_key != key:
        raise ReducedBodyFileError(f"{path}: holds the entry of key {stored_key}, not of {key}")
    if _digest(json.dumps(values, sort_keys=True)) != checksum:
        raise ReducedBodyFileError(f"{path}: checksum mismatch, the file was altered or damaged")
    return frequencies


__getattr__ = renamed_names(__name__, {"LinkCache": "BodyCache"})
