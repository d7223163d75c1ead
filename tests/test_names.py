"""Names: a user's names are unique across every kind of item, checked by
the case (and so by ``mountwb check``, which names the cell), and the
scene names its own Exudyn items within their kind, so no user name can
collide with them."""
import dataclasses

import pytest
from excel_helpers import copy_reference, set_cells

from workbook.cli.main import main
from workbook.errors import CaseError
from workbook.model.reference import LP_SPOOL
from workbook.scene.build import build_scene


@pytest.fixture(scope="module")
def case(coarse_reference):
    return coarse_reference


def _renamed(items, index, name):
    return tuple(dataclasses.replace(item, name=name) if i == index else item for i, item in enumerate(items))


@pytest.mark.parametrize("kind, change, owner", [
    ("hinge 'engine'", lambda c: {"hinges": _renamed(c.hinges, 0, "engine")}, "the scene's own engine"),
    ("hinge 'front-left'", lambda c: {"hinges": _renamed(c.hinges, 0, "front-left")}, "link 'front-left'"),
    ("excitation 'thrust'", lambda c: {"excitations": _renamed(c.excitations, 0, "thrust")},
     "static load 'thrust'"),
    ("rotor 'LP rotor'", lambda c: {"rotors": (dataclasses.replace(LP_SPOOL, name="LP rotor"),)},
     "excitation 'LP rotor'"),
    ("static load 'pylon'", lambda c: {"static_loads": _renamed(c.static_loads, 0, "pylon")},
     "the scene's own pylon"),
])
def test_a_name_used_by_another_kind_of_item_is_refused_naming_both(case, kind, change, owner):
    with pytest.raises(CaseError, match=rf"{kind}, field 'name'.*not used before \(it already names {owner}\)"):
        dataclasses.replace(case, **change(case))


def test_check_names_the_cell_of_a_hinge_named_after_a_link(tmp_path, capsys):
    path = copy_reference(tmp_path)
    set_cells(path, {("Hinges", "name", 3): "front-left"})
    assert main(["check", str(path)]) == 2
    error = capsys.readouterr()
    assert "sheet 'Hinges'" in error.out + error.err and "cell A3" in error.out + error.err
    assert "it already names link 'front-left'" in error.out + error.err


def test_a_user_name_equal_to_an_internal_exudyn_name_builds(cache_dir, case):
    """Before the scene named its items within their kind, a hinge named
    like the rotors' gyroscopic object (or a static load named like the
    excitation's Exudyn load) stopped the build inside Exudyn."""
    odd = dataclasses.replace(case.with_rigid_links(), hinges=_renamed(case.hinges, 0, "rotor gyroscopics"),
                              rotors=(LP_SPOOL,), static_loads=_renamed(case.static_loads, 0, "force front-down-left"))
    scene = build_scene(odd, odd.excitations[0])
    assert set(scene.hinges) == {h.name for h in odd.hinges} and scene.gyroscopics is not None
