"""Whether tensions shift a link's first pinned-pinned frequency, decided by concavity bounds on a grid
(workbook.design.pinned_shift), against the eigenvalue problem at every tension."""
import numpy as np
import pytest

from flexbodies import LinkGeometry, LinkModel
from flexbodies.geometric_stiffness import link_stiffening
from workbook.design.pinned_shift import ShiftBracket

pytestmark = pytest.mark.slow

FRACTION = 0.005


class _Counted:
    """A link's stiffening that counts the tensions its eigenvalue problems are solved at."""

    def __init__(self, stiffening):
        self.stiffening, self.buckling_load, self.solved = stiffening, stiffening.buckling_load, 0

    def pinned_hz(self, tension, count=2):
        self.solved += np.size(tension)
        return self.stiffening.pinned_hz(tension, count)


def _limit(stiffening, sign: float) -> float:
    """The tension (bisection, to round-off) where the shift is FRACTION, in tension (sign 1) or compression."""
    unloaded = stiffening.pinned_hz(0.0, 1)[0]
    low, high = 0.0, 0.9 * stiffening.buckling_load
    for _ in range(200):
        middle = 0.5 * (low + high)
        shift = abs(stiffening.pinned_hz(sign * middle, 1)[0] / unloaded - 1.0)
        low, high = (low, middle) if shift > FRACTION else (middle, high)
    return sign * 0.5 * (low + high)


def test_the_bounds_decide_as_the_eigenvalues_and_spare_most_of_them(tmp_path):
    model = LinkModel(geometry=LinkGeometry(length=0.20, eye_outer_radius=0.025, bore_radius=0.012, thickness=0.020,
                                            shank_width=0.030, shank_thickness=0.020), element_size=0.012)
    stiffening = link_stiffening(model, cache_dir=tmp_path)
    rng = np.random.default_rng(1)
    limits = [_limit(stiffening, sign) for sign in (1.0, -1.0)]
    near = np.concatenate([limit * (1 + np.array([-1e-12, -1e-6, 0.0, 1e-6, 1e-12])) for limit in limits])
    tensions = np.concatenate([rng.uniform(-1.0, 1.2, 4000) * stiffening.buckling_load, near, [0.0]])
    unloaded = stiffening.pinned_hz(0.0, 1)[0]
    expected = np.abs(stiffening.pinned_hz(tensions, 1)[:, 0] / unloaded - 1.0) > FRACTION
    counted = _Counted(stiffening)
    bracket = ShiftBracket.of(counted)
    counted.solved = 0
    assert np.array_equal(bracket.shifted(tensions, FRACTION), expected)
    assert expected.any() and not expected.all()
    assert counted.solved < 0.25 * len(tensions)          # beyond the grid and near the limits only
