"""The isolation formulas and the case's link predicates, each in its one home."""
import dataclasses

import numpy as np
import pytest

from workbook.answers.isolation import efficiency, level_db, pylon_sum, relative_error, transmissibility
from workbook.model.reference import reference_case


def test_pylon_sum_adds_static_forces_histories_and_phasors_of_the_named_channels_only():
    rng = np.random.default_rng(1)
    histories = {name: rng.normal(size=(50, 3)) for name in ("a", "b", "c")}
    np.testing.assert_allclose(pylon_sum(histories, ["a", "c"]), histories["a"] + histories["c"], rtol=0, atol=0)
    static = {"a": np.array([1.0, -2.0, 3.0]), "b": np.array([10.0, 0.0, -1.0]), "ground": np.array([1e9, 1e9, 1e9])}
    np.testing.assert_array_equal(pylon_sum(static, ("a", "b")), [11.0, -2.0, 2.0])
    phasors = {"a": np.array([1 + 1j, 0, 2j]), "b": np.array([-1 + 0j, 3, 1 - 1j])}
    np.testing.assert_array_equal(pylon_sum(phasors, phasors), [1j, 3, 1 + 1j])
    with pytest.raises(ValueError, match="pylon force is undefined"):
        pylon_sum(static, [])


def test_transmissibility_efficiency_and_level():
    t = transmissibility(np.array([50.0, 1000.0, 0.0]), 1000.0)
    np.testing.assert_allclose(t, [0.05, 1.0, 0.0])
    np.testing.assert_allclose(efficiency(t), [95.0, 0.0, 100.0])
    levels = level_db(t)
    np.testing.assert_allclose(levels[:2], [20 * np.log10(0.05), 0.0])
    assert levels[2] == -np.inf
    # an amplified force (T > 1) isolates negatively
    assert efficiency(2.0) == pytest.approx(-100.0)


def test_relative_error_is_signed_and_relative_to_the_reference():
    np.testing.assert_allclose(relative_error([1.1, 0.9, 2.0], [1.0, 1.0, 2.0]), [10.0, -10.0, 0.0])


def test_the_link_mode_rule_and_the_flexibility_predicate_live_on_the_case():
    case = reference_case()
    modal = dataclasses.replace(case, links=tuple(dataclasses.replace(link, modes=6) for link in case.links))
    first, second = modal.links[0].name, modal.links[1].name
    assert modal.link_is_flexible(first) and modal.link_modes(first) == 6
    one_rigid = dataclasses.replace(modal, links=(dataclasses.replace(modal.links[0], flexible=False),) + modal.links[1:])
    assert not one_rigid.link_is_flexible(first) and one_rigid.link_modes(first) == "static"
    assert one_rigid.link_modes(second) == 6
    all_rigid = modal.with_rigid_links()
    assert all(not all_rigid.link_is_flexible(link.name) and all_rigid.link_modes(link.name) == "static"
               for link in all_rigid.links)
    assert not case.rig_sensors_built
