"""The reduced-link file and its cache: reuse, invalidation, damage."""
import json
import logging
import zipfile

import numpy as np
import pytest

from flexbodies import STEEL, TITANIUM, LinkGeometry, LinkModel, ReducedLinkFileError, load_reduced_link, reduce_link, save_reduced_link

#: A small, coarse link: these tests are about files, not accuracy.
SMALL = LinkGeometry(length=0.20, eye_outer_radius=0.025, bore_radius=0.012, thickness=0.020, shank_width=0.030, shank_thickness=0.020)
COARSE = 0.012


def _model(**changes):
    fields = dict(geometry=SMALL, material=STEEL, element_size=COARSE)
    fields.update(changes)
    return LinkModel(**fields)


def _link_files(folder):
    return sorted(folder.glob("link-*.npz"))


def test_second_reduction_is_a_load(tmp_path):
    first = reduce_link(_model(), "static", cache_dir=tmp_path)
    (path,) = _link_files(tmp_path)
    stamp = path.stat().st_mtime_ns
    second = reduce_link(_model(), "static", cache_dir=tmp_path)
    assert not first.cache_hit and second.cache_hit
    assert path.stat().st_mtime_ns == stamp, "a load must not rewrite the file"
    np.testing.assert_array_equal(first.mode_basis, second.mode_basis)
    assert second.input_hash == first.input_hash


def test_auto_reuses_the_file_of_an_equal_decision(tmp_path):
    at_59 = reduce_link(_model(), "auto", 59.0, cache_dir=tmp_path)
    at_100 = reduce_link(_model(), "auto", 100.0, cache_dir=tmp_path)
    assert at_59.n_fixed_interface == 0 and at_100.cache_hit
    assert "100 Hz" in at_100.decision.reason, "the decision reported is the one asked for now"


@pytest.mark.parametrize(
    "change",
    [
        {"material": TITANIUM},
        pytest.param({"element_size": 0.010}, marks=pytest.mark.slow),
        pytest.param({"interface": "RBE3"}, marks=pytest.mark.slow),
        pytest.param({"geometry": LinkGeometry(length=0.21, eye_outer_radius=0.025, bore_radius=0.012, thickness=0.020, shank_width=0.030,
                                               shank_thickness=0.020)}, marks=pytest.mark.slow),
    ],
    ids=["material", "mesh size", "coupling", "geometry"],
)
def test_a_changed_input_recomputes(tmp_path, change):
    base = reduce_link(_model(), "static", cache_dir=tmp_path)
    changed = reduce_link(_model(**change), "static", cache_dir=tmp_path)
    assert not changed.cache_hit
    assert changed.input_hash != base.input_hash
    assert len(_link_files(tmp_path)) == 2


@pytest.mark.slow
def test_a_changed_mode_selection_recomputes(tmp_path):
    static = reduce_link(_model(), "static", cache_dir=tmp_path)
    six = reduce_link(_model(), 6, cache_dir=tmp_path)
    assert not six.cache_hit and six.n_modes == static.n_modes + 6


@pytest.mark.slow
def test_a_changed_mesh_file_recomputes(tmp_path):
    from flexbodies import BoreSpec, MeshSource, mesh_link

    mesh_path = tmp_path / "link.vtu"
    mesh_link(SMALL, COARSE).to_meshio().write(mesh_path)
    bores = (
        BoreSpec("A", centre=(0, 0, 0), axis=(0, 0, 1), radius=0.012),
        BoreSpec("B", centre=(0.2, 0, 0), axis=(0, 0, 1), radius=0.012),
    )
    model = LinkModel(mesh=MeshSource(str(mesh_path), bores))
    first = reduce_link(model, "static", cache_dir=tmp_path / "cache")
    assert reduce_link(model, "static", cache_dir=tmp_path / "cache").cache_hit
    mesh_link(SMALL, 0.010).to_meshio().write(mesh_path)
    changed = reduce_link(model, "static", cache_dir=tmp_path / "cache")
    assert not changed.cache_hit and len(changed.nodes) != len(first.nodes)


def _corrupt(path):
    data = bytearray(path.read_bytes())
    middle = len(data) // 2
    data[middle:middle + 64] = bytes(64)
    path.write_bytes(bytes(data))


@pytest.mark.slow
def test_a_corrupted_file_is_not_used(tmp_path, caplog):
    good = reduce_link(_model(), "static", cache_dir=tmp_path)
    (path,) = _link_files(tmp_path)
    _corrupt(path)
    with pytest.raises(ReducedLinkFileError, match=path.name):
        load_reduced_link(path)
    with caplog.at_level(logging.WARNING, logger="flexbodies.link"):
        again = reduce_link(_model(), "static", cache_dir=tmp_path)
    assert not again.cache_hit
    assert any("recomputing" in r.message for r in caplog.records)
    np.testing.assert_allclose(again.frequencies["reduced_hz"], good.frequencies["reduced_hz"], rtol=1e-10)
    assert load_reduced_link(path).input_hash == good.input_hash, "the damaged file was replaced"


def test_an_altered_array_fails_the_checksum(tmp_path):
    link = reduce_link(_model(), "static", cache_dir=tmp_path, use_cache=False)
    path = save_reduced_link(link, tmp_path / "link.npz")
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["mode_basis"] = arrays["mode_basis"] * 1.001  # a valid archive with wrong numbers
    np.savez_compressed(path, **arrays)
    with pytest.raises(ReducedLinkFileError, match="checksum"):
        load_reduced_link(path)


def test_a_file_of_another_version_is_rejected(tmp_path):
    link = reduce_link(_model(), "static", cache_dir=tmp_path, use_cache=False)
    path = save_reduced_link(link, tmp_path / "link.npz")
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    meta = json.loads(str(arrays["meta"]))
    meta["schema_version"] = 99
    arrays["meta"] = np.array(json.dumps(meta))
    np.savez_compressed(path, **arrays)
    with pytest.raises(ReducedLinkFileError, match="version 99"):
        load_reduced_link(path)


def test_a_file_that_is_not_an_archive_is_rejected(tmp_path):
    path = tmp_path / "link.npz"
    path.write_text("not a reduced link")
    with pytest.raises(ReducedLinkFileError, match="not a readable"):
        load_reduced_link(path)
    assert not zipfile.is_zipfile(path)


def test_the_file_holds_what_the_issue_lists(tmp_path):
    link = reduce_link(_model(), "auto", 59.0, cache_dir=tmp_path)
    (path,) = _link_files(tmp_path)
    with np.load(path) as data:
        meta = json.loads(str(data["meta"]))
        names = set(data.files)
    assert {"nodes", "master_nodes", "interface_nodes_0", "interface_nodes_1", "mode_basis",
            "ffrf_massMatrixReduced", "ffrf_stiffnessMatrixReduced", "freq_mounted_hz", "freq_free_free_hz"} <= names
    assert meta["units"]["length"] == "m" and meta["schema_version"] == 1
    assert meta["info"]["input_hash"] == link.input_hash and "package_version" in meta
    assert meta["info"]["inputs"]["material"]["name"] == "steel"
    assert "low-frequency rule met" in meta["decision"]["reason"]
