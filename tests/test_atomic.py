"""Files are replaced whole and keep their permissions."""
import os
import stat

import pytest

from flexbodies.atomic import replacing


def test_a_replaced_file_keeps_its_permissions(tmp_path):
    path = tmp_path / "case.xlsx"
    path.write_text("old")
    os.chmod(path, 0o640)
    with replacing(path) as temporary:
        temporary.write_text("new")
    assert path.read_text() == "new"
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    assert list(tmp_path.iterdir()) == [path]


def test_a_new_file_gets_the_usual_permissions(tmp_path):
    umask = os.umask(0o022)
    try:
        with replacing(tmp_path / "new.npz") as temporary:
            temporary.write_bytes(b"data")
    finally:
        os.umask(umask)
    assert stat.S_IMODE((tmp_path / "new.npz").stat().st_mode) == 0o644


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "case.xlsx"
    path.write_text("old")
    with pytest.raises(RuntimeError):
        with replacing(path) as temporary:
            temporary.write_text("half")
            raise RuntimeError("disk full")
    assert path.read_text() == "old"
    assert list(tmp_path.iterdir()) == [path]
