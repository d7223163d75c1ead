"""The generated sections of the docs are what their scripts generate now.

Each ``docs/make_*_docs.py`` script regenerates its document's sections
(between ``<!-- generated: NAME -->`` and ``<!-- end: NAME -->``) from the
code; a committed section that differs fails here, naming the document and
the section. Fix: run the script and commit what it writes.
"""
import difflib
import importlib
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parent.parent / "docs"
sys.path.insert(0, str(DOCS))

from generated_sections import section  # noqa: E402


def _differences(document: str, script: str, generated: dict) -> list[str]:
    text = (DOCS / document).read_text()
    failures = []
    for name, content in generated.items():
        committed = section(text, name, document)
        if committed != content:
            diff = "\n".join(difflib.unified_diff(committed.splitlines(), content.splitlines(), "committed",
                                                  "generated", lineterm="", n=0))
            failures.append(f"docs/{document}, section '{name}' differs from what docs/{script} generates "
                            f"(run it and commit the result):\n{diff}")
    return failures


@pytest.mark.slow
def test_reference_mount_doc_is_current(cache_dir):
    script = importlib.import_module("make_reference_docs")
    failures = _differences(script.DOCUMENT, "make_reference_docs.py", script.sections())
    assert not failures, "\n\n".join(failures)


@pytest.mark.slow
def test_four_pole_doc_is_current(cache_dir):
    script = importlib.import_module("make_four_pole_docs")
    failures = _differences(script.DOCUMENT, "make_four_pole_docs.py", script.sections())
    assert not failures, "\n\n".join(failures)


@pytest.mark.slow
def test_stress_doc_and_readme_are_current(cache_dir):
    script = importlib.import_module("make_stress_docs")
    generated = script.sections()
    readme = {name: generated.pop(name) for name in script.README_SECTIONS}
    failures = (_differences(script.DOCUMENT, "make_stress_docs.py", generated)
                + _differences("../README.md", "make_stress_docs.py", readme))
    assert not failures, "\n\n".join(failures)


def _untimed_failures(name: str) -> list[str]:
    """Differences of every section of docs script *name* but its measured wall times (``TIMED``)."""
    script = importlib.import_module(name)
    generated = {section_name: content for section_name, content in script.sections().items()
                 if section_name != script.TIMED}
    return _differences(script.DOCUMENT, f"{name}.py", generated)


@pytest.mark.slow
def test_stress_stiffening_doc_is_current(cache_dir):
    failures = _untimed_failures("make_stiffening_docs")
    assert not failures, "\n\n".join(failures)


@pytest.mark.slow
def test_flexible_engine_doc_is_current(cache_dir):
    failures = _untimed_failures("make_flexible_engine_docs")
    assert not failures, "\n\n".join(failures)


@pytest.mark.slow
def test_rig_sensor_doc_is_current(cache_dir):
    script = importlib.import_module("make_rig_sensor_docs")
    failures = _differences(script.DOCUMENT, "make_rig_sensor_docs.py", script.sections(*script.study()))
    assert not failures, "\n\n".join(failures)


def test_a_changed_section_is_named():
    """The comparison names the document and the section that differ."""
    text = (DOCS / "reference-mount.md").read_text()
    generated = {"balance": section(text, "balance", "reference-mount.md") + " (changed)"}
    failures = _differences("reference-mount.md", "make_reference_docs.py", generated)
    assert len(failures) == 1 and "docs/reference-mount.md, section 'balance'" in failures[0]


@pytest.mark.slow
def test_updating_doc_is_current(cache_dir):
    script = importlib.import_module("make_updating_docs")
    failures = _differences(script.DOCUMENT, "make_updating_docs.py", script.sections(*script.study()))
    assert not failures, "\n\n".join(failures)
