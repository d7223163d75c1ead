"""Replace a file all at once, keeping its permissions."""
from __future__ import annotations

import os
import stat
import tempfile
from contextlib import contextmanager
from pathlib import Path

__all__ = ["replacing"]


def _default_mode() -> int:
    """Permissions a newly created file gets under the current umask."""
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


@contextmanager
def replacing(path, suffix: str = ".tmp"):
    """Write to a temporary file beside ``path``, then rename it over ``path``.

    ``path`` is never half-written: a reader sees the old file or the new one.
    The new file keeps the permissions of the file it replaces (a new file
    gets the usual ones); on any error the temporary file is removed and
    ``path`` is left as it was.

    Parameters
    ----------
    path : str or Path
        The file to write or replace.
    suffix : str
        Ending of the temporary file's name.

    Yields
    ------
    Path
        The temporary file to write to.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, name = tempfile.mkstemp(prefix=f".{path.name}-", suffix=suffix, dir=path.parent)
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        try:
            mode = stat.S_IMODE(path.stat().st_mode)
        except FileNotFoundError:
            mode = _default_mode()
        os.chmod(temporary, mode)
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
