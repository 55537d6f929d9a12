"""The fast paths of the exploration cost give exactly the numbers of their plain numpy definitions."""

from __future__ import annotations

import numpy as np
import pytest

from hiconav.exploration.cost import _coarsen


@pytest.mark.parametrize("stride", [1, 2, 3, 4])
def test_coarsen_equals_the_blockwise_any(stride):
    rng = np.random.default_rng(stride)
    for shape in [(1, 1), (7, 5), (40, 61), (101, 100)]:
        mask = rng.random(shape) < 0.2
        H, W = shape
        Hc, Wc = -(-H // stride), -(-W // stride)
        pad = np.zeros((Hc * stride, Wc * stride), dtype=bool)
        pad[:H, :W] = mask
        expected = pad.reshape(Hc, stride, Wc, stride).any(axis=(1, 3))
        got = _coarsen(mask, stride)
        assert got.shape == expected.shape and np.array_equal(got, expected)


def test_a_one_cell_passage_stays_open_and_a_robot_radius_band_does_not_leak():
    from types import SimpleNamespace

    from hiconav.exploration.cost import geodesic_distances

    res = 0.05
    state = np.zeros((40, 80), dtype=np.int8)
    lethal = np.zeros((40, 80), dtype=bool)
    lethal[:, 38:45] = True  # a wall's robot-radius band, 7 cells thick
    grid = SimpleNamespace(state=state, inflated=lethal, lethal=lethal, origin=np.zeros(2), resolution=res,
                           world_to_cell=lambda xy: np.floor(np.asarray(xy)[..., ::-1] / res).astype(np.int64))
    pts = np.array([[0.5, 1.0], [3.5, 1.0]])
    assert np.isinf(geodesic_distances(grid, pts)[0, 1])
    lethal2 = lethal.copy()
    lethal2[20, 38:45] = False  # a passage one cell wide (a tight doorway)
    grid.lethal = lethal2
    d = geodesic_distances(grid, pts)[0, 1]
    assert 3.0 <= d < 4.5
