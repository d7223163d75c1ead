"""Helpers of the interrupt tests: start ``mountwb`` in a process of its own,
signal it once it reaches a stage, and list what it left behind."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import psutil

ROOT = Path(__file__).resolve().parents[1]


def _interruptible() -> None:
    """In the child before it starts: Ctrl-C acts as on a terminal, even when the test runner was
    started in the background of a shell, which leaves SIGINT ignored for every child."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _interruptible_group() -> None:
    """As :func:`_interruptible`, and the child leads a process group of its own (as a job a shell,
    ``timeout`` or a scheduler starts), so that a signal can go to it and every worker at once."""
    _interruptible()
    os.setpgid(0, 0)


def start(*args: str, cwd=None, env: dict | None = None, group: bool = False) -> subprocess.Popen:
    """``mountwb -v ARGS`` with this tree on the path; stderr is read line by line.

    With *group*, the process leads a process group of its own: ``os.killpg(process.pid, signum)``
    signals it and its workers together.
    """
    environment = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1", **(env or {})}
    return subprocess.Popen([sys.executable, "-m", "workbook.cli.main", "-v", *args], cwd=cwd, env=environment,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_interruptible_group if group else _interruptible)


def signal_at(process: subprocess.Popen, marker: str, signum: int = signal.SIGINT, timeout: float = 300):
    """Send *signum* once a stderr line contains *marker*; return (exit code, stderr after the marker).

    Fails if the process ended before printing *marker*.
    """
    seen = []
    for line in process.stderr:
        seen.append(line)
        if marker in line:
            break
    else:
        raise AssertionError(f"{marker!r} never printed; stderr:\n{''.join(seen)}")
    process.send_signal(signum)
    _, rest = process.communicate(timeout=timeout)
    return process.returncode, rest


def descendants(pid: int) -> list[int]:
    """PIDs of every living descendant of *pid* (an empty list once it is gone)."""
    try:
        return [child.pid for child in psutil.Process(pid).children(recursive=True)]
    except psutil.NoSuchProcess:
        return []


def alive(pids) -> list[int]:
    """Those of *pids* still running (zombies count as gone)."""
    living = []
    for pid in pids:
        try:
            if psutil.Process(pid).status() != psutil.STATUS_ZOMBIE:
                living.append(pid)
        except psutil.NoSuchProcess:
            pass
    return living


def files_in(folder: Path) -> dict[str, bytes]:
    """Every file under *folder* (hidden and temporary ones too) with its content."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(Path(folder).rglob("*")) if p.is_file()}


SIGNAL_EXIT = {signal.SIGINT: 130, signal.SIGTERM: 143}
