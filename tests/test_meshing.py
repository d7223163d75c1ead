"""Link geometry, gmsh meshing, user meshes and bores (real gmsh, meshio, scikit-fem)."""
import logging
import math

import gmsh
import meshio
import numpy as np
import pytest
import skfem

from flexbodies.assembly import assemble
from flexbodies.eigen import natural_frequencies
from flexbodies.geometry import LinkGeometry
from flexbodies.materials import STEEL
from flexbodies.meshing import BodyMesh, BoreSpec, default_element_size, load_mesh, mesh_link

REFERENCE = LinkGeometry(length=0.30, eye_outer_radius=0.030, bore_radius=0.015,
                         thickness=0.025, shank_width=0.040, shank_thickness=0.025)
COARSE = 0.015  # m; coarse mesh for the file round trips
BORE_AREA = 2 * math.pi * REFERENCE.bore_radius * REFERENCE.thickness


def _geometric_specs(g: LinkGeometry):
    return [BoreSpec("A", centre=(0, 0, 0), axis=(0, 0, 1), radius=g.bore_radius),
            BoreSpec("B", centre=(g.length, 0, 0), axis=(0, 0, -1), radius=g.bore_radius)]


def _frequencies(link: BodyMesh) -> np.ndarray:
    model = assemble(link, STEEL)
    return natural_frequencies(model.stiffness, model.mass, 9, shift_hz=200.0)[0][6:]


@pytest.fixture(scope="module")
def reference_mesh() -> BodyMesh:
    return mesh_link(REFERENCE)


@pytest.fixture(scope="module")
def coarse_mesh() -> BodyMesh:
    return mesh_link(REFERENCE, element_size=COARSE)


@pytest.fixture(scope="module")
def coarse_frequencies(coarse_mesh) -> np.ndarray:
    return _frequencies(coarse_mesh)


# --- geometry -----------------------------------------------------------------------


@pytest.mark.parametrize("change, words", [
    (dict(bore_radius=0.03), "bore radius .* must be smaller than the eye outer radius"),
    (dict(shank_width=0.06), "shank width .* must be smaller than the eye diameter"),
    (dict(length=0.06), "the eyes overlap"),
    (dict(shank_thickness=0.03), "shank thickness .* must not exceed the eye thickness"),
    (dict(thickness=-0.025), "thickness must be a positive length"),
])
def test_geometry_validation(change, words):
    values = dict(length=0.3, eye_outer_radius=0.03, bore_radius=0.015, thickness=0.025,
                  shank_width=0.04, shank_thickness=0.025) | change
    with pytest.raises(ValueError, match=words):
        LinkGeometry(**values)


def test_reference_geometry_volume():
    # Two rings 2 pi (R^2 - r^2) t plus the shank strip outside the eye discs.
    assert REFERENCE.volume == pytest.approx(3.50830e-4, rel=1e-5)
    assert default_element_size(REFERENCE) == pytest.approx(0.010)


# --- gmsh meshing -------------------------------------------------------------------


def test_reference_mesh_and_bores(reference_mesh):
    mesh = reference_mesh
    assert [b.name for b in mesh.bores] == ["A", "B"]
    assert 15_000 <= 3 * mesh.nodes.shape[0] <= 25_000
    assert mesh.describe().startswith("quadratic tetrahedra, ")
    for bore, centre in zip(mesh.bores, ([0, 0, 0], [REFERENCE.length, 0, 0]), strict=True):
        np.testing.assert_allclose(bore.centre, centre, atol=1e-7)
        np.testing.assert_allclose(bore.axis, [0, 0, 1])
        relative = mesh.nodes[bore.nodes] - bore.centre
        radial = np.hypot(relative[:, 0], relative[:, 1])
        np.testing.assert_allclose(radial, REFERENCE.bore_radius, rtol=1e-9)
        assert np.abs(relative[:, 2]).max() == pytest.approx(REFERENCE.thickness / 2, abs=1e-8)
        # The quadratic surface through nodes on the circle is slightly
        # shorter than the circle: measured -1.3e-5 at 16 faces around.
        assert bore.weights.sum() == pytest.approx(BORE_AREA, rel=3e-5)
        assert bore.area == bore.weights.sum()
        # Corner nodes of 6-node triangles carry (almost) no load: exactly
        # none on flat faces, ~1e-3 of an edge node's share on this curved one.
        corner = bore.nodes < mesh.mesh.nvertices
        assert 0.2 < corner.mean() < 0.35
        assert np.abs(bore.weights[corner]).max() < 1e-2 * bore.weights[~corner].min()


def test_mesh_link_is_deterministic_silent_and_leaves_nothing(tmp_path, monkeypatch, coarse_mesh, capfd):
    monkeypatch.chdir(tmp_path)
    capfd.readouterr()
    again = mesh_link(REFERENCE, element_size=COARSE)
    assert capfd.readouterr() == ("", "")
    assert list(tmp_path.iterdir()) == []
    assert not gmsh.isInitialized()
    np.testing.assert_array_equal(again.nodes, coarse_mesh.nodes)
    np.testing.assert_array_equal(again.mesh.t, coarse_mesh.mesh.t)
    for a, b in zip(again.bores, coarse_mesh.bores, strict=True):
        np.testing.assert_array_equal(a.weights, b.weights)


def test_element_size_must_be_positive():
    with pytest.raises(ValueError, match="element size must be a positive length"):
        mesh_link(REFERENCE, element_size=0.0)


def test_surface_triangles_enclose_the_volume(coarse_mesh):
    tris = coarse_mesh.surface_triangles()
    assert tris.ndim == 2 and tris.shape[1] == 3 and tris.max() < coarse_mesh.nodes.shape[0]
    x = coarse_mesh.nodes[tris]
    # Divergence theorem: outward triangles give the enclosed volume.
    volume = np.einsum("ij,ij->i", x[:, 0], np.cross(x[:, 1], x[:, 2])).sum() / 6
    assert volume == pytest.approx(REFERENCE.volume, rel=2e-3)


# --- user meshes ------------------------------------------------------------------------


@pytest.mark.parametrize("suffix, file_format, specs", [
    (".msh", "gmsh", _geometric_specs(REFERENCE)),
    (".vtu", None, _geometric_specs(REFERENCE)),
    (".inp", None, [BoreSpec("A", node_set="A"), BoreSpec("B", node_set="b")]),
])
def test_user_mesh_round_trip(tmp_path, coarse_mesh, coarse_frequencies, suffix, file_format, specs):
    path = tmp_path / f"link{suffix}"
    meshio.write(path, coarse_mesh.to_meshio(), file_format=file_format)
    loaded = load_mesh(path, specs)
    assert loaded.source == str(path)
    np.testing.assert_array_equal(loaded.nodes, coarse_mesh.nodes)
    for got, direct in zip(loaded.bores, coarse_mesh.bores, strict=True):
        assert got.name == direct.name
        np.testing.assert_array_equal(got.nodes, direct.nodes)
        np.testing.assert_allclose(got.weights, direct.weights, rtol=1e-12, atol=1e-20)
        np.testing.assert_allclose(got.centre, direct.centre, atol=1e-6)
        assert abs(got.axis @ direct.axis) == pytest.approx(1.0)
        assert got.radius == pytest.approx(direct.radius, rel=1e-4)
    np.testing.assert_allclose(_frequencies(loaded), coarse_frequencies, rtol=1e-9)


def test_quadratic_hexahedron_file(tmp_path):
    """hexahedron27 in meshio's (VTK's) node order maps onto scikit-fem's."""
    x = np.linspace(0.0, 0.02, 3)
    link = BodyMesh(skfem.MeshHex2.from_mesh(skfem.MeshHex1.init_tensor(x, x, x)))
    path = tmp_path / "cube.vtu"
    meshio.write(path, link.to_meshio())
    loaded = load_mesh(path, [])
    np.testing.assert_array_equal(loaded.nodes, link.nodes)
    direct, from_file = (assemble(m, STEEL).stiffness for m in (link, loaded))
    assert abs(from_file - direct).max() == 0.0


def test_millimetre_file_with_scale(tmp_path, coarse_mesh):
    data = coarse_mesh.to_meshio()
    data.points *= 1e3
    path = tmp_path / "link_mm.vtu"
    meshio.write(path, data)
    loaded = load_mesh(path, _geometric_specs(REFERENCE), scale=1e-3)
    np.testing.assert_allclose(loaded.nodes, coarse_mesh.nodes, rtol=1e-12, atol=1e-15)
    assert [b.nodes.size for b in loaded.bores] == [b.nodes.size for b in coarse_mesh.bores]


def _write_gmsh_plate_with_hole(path):
    """A second-order gmsh file in mm with a physical surface group "BORE"."""
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        box = occ.addBox(-30, -30, 0, 60, 60, 20)
        hole = occ.addCylinder(0, 0, -5, 0, 0, 30, 10)
        occ.cut([(3, box)], [(3, hole)])
        occ.synchronize()
        bore = [tag for _, tag in gmsh.model.getEntities(2)
                if abs(occ.getMass(2, tag) - 2 * math.pi * 10 * 20) < 1e-6]
        gmsh.model.addPhysicalGroup(2, bore, name="BORE")
        gmsh.model.addPhysicalGroup(3, [tag for _, tag in gmsh.model.getEntities(3)], name="PLATE")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 8)
        gmsh.option.setNumber("Mesh.ElementOrder", 2)
        gmsh.model.mesh.generate(3)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


def test_gmsh_physical_group_bore(tmp_path):
    """The named surface of a second-order gmsh file (lost by skfem's own import)."""
    path = tmp_path / "plate.msh"
    _write_gmsh_plate_with_hole(path)
    named, found = load_mesh(path, [
        BoreSpec("named", node_set="bore"),
        BoreSpec("found", centre=(0, 0, 0), axis=(0, 0, 1), radius=0.010),
    ], scale=1e-3).bores
    np.testing.assert_array_equal(named.nodes, found.nodes)
    np.testing.assert_allclose(named.weights, found.weights)
    # gmsh's default sizing puts few faces around this hole: measured -2.3e-4.
    assert named.weights.sum() == pytest.approx(2 * math.pi * 0.010 * 0.020, rel=1e-3)
    np.testing.assert_allclose(named.centre, [0, 0, 0.010], atol=2e-6)  # fitted: measured 8e-7
    assert abs(named.axis[2]) == pytest.approx(1.0)
    assert named.radius == pytest.approx(0.010, rel=1e-3)  # fitted: measured -2.3e-4


def test_linear_tetrahedra_load_with_a_warning(tmp_path, caplog):
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], dtype=float)
    path = tmp_path / "two_tets.vtu"
    meshio.write(path, meshio.Mesh(points, [("tetra", np.array([[0, 1, 2, 3], [1, 2, 3, 4]]))]))
    with caplog.at_level(logging.WARNING, logger="flexbodies.meshing"):
        link = load_mesh(path, [])
    assert "too stiff in bending" in caplog.text
    assert link.describe().startswith("linear tetrahedra, 2 elements, 5 nodes, 15 DOF")


# --- errors -------------------------------------------------------------------------------


def test_missing_file(tmp_path):
    path = tmp_path / "nowhere.msh"
    with pytest.raises(FileNotFoundError, match=f"mesh file {path} does not exist"):
        load_mesh(path, [])


def test_unreadable_file(tmp_path):
    path = tmp_path / "garbage.vtu"
    path.write_text("this is not a mesh")
    with pytest.raises(ValueError, match=f"cannot read mesh file {path}"):
        load_mesh(path, [])


def test_file_without_volume_cells(tmp_path):
    path = tmp_path / "surface.vtu"
    meshio.write(path, meshio.Mesh(np.eye(3), [("triangle", np.array([[0, 1, 2]]))]))
    with pytest.raises(ValueError, match=f"{path}: no supported volume cells.*holds triangle"):
        load_mesh(path, [])


def test_unknown_node_set_lists_the_known_ones(tmp_path, coarse_mesh):
    path = tmp_path / "link.inp"
    meshio.write(path, coarse_mesh.to_meshio())
    with pytest.raises(ValueError, match=f"node set 'BORE_C' not found in {path}; node sets in the file: A, B"):
        load_mesh(path, [BoreSpec("C", node_set="BORE_C")])


def test_bore_that_matches_nothing(tmp_path, coarse_mesh):
    path = tmp_path / "link.vtu"
    meshio.write(path, coarse_mesh.to_meshio())
    spec = BoreSpec("A", centre=(0, 0, 0), axis=(0, 0, 1), radius=15.0)  # mm instead of m
    with pytest.raises(ValueError, match=(f"bore 'A': no boundary face of {path} lies on a cylinder "
                                          r"of radius 15 m .*boundary node nearest to that cylinder is 0.33 m from the axis")):
        load_mesh(path, [spec])


@pytest.mark.parametrize("kwargs, words", [
    (dict(node_set="A", radius=0.01), "either node_set or centre/axis/radius"),
    (dict(centre=(0, 0, 0), axis=(0, 0, 1)), "needs centre, axis and radius"),
    (dict(centre=(0, 0, 0), axis=(0, 0, 0), radius=0.01), "non-zero vector"),
])
def test_bore_spec_validation(kwargs, words):
    with pytest.raises(ValueError, match=words):
        BoreSpec("A", **kwargs)
