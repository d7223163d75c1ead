"""The body-by-body harmonic solve of designs together (workbook.design.blocks.channel_solve) on small mounts
whose whole matrices are solved directly."""
import numpy as np
import pytest

from workbook.design.blocks import BACKWARD_ERROR, ChannelCoupling, channel_solve


class _Layout:
    """Two bodies of three coordinates each (w = b = 3); body 0 has *width* of them independent (the rest
    padding), body 1 all three."""

    coordinates = np.array([[0, 1, 2], [3, 4, 5]])

    def __init__(self, width):
        self.count = width + 3
        self.independent = np.array([[0, 1, 2][:width] + [self.count] * (3 - width), [width, width + 1, width + 2]])

    def marker_rows(self, channels):
        return channels.blocks, channels.positions


class _Channels:
    """Channel 0 from body 0 to body 1, channel 1 from the ground to body 1: points 0, 1, (ground), 3."""

    count = 2
    blocks = np.array([0, 1, 0, 1])
    positions = np.array([[0, 1, 2], [0, 1, 2], [3, 3, 3], [0, 1, 2]])


def _problem(rng, gap, width):
    """Bodies, point Jacobians, impedances and loads of one design; body 0, on no channel to the ground, is
    ``gap`` from singular (the whole matrix, with channel 0's springs, is not); of its three coordinates the
    last ``3 - width`` are padding (one on the diagonal, zero elsewhere and in its Jacobian and load)."""
    jacobian = rng.standard_normal((4, 3, 3))
    jacobian[2] = 0.0
    jacobian[0] *= -1.0
    jacobian[0, :, width:] = 0.0
    impedance = np.array([np.eye(3) * (2.0 + 0.1j), np.diag([1.0, 2.0, 3.0]) * (1.0 + 0.05j)])
    dynamic = np.array([gap * np.diag([1.0] * width + [1.0 / gap] * (3 - width)),
                        rng.standard_normal((3, 3)) + 5 * np.eye(3)], dtype=complex)
    loads = rng.standard_normal((2, 3)) + 1j * rng.standard_normal((2, 3))
    loads[0, width:] = 0.0
    return dynamic, jacobian, impedance, loads


def _whole(dynamic, jacobian, impedance, loads):
    """The channels' separations of the whole 6 x 6 solve."""
    matrix = np.zeros((6, 6), dtype=complex)
    matrix[:3, :3], matrix[3:, 3:] = dynamic
    channels = np.zeros((2, 3, 6))
    channels[0, :, :3], channels[0, :, 3:] = jacobian[0], jacobian[1]
    channels[1, :, 3:] = jacobian[3]
    for c in range(2):
        matrix += channels[c].T @ impedance[c] @ channels[c]
    return channels @ np.linalg.solve(matrix, loads.reshape(6))


@pytest.mark.parametrize("width", [3, 2])
def test_body_by_body_is_the_whole_solve_and_a_body_near_its_own_resonance_is_marked(width):
    """Bodies of the same width are solved together, of another width apart, each on its own coordinates."""
    rng = np.random.default_rng(2)
    coupling = ChannelCoupling.of(_Layout(width), _Channels())
    assert list(coupling.moving) == [0, 1, 3] and len(coupling.coupled) == 2 and list(coupling.grounded) == [2]
    assert [(list(g.blocks), g.width) for g in coupling.groups] == ([([0, 1], 3)] if width == 3 else [([0], 2), ([1], 3)])
    for gap, trusted in ((3.0, True), (1e-13, False)):
        dynamic, jacobian, impedance, loads = _problem(rng, gap, width)
        expected = _whole(dynamic, jacobian, impedance, loads)
        separation, trouble = channel_solve(coupling, dynamic[None], jacobian[None], impedance[None], loads[None])
        assert trouble[0] == (not trusted)
        if trusted:
            assert np.abs(separation[0] - expected).max() <= 1e-12 * np.abs(expected).max()
    assert BACKWARD_ERROR <= 1e-12
