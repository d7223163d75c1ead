"""The reduced-link store in trouble: folders that cannot be used, two processes, killed writers, the command."""
import fcntl
import json
import logging
import os
import signal
import subprocess
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from flexbodies import LinkGeometry, LinkModel, load_reduced_body, reduce_link, reduce_link_set
from flexbodies.cache import STALE_SECONDS
from flexbodies.geometric_stiffness import link_stiffening
from workbook.cli.main import main

ROOT = Path(__file__).resolve().parents[1]
#: A tiny, coarse link: these tests are about files and processes, not accuracy.
TINY = LinkGeometry(length=0.12, eye_outer_radius=0.020, bore_radius=0.010, thickness=0.015, shank_width=0.020,
                    shank_thickness=0.015)
MODEL = LinkModel(geometry=TINY, element_size=0.012)

#: One run in a process of its own: reduce the tiny link, print whether it was loaded.
RUN = f"""
import json, logging
logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
from flexbodies import LinkGeometry, LinkModel, reduce_link
link = reduce_link(LinkModel(geometry=LinkGeometry(**{TINY.__dict__!r}), element_size=0.012), "static")
print(json.dumps({{"hit": link.cache_hit, "mass": link.mass}}))
"""


def _start(cache, **env) -> subprocess.Popen:
    environment = dict(os.environ, MOUNTWB_CACHE=str(cache), PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1", **env)
    return subprocess.Popen([sys.executable, "-c", RUN], env=environment, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _finish(process) -> tuple:
    out, err = process.communicate(timeout=300)
    assert process.returncode == 0, err
    return json.loads(out.strip().splitlines()[-1]), [line for line in err.splitlines() if line.startswith("WARNING")]


def test_a_cache_path_naming_a_file_warns_once_and_the_run_goes_on(tmp_path):
    not_a_folder = tmp_path / "cache.txt"
    not_a_folder.write_text("a file, not a folder")
    result, warnings = _finish(_start(not_a_folder))
    assert not result["hit"] and result["mass"] > 0
    assert len(warnings) == 1, warnings
    assert str(not_a_folder) in warnings[0] and "without caching" in warnings[0]
    assert not_a_folder.read_text() == "a file, not a folder"


def test_a_cache_path_naming_a_file_leaves_out_the_geometric_stiffness_as_well(tmp_path, caplog):
    not_a_folder = tmp_path / "cache.txt"
    not_a_folder.write_text("a file, not a folder")
    with caplog.at_level(logging.WARNING, logger="flexbodies"):
        link, = reduce_link_set(MODEL, "static", cache_dir=not_a_folder, stiffening=True)
        stiffening = link_stiffening(MODEL, cache_dir=not_a_folder)
    assert stiffening.cache_file is None and stiffening.nodes == int(link.master_nodes[0])
    warnings = [record.getMessage() for record in caplog.records if record.levelno == logging.WARNING]
    assert len(warnings) == 1 and str(not_a_folder) in warnings[0] and "without caching" in warnings[0], warnings
    assert not_a_folder.read_text() == "a file, not a folder"


@contextmanager
def _mounted(folder: Path, options: str):
    """A small tmpfs at ``folder``, or the test skipped with the reason."""
    folder.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)], capture_output=True, text=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a small file system here ({done.stderr.strip() or 'mount failed'})")
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)


@pytest.mark.slow
@pytest.mark.parametrize("options, reason", [("size=64k", "No space left on device"), ("ro,size=64k", "Read-only file system")],
                         ids=["full", "read-only"])
def test_a_full_or_read_only_file_system_warns_once_and_the_run_goes_on(tmp_path, caplog, options, reason):
    clean = reduce_link(MODEL, "static", use_cache=False)
    with _mounted(tmp_path / "cache", options) as folder:
        if "ro" not in options.split(","):
            with pytest.raises(OSError):  # fill it to the last block
                with open(folder / "filler", "wb") as handle:
                    while True:
                        handle.write(bytes(4096))
                        handle.flush()
        with caplog.at_level(logging.WARNING, logger="flexbodies"):
            link = reduce_link(MODEL, "static", cache_dir=folder)
            again = reduce_link(MODEL, "static", cache_dir=folder)
        left = sorted(p.name for p in folder.iterdir())
    warnings = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(warnings) == 1 and str(folder) in warnings[0] and reason in warnings[0], warnings
    assert link.mass == pytest.approx(clean.mass, rel=1e-12) and not link.cache_hit
    assert again.mass == link.mass
    assert not [name for name in left if name.endswith(".tmp")], left


@pytest.mark.slow
def test_two_processes_on_one_empty_cache_compute_the_link_once(tmp_path):
    first, second = _start(tmp_path), _start(tmp_path)
    results = [_finish(first)[0], _finish(second)[0]]
    assert sorted(r["hit"] for r in results) == [False, True], results
    assert results[0]["mass"] == results[1]["mass"]
    assert len(list(tmp_path.glob("link-*.npz"))) == 1


@pytest.mark.slow
def test_a_lock_held_too_long_is_given_up_with_a_warning(tmp_path, caplog, monkeypatch):
    monkeypatch.setenv("MOUNTWB_CACHE_LOCK_TIMEOUT", "0.5")
    lock = tmp_path / f".{MODEL.key()}.lock"
    with open(lock, "a+") as handle:  # another process computing the same link, for ever
        fcntl.flock(handle, fcntl.LOCK_EX)
        start = time.monotonic()
        with caplog.at_level(logging.WARNING, logger="flexbodies.cache"):
            link = reduce_link(MODEL, "static", cache_dir=tmp_path)
        waited = time.monotonic() - start
    (warning,) = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert str(lock) in warning and "waited 0.5 s" in warning
    assert waited > 0.5 and not link.cache_hit
    assert reduce_link(MODEL, "static", cache_dir=tmp_path).cache_hit, "the entry was written all the same"


KILLED_WRITER = """
import os, signal, sys
from flexbodies.atomic import replacing
with replacing(sys.argv[1]) as temporary:
    temporary.write_bytes(bytes(1000))
    os.kill(os.getpid(), signal.SIGKILL)
"""


@pytest.mark.slow
def test_temporary_files_of_a_killed_process_are_removed_by_the_next_run(tmp_path, capsys):
    for name in ("old", "new"):
        killed = subprocess.run([sys.executable, "-c", KILLED_WRITER, str(tmp_path / f"link-{name}.npz")],
                                env=dict(os.environ, PYTHONPATH=str(ROOT)))
        assert killed.returncode == -signal.SIGKILL
    (old,) = tmp_path.glob(".link-old.npz-*.tmp")
    (new,) = tmp_path.glob(".link-new.npz-*.tmp")  # could belong to a process writing right now
    past = time.time() - 2 * STALE_SECONDS
    os.utime(old, (past, past))
    assert main(["cache", "info", "--folder", str(tmp_path)]) == 0
    assert old.name in capsys.readouterr().out
    _finish(_start(tmp_path))
    assert not old.exists() and new.exists()
    assert not (tmp_path / "link-old.npz").exists(), "a killed write never leaves a half entry"


@pytest.mark.slow
def test_cache_command_lists_verifies_and_clears(tmp_path, capsys):
    folder = str(tmp_path)
    link = reduce_link(MODEL, "static", cache_dir=tmp_path)
    (path,) = tmp_path.glob("link-*.npz")
    (tmp_path / "notes.txt").write_text("not the cache's")
    assert main(["cache", "info", "--folder", folder]) == 0
    assert "1 reduced body(ies), 0 clamped reduction(s), 1 frequency summary" in capsys.readouterr().out
    assert main(["cache", "verify", "--folder", folder]) == 0
    assert "2 entries checked, 0 corrupt" in capsys.readouterr().out
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    assert main(["cache", "verify", "--folder", folder]) == 1
    output = capsys.readouterr().out
    assert f"corrupt: {path}" in output and "1 corrupt" in output
    assert main(["cache", "clear", "--folder", folder]) == 0
    assert not list(tmp_path.glob("link-*")) and not list(tmp_path.glob("fe-*"))
    assert (tmp_path / "notes.txt").exists(), "clear removes the store's files only"
    again = reduce_link(MODEL, "static", cache_dir=tmp_path)
    assert not again.cache_hit and again.mass == link.mass
    assert load_reduced_body(path).input_hash == link.input_hash


@pytest.mark.parametrize("action", ["info", "verify", "clear"])
def test_cache_command_refuses_a_folder_that_is_a_file_and_names_a_missing_one(tmp_path, capsys, action):
    not_a_folder = tmp_path / "cache.txt"
    not_a_folder.write_text("a file, not a folder")
    assert main(["cache", action, "--folder", str(not_a_folder)]) == 2
    assert f"--folder {not_a_folder}: a file; expected the cache folder" in capsys.readouterr().err
    assert not_a_folder.read_text() == "a file, not a folder"
    assert main(["cache", action, "--folder", str(tmp_path / "nowhere")]) == 0
    assert f"{tmp_path / 'nowhere'}: no such folder, nothing stored" in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cache.txt"]


def test_cache_command_lists_checks_and_clears_the_geometric_stiffness_files(tmp_path, capsys):
    """The links' geometric stiffness files beside the reduced bodies are the store's too: listed, an
    unreadable one named by verify, every one (and a temporary file a killed writer left) removed by
    clear, and nothing else."""
    np.savez(tmp_path / "stiffening-aaaa.npz", data=np.ones(3), indptr=np.arange(3))
    np.save(tmp_path / "stiffening-aaaa-bbbb.npy", np.eye(2))
    (tmp_path / "stiffening-cccc-dddd.npy").write_bytes(b"not a NumPy file")
    (tmp_path / ".stiffening-aaaa.npz-x.tmp").write_bytes(bytes(10))
    (tmp_path / "notes.txt").write_text("not the cache's")
    folder = str(tmp_path)
    assert main(["cache", "info", "--folder", folder]) == 0
    assert ("0 reduced body(ies), 0 clamped reduction(s), 0 frequency summary(ies), 3 geometric stiffness file(s)"
            in capsys.readouterr().out)
    assert main(["cache", "verify", "--folder", folder]) == 1
    output = capsys.readouterr().out
    assert "corrupt:" in output and "stiffening-cccc-dddd.npy" in output and "3 entries checked, 1 corrupt" in output
    assert main(["cache", "clear", "--folder", folder]) == 0
    assert "removed 4 file(s)" in capsys.readouterr().out
    assert not list(tmp_path.glob("stiffening-*")) and not list(tmp_path.glob(".stiffening-*"))
    assert (tmp_path / "notes.txt").exists(), "clear removes the store's files only"
