"""Worker processes end with their parent: real processes, the parent killed outright (SIGKILL)."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time

import psutil
from cli_signals import ROOT, alive

from workbook.processes import PARENT_CHECK_INTERVAL

#: A process that starts a worker and waits; the worker sets up its watch only once this process is gone,
#: as a worker does whose start-up (imports, the prepared mount) outlasts a study killed meanwhile.
_PARENT = textwrap.dedent("""
    import multiprocessing, os, sys, time

    def worker(parent):
        while os.getppid() == parent:             # until the parent is killed
            time.sleep(0.02)
        from workbook.processes import end_with_parent
        end_with_parent()
        time.sleep(120)

    if __name__ == "__main__":
        process = multiprocessing.get_context("spawn").Process(target=worker, args=(os.getpid(),))
        process.start()
        print(process.pid, flush=True)
        time.sleep(120)
""")


def test_a_worker_watching_after_its_parent_was_killed_ends(tmp_path):
    """It watched its new parent (init) and outlived the study for ever, waiting for rows."""
    script = tmp_path / "parent.py"
    script.write_text(_PARENT)
    environment = {**os.environ, "PYTHONPATH": str(ROOT)}
    parent = subprocess.Popen([sys.executable, str(script)], env=environment, stdout=subprocess.PIPE, text=True)
    worker = int(parent.stdout.readline())
    parent.kill()
    parent.wait()                                 # (its output stays open in the worker)
    end = time.monotonic() + 10 * PARENT_CHECK_INTERVAL + 5
    try:
        while alive([worker]) and time.monotonic() < end:
            time.sleep(0.1)
        assert not alive([worker]), "the worker outlived its parent"
    finally:
        for pid in alive([worker]):
            psutil.Process(pid).kill()
        parent.stdout.close()
