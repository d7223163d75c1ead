"""The design evaluation's mass matrix far from the prepared state, against Exudyn's at that state.

Hinges at a quarter of the reference stiffness sag the engine by 6.5 mm and
turn the links by about a hundredth of a radian: the expansion's M of first
order in the rotation is then 1e-4 off Exudyn's; turned exactly (a
floating-frame body's kinetic energy in its own frame does not change with
its rotation) it agrees, body by body, to the first-order change of the
modal coordinates and the engine's small rotation.
"""
import dataclasses

import numpy as np
import pytest

from tests.conftest import COARSE_ELEMENT_SIZE
from workbook.design.assembly import turned_mass
from workbook.design.linear_mount import LinearMount
from workbook.model.reference import reference_case

pytestmark = pytest.mark.slow


def _softer(case, factor):
    return dataclasses.replace(case, hinges=tuple(
        dataclasses.replace(h, stiffness=tuple(h.values("stiffness") * factor)) for h in case.hinges))


def test_turned_mass_is_exudyns_at_the_design_state(cache_dir):
    case = reference_case(element_size=COARSE_ELEMENT_SIZE)
    case = dataclasses.replace(case, excitations=case.excitations[:1])
    design = _softer(case, 0.25)
    mount, at_design = LinearMount.prepare(case), LinearMount.prepare(design)
    name = case.excitations[0].name
    solution = mount.solve_items(design)[0]
    expansion, exact = solution.prepared.expansion, at_design.items[name].expansion
    dq = exact.state - expansion.state            # the design's state, solved by Exudyn
    assert np.abs(dq - solution.state.dq).max() < 1e-3 * np.abs(dq).max()
    expected = exact.rest.full(exact.rest.at("mass", np.zeros_like(dq)))
    first_order = expansion.rest.full(expansion.rest.at("mass", dq))
    turned = expansion.rest.full(turned_mass(expansion, dq))
    for block in expansion.rest.coordinates:
        block = block[block < len(dq)]
        own = np.abs(expected[np.ix_(block, block)]).max()
        turned_error = np.abs(turned - expected)[np.ix_(block, block)].max() / own
        assert turned_error < 1e-7
    links = expansion.euler_blocks.ravel()
    assert np.abs(first_order - expected)[np.ix_(links, links)].max() > 1e4 * np.abs(
        turned - expected)[np.ix_(links, links)].max()
