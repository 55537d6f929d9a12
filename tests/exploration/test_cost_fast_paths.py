"""The fast paths of the exploration cost give exactly the numbers of their plain numpy definitions."""

from __future__ import annotations

import numpy as np
import pytest

from hiconav.exploration.cost import _coarsen


@pytest.mark.parametrize("stride", [1, 2, 3, 4])
def test_coarsen_equals_the_blockwise_all(stride):
    rng = np.random.default_rng(stride)
    for shape in [(1, 1), (7, 5), (40, 61), (101, 100)]:
        mask = rng.random(shape) < 0.8
        H, W = shape
        Hc, Wc = -(-H // stride), -(-W // stride)
        pad = np.zeros((Hc * stride, Wc * stride), dtype=bool)
        pad[:H, :W] = mask
        expected = pad.reshape(Hc, stride, Wc, stride).all(axis=(1, 3))
        got = _coarsen(mask, stride)
        assert got.shape == expected.shape and np.array_equal(got, expected)
