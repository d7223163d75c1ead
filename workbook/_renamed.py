"""Old method names of the result objects, kept for one release with a warning.

The result objects speak one vocabulary: ``to_pandas()`` for the table,
``to_text()`` for the printed table and ``plot()`` for the figure (see
``docs/developer.md``). Their former names (``table()``, ``frame()``,
``to_frame()`` ...) call the new ones and issue a ``DeprecationWarning``.
"""
from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

#: The release that removes the old names.
REMOVED_IN = "0.3"


def renamed(old: str, new: str, call: Callable[..., Any]) -> Callable[..., Any]:
    """A method *old* that warns and returns ``call(self, *args, **kwargs)``.

    Parameters
    ----------
    old : str
        The former name, as the warning shows it (e.g. ``"table"``).
    new : str
        What to write instead (e.g. ``"to_pandas()"``).
    call : callable
        ``call(self, *args, **kwargs)`` gives the answer under the new name.
    """

    def method(self, *args, **kwargs):
        warnings.warn(f"{type(self).__name__}.{old}() is now {new}; {old}() goes in version {REMOVED_IN}",
                      DeprecationWarning, stacklevel=2)
        return call(self, *args, **kwargs)

    method.__name__ = old
    method.__doc__ = f"Former name of {new} (deprecated, goes in version {REMOVED_IN})."
    return method
