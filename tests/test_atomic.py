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


def test_a_figure_that_fails_to_render_leaves_the_old_picture(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from workbook.answers.saving import save_figure

    path = tmp_path / "mount-layout.png"
    good = plt.figure()
    save_figure(good, path)
    before = path.read_bytes()
    assert before.startswith(b"\x89PNG")
    broken = plt.figure()
    broken.text(0.5, 0.5, r"$\frac{1}$")  # mathtext that cannot be laid out
    with pytest.raises(ValueError):
        save_figure(broken, path)
    plt.close("all")
    assert path.read_bytes() == before
    assert list(tmp_path.iterdir()) == [path]


def test_a_saved_table_reads_back_whole(tmp_path):
    import pandas as pd

    from workbook.answers.saving import save_csv, save_text

    frame = pd.DataFrame({"T": [0.0363, 0.0019]}, index=["x", "y"])
    path = save_csv(frame, tmp_path / "table.csv")
    pd.testing.assert_frame_equal(pd.read_csv(path, index_col=0), frame)
    assert save_text("é\n", tmp_path / "note.md").read_text(encoding="utf-8") == "é\n"
