"""Replace the generated sections of a markdown document.

A generated section sits between ``<!-- generated: NAME -->`` and
``<!-- end: NAME -->``; the ``make_*_docs.py`` scripts rewrite only those.
"""
from __future__ import annotations

import re


def replace_section(text: str, name: str, content: str, document: str) -> str:
    """*text* with the section *name* replaced by *content*.

    Raises
    ------
    ValueError
        If the section's markers are missing (named with *document*).
    """
    pattern = re.compile(rf"(<!-- generated: {name} -->\n).*?(<!-- end: {name} -->)", re.S)
    if not pattern.search(text):
        raise ValueError(f"marker 'generated: {name}' missing in {document}")
    return pattern.sub(lambda m: m.group(1) + content + "\n" + m.group(2), text)
