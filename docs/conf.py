"""Sphinx configuration of the Engine Mount Workbook documentation.

Build (warnings are errors)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The API reference follows the packages' public names: ``api/index.rst`` is
written here, at each build, from ``flexbodies.__all__`` and
``workbook.__all__`` (a package without ``__all__`` is left out), and
autosummary writes one page per name.
"""
import importlib
import importlib.metadata
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

DOCS = Path(__file__).resolve().parent

project = "Engine Mount Workbook"
author = "Engine Mount Workbook contributors"
copyright = "Engine Mount Workbook contributors"
release = importlib.metadata.version("engine-mount-workbook")

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build"]
html_theme = "alabaster"

autosummary_generate = True
autodoc_default_options = {"members": True}
# The numpydoc sections give the types; the signatures stay short.
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False

sphinx_gallery_conf = {
    "examples_dirs": str(DOCS.parent / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
}


def _public_names(package: str) -> list[str]:
    """The names of *package*'s ``__all__``, or none when it has no ``__all__``."""
    return list(getattr(importlib.import_module(package), "__all__", ()))


def _write_api_index() -> None:
    """Write ``api/index.rst``: one autosummary table per package, its public names sorted."""
    lines = ["API reference", "=============", "",
             "The public names of each package, from its ``__all__``.", ""]
    for package in ("workbook", "flexbodies"):
        names = _public_names(package)
        if not names:
            continue
        title = f"``{package}``"
        lines += [title, "-" * len(title), "", f".. automodule:: {package}", "   :no-members:", "",
                  f".. currentmodule:: {package}", "", ".. autosummary::", "   :toctree: generated", ""]
        lines += [f"   {name}" for name in sorted(names, key=str.lower)]
        lines.append("")
    target = DOCS / "api" / "index.rst"
    target.parent.mkdir(exist_ok=True)
    text = "\n".join(lines)
    if not target.exists() or target.read_text() != text:
        target.write_text(text)


_write_api_index()
