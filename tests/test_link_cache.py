"""The reduced-link file and its cache: reuse, invalidation, damage."""
import json
import logging
import zipfile

import numpy as np
import pytest

from flexbodies import STEEL, TITANIUM, LinkGeometry, LinkModel, ReducedBodyFileError, load_reduced_body, reduce_link, save_reduced_body
from flexbodies.reduced import SCHEMA_VERSION

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
    with pytest.raises(ReducedBodyFileError, match=path.name):
        load_reduced_body(path)
    with caplog.at_level(logging.WARNING, logger="flexbodies.link"):
        again = reduce_link(_model(), "static", cache_dir=tmp_path)
    assert not again.cache_hit
    assert any("recomputing" in r.message for r in caplog.records)
    np.testing.assert_allclose(again.frequencies["reduced_hz"], good.frequencies["reduced_hz"], rtol=1e-10)
    assert load_reduced_body(path).input_hash == good.input_hash, "the damaged file was replaced"


def test_an_altered_array_fails_the_checksum(tmp_path):
    link = reduce_link(_model(), "static", cache_dir=tmp_path, use_cache=False)
    path = save_reduced_body(link, tmp_path / "link.npz")
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["mode_basis"] = arrays["mode_basis"] * 1.001  # a valid archive with wrong numbers
    np.savez_compressed(path, **arrays)
    with pytest.raises(ReducedBodyFileError, match="checksum"):
        load_reduced_body(path)


def test_a_file_of_another_version_is_rejected(tmp_path):
    link = reduce_link(_model(), "static", cache_dir=tmp_path, use_cache=False)
    path = save_reduced_body(link, tmp_path / "link.npz")
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    meta = json.loads(str(arrays["meta"]))
    meta["schema_version"] = 99
    arrays["meta"] = np.array(json.dumps(meta))
    np.savez_compressed(path, **arrays)
    with pytest.raises(ReducedBodyFileError, match="version 99"):
        load_reduced_body(path)


def test_a_file_that_is_not_an_archive_is_rejected(tmp_path):
    path = tmp_path / "link.npz"
    path.write_text("not a reduced link")
    with pytest.raises(ReducedBodyFileError, match="not a readable"):
        load_reduced_body(path)
    assert not zipfile.is_zipfile(path)


def test_the_file_holds_what_the_issue_lists(tmp_path):
    link = reduce_link(_model(), "auto", 59.0, cache_dir=tmp_path)
    (path,) = _link_files(tmp_path)
    with np.load(path) as data:
        meta = json.loads(str(data["meta"]))
        names = set(data.files)
    assert {"nodes", "master_nodes", "interface_nodes_0", "interface_nodes_1", "mode_basis",
            "ffrf_massMatrixReduced", "ffrf_stiffnessMatrixReduced", "freq_mounted_hz", "freq_free_free_hz"} <= names
    assert meta["units"]["length"] == "m" and meta["schema_version"] == SCHEMA_VERSION
    assert meta["info"]["input_hash"] == link.input_hash and "package_version" in meta
    assert meta["info"]["inputs"]["material"]["name"] == "steel"
    assert "low-frequency rule met" in meta["decision"]["reason"]


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["fe-{key}.json", "link-*.npz"], ids=["frequency summary", "reduced link"])
def test_another_keys_entry_is_recomputed_with_one_warning(tmp_path, caplog, kind):
    steel, titanium = _model(), _model(material=TITANIUM)
    dirty = tmp_path / "dirty"
    reduce_link(steel, 6, cache_dir=dirty)
    clean = reduce_link(titanium, 6, cache_dir=tmp_path / "clean")
    reduce_link(titanium, 6, cache_dir=dirty)

    def entry(model):
        if kind.startswith("fe-"):
            return dirty / kind.format(key=model.key())
        (path,) = [p for p in _link_files(dirty) if load_reduced_body(p).info["inputs"] == model.fingerprint()]
        return path

    target = entry(titanium)
    # the steel link's entry copied over the titanium link's, as a folder copied between projects might
    target.write_bytes(entry(steel).read_bytes())
    with caplog.at_level(logging.WARNING, logger="flexbodies.cache"):
        again = reduce_link(titanium, 6, cache_dir=dirty)
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1 and target.name in warnings[0] and "not of" in warnings[0], warnings
    assert not again.cache_hit
    np.testing.assert_allclose(again.frequencies["mounted_hz"], clean.frequencies["mounted_hz"], rtol=1e-12)
    np.testing.assert_allclose(again.frequencies["reduced_hz"], clean.frequencies["reduced_hz"], rtol=1e-12)
    np.testing.assert_allclose(again.ffrf["massMatrixReduced"], clean.ffrf["massMatrixReduced"], rtol=1e-9, atol=1e-12)
    # the copied entry would have been another link: titanium is much lighter than steel
    assert again.mass < 0.7 * reduce_link(steel, 6, cache_dir=dirty).mass
    # the entry was replaced by the right one: the next run loads it without a word
    caplog.clear()
    assert reduce_link(titanium, 6, cache_dir=dirty).cache_hit
    assert not [r for r in caplog.records if r.levelno == logging.WARNING]


def test_lengths_equal_up_to_round_off_are_one_link():
    # 0.26 from hinge points comes out as 0.25999999999999995: the same link, one reduction
    computed = LinkGeometry(length=0.13 + 0.13 - 5.551115123125783e-17, eye_outer_radius=0.025, bore_radius=0.012,
                            thickness=0.020, shank_width=0.030, shank_thickness=0.020)
    typed = LinkGeometry(length=0.26, eye_outer_radius=0.025, bore_radius=0.012, thickness=0.020, shank_width=0.030,
                         shank_thickness=0.020)
    near = LinkGeometry(length=0.26 * (1 + 1e-9), eye_outer_radius=0.025, bore_radius=0.012, thickness=0.020,
                        shank_width=0.030, shank_thickness=0.020)
    assert computed == typed and _model(geometry=computed).key() == _model(geometry=typed).key()
    assert _model(geometry=near).key() != _model(geometry=typed).key(), "a real change of length is a new link"
