"""A body meshed as unconnected pieces is refused before its reduction.

A loose piece moves freely: its rigid-body motions count among the body's
"elastic" modes, the first free-free frequency is 0 Hz and the mode
decision divided by it (before: a raw ``ZeroDivisionError`` and a
traceback). The mesh file is named with its number of pieces.
"""
import dataclasses

import meshio
import numpy as np
import pytest
from conftest import COARSE_ELEMENT_SIZE

from flexbodies.casing import CasingGeometry, CasingInterface, mesh_casing
from flexbodies.casing_reduction import CasingModel, reduce_casing
from flexbodies.meshing import mesh_pieces
from flexbodies.selection import decide_modes
from workbook.errors import CaseError
from workbook.model.casing import EngineCasing
from workbook.model.reference import reference_case
from workbook.scene.engine_casing import reduce_engine_casing

#: A tube 0.4 m long and a loose ring 0.2 m beyond it, each meshed on its own.
TUBE, LOOSE = CasingGeometry(0.1, 0.02, 0.0, 0.4), CasingGeometry(0.1, 0.02, 0.6, 0.8)
INTERFACES = (CasingInterface("eye", (0.2, 0.0, 0.1), "eye", 0.05),
              CasingInterface("bearing", (0.2, 0.0, 0.0), "bearing", 0.04))


@pytest.fixture(scope="module")
def meshes():
    return mesh_casing(TUBE, 0.04), mesh_casing(LOOSE, 0.04)


def _write(pieces, path):
    parts = [piece.to_meshio() for piece in pieces]
    offsets = np.cumsum([0] + [len(p.points) for p in parts[:-1]])
    cells = np.vstack([p.cells[0].data + offset for p, offset in zip(parts, offsets, strict=True)])
    meshio.Mesh(np.vstack([p.points for p in parts]), [(parts[0].cells[0].type, cells)]).write(path)
    return str(path)


def test_the_pieces_are_counted_element_by_element(meshes, tmp_path):
    """Each piece's element count is that of the mesh it was written from."""
    tube, loose = meshes
    joined = _write(meshes, tmp_path / "two.vtu")
    with pytest.raises(ValueError) as error:
        reduce_casing(CasingModel(INTERFACES, mesh_file=joined), "auto", [100.0], use_cache=False)
    counts = f"{tube.mesh.nelements}, {loose.mesh.nelements} elements"
    assert f"two.vtu: the mesh is 2 unconnected pieces ({counts})" in str(error.value)
    assert "x 0.6 to 0.8" in str(error.value)                 # where the loose piece lies
    assert np.bincount(mesh_pieces(tube.mesh)).tolist() == [tube.mesh.nelements]


def test_one_piece_reduces_with_a_positive_fundamental(meshes, tmp_path):
    """The tube alone, written and read the same way, passes and its first
    free-free frequency is that of a bending tube (positive, not 0)."""
    (reduced,) = reduce_casing(CasingModel(INTERFACES, mesh_file=_write(meshes[:1], tmp_path / "one.vtu")),
                               "static", [100.0], use_cache=False)
    assert reduced.frequencies["free_free_hz"][0] > 100.0


def test_a_case_with_a_two_piece_casing_names_the_mesh_field(meshes, tmp_path):
    case = reference_case(element_size=COARSE_ELEMENT_SIZE)
    casing = EngineCasing(bearing_planes=(0.2, 0.3), mesh=_write(meshes, tmp_path / "casing.vtu"))
    case = dataclasses.replace(case, engine=dataclasses.replace(case.engine, casing=casing))
    with pytest.raises(CaseError, match=r"engine casing, field 'mesh': .*casing.vtu: the mesh is 2 unconnected "
                                        r"pieces"):
        reduce_engine_casing(case, 100.0)


def test_a_zero_fundamental_is_refused_in_words():
    with pytest.raises(ValueError, match="first elastic frequency is 0 Hz: part of it moves freely"):
        decide_modes("auto", 0.0, 100.0)
