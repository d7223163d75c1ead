"""The axial stiffness of a reduced link equals its full FE model's."""
import pytest
from test_reduction import TEST_LINK, _flexibility_at_b

from flexbodies import STEEL, LinkModel, build_fe_model, reduce_link_set
from flexbodies.reduction import couple
from workbook.answers.link_stiffness import axial_stiffness


@pytest.mark.slow
def test_axial_stiffness_is_the_full_fe_models(cache_dir):
    """The test link's eyes lie on its x axis: the full model's axial
    stiffness is 1 / (flexibility of eye B in x, eye A clamped), RBE2 bore
    couplings as the reduction uses; the fixed-interface modes kept do not
    change it."""
    model = LinkModel(geometry=TEST_LINK, material=STEEL)
    reduced = reduce_link_set(model, 3, (1000.0,))[0]
    coupled = couple(build_fe_model(model)[0], model.interface)
    masters = coupled.coupling.master_dofs
    full = 1.0 / _flexibility_at_b(coupled.stiffness, masters[0], masters[1])[0, 0]
    assert axial_stiffness(reduced) == pytest.approx(full, rel=1e-7)
