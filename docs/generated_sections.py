"""Read and replace the generated sections of a markdown document.

A generated section sits between ``<!-- generated: NAME -->`` and
``<!-- end: NAME -->``; the ``make_*_docs.py`` scripts rewrite only those,
and ``tests/test_docs_current.py`` compares them with what the scripts
generate now.
"""
from __future__ import annotations

import re
from pathlib import Path


def _pattern(name: str) -> re.Pattern:
    return re.compile(rf"(<!-- generated: {re.escape(name)} -->\n)(.*?)\n?(<!-- end: {re.escape(name)} -->)", re.S)


def section(text: str, name: str, document: str) -> str:
    """The content of the section *name* of *text*.

    Raises
    ------
    ValueError
        If the section's markers are missing (named with *document*).
    """
    match = _pattern(name).search(text)
    if match is None:
        raise ValueError(f"marker 'generated: {name}' missing in {document}")
    return match.group(2)


def replace_section(text: str, name: str, content: str, document: str) -> str:
    """*text* with the section *name* replaced by *content*.

    Raises
    ------
    ValueError
        If the section's markers are missing (named with *document*).
    """
    section(text, name, document)
    return _pattern(name).sub(lambda m: m.group(1) + content + "\n" + m.group(3), text)


def rewrite_sections(path: Path, sections: dict[str, str]) -> Path:
    """Replace each generated section of the document at *path* by its content in *sections* (by name).

    Raises
    ------
    ValueError
        If a section's markers are missing; the document is then left as it was.
    """
    text = path.read_text()
    for name, content in sections.items():
        text = replace_section(text, name, content, path.name)
    path.write_text(text)
    return path
