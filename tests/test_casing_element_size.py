"""A parametric casing meshed too coarse for its wall is refused naming
``element_size`` and a size that meshes.

Quadratic tetrahedra several times larger than the wall's thickness fold
where their edge nodes follow the curved surfaces. Before, 0.14 m on the
reference casing (25 mm wall) stopped on "tangled or degenerate" elements
with the blame on the case's ``geometry`` and the "element node order".
"""
import dataclasses

import pytest
from conftest import COARSE_ELEMENT_SIZE

from flexbodies.assembly import tangled_elements
from flexbodies.casing import mesh_casing
from workbook.errors import CaseError
from workbook.model.reference import reference_case, reference_casing
from workbook.scene.engine_casing import reduce_engine_casing


def _with_casing(element_size):
    case = reference_case(element_size=COARSE_ELEMENT_SIZE)
    return dataclasses.replace(case, engine=dataclasses.replace(case.engine,
                                                                casing=reference_casing(element_size=element_size)))


@pytest.mark.parametrize("element_size", [0.14, 0.2])
def test_a_size_that_tangles_names_element_size_and_one_that_meshes(element_size):
    """The size offered is checked on its own mesh: no tangled element; the
    size refused has some."""
    case = _with_casing(element_size)
    geometry = case.engine.casing.geometry
    with pytest.raises(CaseError) as error:
        reduce_engine_casing(case, 100.0)
    assert error.value.field == "element_size" and error.value.value == element_size
    words = str(error.value)
    assert "geometry" not in words and "node order" not in words
    largest = float(words.split("an element size of at most ")[1].split(" m")[0])
    assert largest < element_size and largest > 2 * geometry.thickness
    assert tangled_elements(mesh_casing(geometry, element_size).mesh).size > 0
    assert tangled_elements(mesh_casing(geometry, largest).mesh).size == 0
