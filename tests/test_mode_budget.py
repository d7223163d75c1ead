"""An excitation far above a mount's range asks for more link modes than a
reduction keeps: refused in words before the modes are computed.

Before, 14910 Hz (an rpm typed as Hz) on the flexible links sized the second
Lanczos batch from a count growing as f^2 (9000 modes: ARPACK asked for
18165 vectors of a 47k-DOF link, a MemoryError of 6.4 GiB), and 1e5 Hz ran
for minutes in gigabytes. The count is now extrapolated from the modal
density of the batch computed so far, checked against the Lanczos count.
"""
import dataclasses

import numpy as np
import pytest
from conftest import COARSE_ELEMENT_SIZE

from flexbodies.craig_bampton import MODE_BUDGET, ModeBudgetExceeded, estimated_mode_count, fixed_interface_set
from flexbodies.interior import InteriorSolver
from flexbodies.link import _meshed_fe_model
from flexbodies.reduction import couple
from workbook.errors import CaseError
from workbook.model.case import ModeCutoff
from workbook.model.reference import LP_ROTOR, reference_case
from workbook.scene.build import reduce_links


@pytest.fixture(scope="module")
def thrust_rod(cache_dir):
    """The coarse reference thrust rod's interior solver (14k DOF)."""
    model = reference_case(element_size=COARSE_ELEMENT_SIZE).link_map["thrust-left"].model
    fe, _, _, _ = _meshed_fe_model(model)
    coupled = couple(fe, model.interface)
    return InteriorSolver(coupled.stiffness, coupled.mass, coupled.coupling)


def _only_thrust_rods_flexible(case):
    links = tuple(dataclasses.replace(link, flexible=link.name.startswith("thrust")) for link in case.links)
    return dataclasses.replace(case, links=links)


def test_the_estimate_from_eight_modes_is_near_the_lanczos_count(thrust_rod):
    """From the 8 lowest fixed-interface modes (239 to 1986 Hz), the count
    below 10 and 20 kHz within a factor 1.5 of the modes Lanczos finds
    (measured: 41 against 31, 81 against 56)."""
    lowest, _ = thrust_rod.fixed_interface_modes(8)
    frequencies, _ = thrust_rod.fixed_interface_modes(70)
    for cutoff in (10e3, 20e3):
        counted = int(np.sum(frequencies < cutoff))
        estimate, _ = estimated_mode_count(lowest, cutoff)
        assert counted <= estimate <= 1.5 * counted, (cutoff, counted, estimate)


def test_a_far_cutoff_is_refused_after_the_first_batch(thrust_rod):
    """4 x 1e5 Hz: refused after the first batch of 8 modes, none more asked for."""
    asked = []

    def modes_of(count):
        asked.append(count)
        return thrust_rod.fixed_interface_modes(count)

    with pytest.raises(ModeBudgetExceeded, match=r"up to 400000 Hz: about \d+ of them .* more than the 200"):
        fixed_interface_set(modes_of, len(thrust_rod.interior), cutoff_hz=4e5)
    assert asked == [8]


def test_an_rpm_typed_as_hz_is_refused_naming_the_excitation(cache_dir):
    """14910 Hz (the reference HP spool's 14910 rpm) on the flexible thrust rods."""
    typo = dataclasses.replace(LP_ROTOR, frequency_hz=14910.0, rpm=None)
    case = _only_thrust_rods_flexible(dataclasses.replace(reference_case(element_size=COARSE_ELEMENT_SIZE),
                                                          excitations=(typo,)))
    with pytest.raises(CaseError) as error:
        reduce_links(case, typo)
    words = str(error.value)
    assert words.startswith(f"excitation {LP_ROTOR.name!r}, field 'frequency_hz': found 14910.0")
    assert "an excitation of 14910 Hz asks for about" in words and "of link 'thrust-" in words
    assert f"more than the {MODE_BUDGET}" in words and "is it a speed in rpm? (14910 rpm is 248.5 Hz" in words
    assert int(words.split("asks for about ")[1].split()[0]) > MODE_BUDGET


def test_a_link_cutoff_of_its_own_names_the_link_modes(cache_dir):
    case = _only_thrust_rods_flexible(reference_case(element_size=COARSE_ELEMENT_SIZE))
    links = tuple(dataclasses.replace(link, modes=ModeCutoff(1e6)) if link.name == "thrust-left" else link
                  for link in case.links)
    with pytest.raises(CaseError, match=r"link 'thrust-left', field 'modes': found .*a cut-off below about"):
        reduce_links(dataclasses.replace(case, links=links))
