"""Names of a package imported on first use (PEP 562): ``import workbook`` or ``import flexbodies`` stays
fast, and a name's heavy dependencies load only when it is used."""
from __future__ import annotations

import importlib
import sys
from typing import Callable


def lazy_names(package: str, homes: dict[str, tuple[str, ...]]) -> tuple[Callable, Callable, list[str]]:
    """The module ``__getattr__`` and ``__dir__`` of *package* and its lazily loaded names.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    homes : dict of str to tuple of str
        Module (relative to *package*) -> the names it holds.
    """
    module_of = {name: module for module, names in homes.items() for name in names}

    def __getattr__(name: str):
        if name not in module_of:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f".{module_of[name]}", package), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__():
        namespace = sys.modules[package]
        return sorted(set(vars(namespace)) | set(getattr(namespace, "__all__", ())) | set(module_of))

    return __getattr__, __dir__, list(module_of)
