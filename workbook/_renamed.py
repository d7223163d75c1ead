"""Old names kept for one release with a warning: methods of the result objects, names of modules.

The result objects speak one vocabulary: ``to_pandas()`` for the table,
``to_text()`` for the printed table and ``plot()`` for the figure (see
``docs/developer.md``). Their former names (``table()``, ``frame()``,
``to_frame()`` ...) call the new ones and issue a ``DeprecationWarning``;
so do the former names of :mod:`flexbodies`' general machinery (``ReducedLink``
is ``ReducedBody``, ``LinkCache`` is ``BodyCache``, ``LinkMesh`` is ``BodyMesh``).
"""
from __future__ import annotations

import sys
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


def renamed_names(module: str, names: dict[str, str], fallback: Callable[[str], Any] | None = None) -> Callable[[str], Any]:
    """A module ``__getattr__`` (PEP 562) under which each former name of *names* warns and gives the new one.

    Parameters
    ----------
    module : str
        The module's ``__name__``.
    names : dict of str to str
        Former name -> its name now, both in *module*.
    fallback : callable, optional
        The module's ``__getattr__`` for every other name (a lazily loading
        package's); without it, another name is an ``AttributeError``.
    """

    def __getattr__(name: str) -> Any:
        if name in names:
            warnings.warn(f"{module}.{name} is now {module}.{names[name]}; {name} goes in version {REMOVED_IN}",
                          DeprecationWarning, stacklevel=2)
            return getattr(sys.modules[module], names[name])
        if fallback is not None:
            return fallback(name)
        raise AttributeError(f"module {module!r} has no attribute {name!r}")

    return __getattr__
