"""The body-by-body harmonic solve of designs together (workbook.design.blocks.channel_solve) on small mounts
whose whole matrices are solved directly."""
import numpy as np

from workbook.design.blocks import BACKWARD_ERROR, ChannelCoupling, channel_solve


class _Layout:
    """Two bodies of three coordinates each (w = b = 3), every coordinate independent."""

    coordinates = np.array([[0, 1, 2], [3, 4, 5]])

    def marker_rows(self, channels):
        return channels.blocks, channels.positions


class _Channels:
    """Channel 0 from body 0 to body 1, channel 1 from the ground to body 1: points 0, 1, (ground), 3."""

    count = 2
    blocks = np.array([0, 1, 0, 1])
    positions = np.array([[0, 1, 2], [0, 1, 2], [3, 3, 3], [0, 1, 2]])


def _problem(rng, gap):
    """Bodies, point Jacobians, impedances and loads of one design; body 0, on no channel to the ground, is
    ``gap`` from singular (the whole matrix, with channel 0's springs, is not)."""
    jacobian = rng.standard_normal((4, 3, 3))
    jacobian[2] = 0.0
    jacobian[0] *= -1.0
    impedance = np.array([np.eye(3) * (2.0 + 0.1j), np.diag([1.0, 2.0, 3.0]) * (1.0 + 0.05j)])
    dynamic = np.array([gap * np.eye(3), rng.standard_normal((3, 3)) + 5 * np.eye(3)], dtype=complex)
    loads = rng.standard_normal((2, 3)) + 1j * rng.standard_normal((2, 3))
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


def test_body_by_body_is_the_whole_solve_and_a_body_near_its_own_resonance_is_marked():
    rng = np.random.default_rng(2)
    coupling = ChannelCoupling.of(_Layout(), _Channels())
    assert list(coupling.moving) == [0, 1, 3] and len(coupling.coupled) == 2 and list(coupling.grounded) == [2]
    for gap, trusted in ((3.0, True), (1e-13, False)):
        dynamic, jacobian, impedance, loads = _problem(rng, gap)
        expected = _whole(dynamic, jacobian, impedance, loads)
        separation, trouble = channel_solve(coupling, dynamic[None], jacobian[None], impedance[None], loads[None])
        assert trouble[0] == (not trusted)
        if trusted:
            assert np.abs(separation[0] - expected).max() <= 1e-12 * np.abs(expected).max()
    assert BACKWARD_ERROR <= 1e-12
