"""Every Python block of the user guide (docs/*.md) and of README.md runs.

The blocks of one page run in order in one namespace, as a reader would
paste them; a failure names the page and the block's number on it.
"""
import re
import traceback
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
PAGES = sorted(ROOT.glob("docs/*.md")) + [ROOT / "README.md"]

#: A fenced block opened by ```python at the start of a line, up to its closing fence.
BLOCK = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.DOTALL | re.MULTILINE)

#: Pages whose blocks take more than about 5 s with an empty reduction cache.
SLOW_PAGES = {"flexible-links.md", "four-pole.md", "index.md", "reference-mount.md", "rig-sensors.md", "README.md"}


def python_blocks(page: Path) -> list[str]:
    """The source of each ```python block of *page*, in the page's order."""
    return BLOCK.findall(page.read_text(encoding="utf-8"))


def _page_param(page: Path):
    name = str(page.relative_to(ROOT))
    return pytest.param(page, id=name, marks=[pytest.mark.slow] if page.name in SLOW_PAGES else [])


PAGES_WITH_CODE = [page for page in PAGES if python_blocks(page)]


def test_blocks_are_found():
    """The pages hold Python blocks and the extraction finds their code."""
    assert PAGES_WITH_CODE
    for page in PAGES_WITH_CODE:
        assert all(block.strip() for block in python_blocks(page)), page.name


@pytest.mark.parametrize("page", [_page_param(page) for page in PAGES_WITH_CODE])
def test_python_blocks_run(page):
    name = str(page.relative_to(ROOT))
    namespace = {"__name__": f"docs_example_{page.stem.replace('-', '_')}"}
    try:
        for number, code in enumerate(python_blocks(page), start=1):
            try:
                exec(compile(code, f"{name}, python block {number}", "exec"), namespace)
            except Exception:
                pytest.fail(f"{name}, python block {number} failed:\n{traceback.format_exc()}", pytrace=False)
    finally:
        plt.close("all")
