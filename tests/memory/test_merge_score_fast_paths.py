"""box_iou_many / merge_scores (eq. 4) give bit-identical numbers to their np.clip / np.prod definitions."""

from __future__ import annotations

import numpy as np
import pytest

from hiconav.memory.config import MemoryConfig
from hiconav.memory.objects import box_iou_many, merge_scores


def _reference_iou(bmin, bmax, mins, maxs, pad, mode):
    a0, a1 = bmin - pad, bmax + pad
    b0, b1 = mins - pad, maxs + pad
    inter = np.prod(np.clip(np.minimum(a1, b1) - np.maximum(a0, b0), 0.0, None), axis=1)
    va = float(np.prod(np.clip(a1 - a0, 0.0, None)))
    vb = np.prod(np.clip(b1 - b0, 0.0, None), axis=1)
    den = np.minimum(va, vb) if mode == "overlap" else va + vb - inter
    return np.where(den > 0, inter / np.maximum(den, 1e-12), 0.0)


@pytest.mark.parametrize("mode", ["iou", "overlap"])
def test_box_iou_many_is_bit_identical_to_the_reference(mode):
    rng = np.random.default_rng(0)
    for trial in range(300):
        k = int(rng.integers(1, 60))
        mins = rng.normal(size=(k, 3)) * rng.choice([0.01, 1.0, 10.0])
        maxs = mins + np.abs(rng.normal(size=(k, 3))) * rng.choice([0.001, 0.5, 3.0])
        if trial % 5 == 0:
            maxs[0] = mins[0] - 0.1  # an inverted (empty) box
        bmin = rng.normal(size=3)
        bmax = bmin + np.abs(rng.normal(size=3))
        pad = float(rng.choice([0.0, 0.05, 0.1]))
        got = box_iou_many(bmin, bmax, mins, maxs, pad, mode)
        assert np.array_equal(got, _reference_iou(bmin, bmax, mins, maxs, pad, mode))


def test_merge_scores_semantic_term_is_the_clipped_cosine():
    rng = np.random.default_rng(1)
    cfg = MemoryConfig()
    k = 20
    feats = rng.normal(size=(k, 16)).astype(np.float32)
    feats /= np.linalg.norm(feats, axis=1, keepdims=True)
    mins = rng.normal(size=(k, 3))
    maxs = mins + 1.0
    bmin, bmax = mins[3], maxs[3]
    s = merge_scores(bmin, bmax, feats[3], None, mins, maxs, feats, [None] * k, cfg)
    expected = (cfg.lambda_1 * _reference_iou(bmin, bmax, mins, maxs, cfg.box_padding, cfg.geometric)
                + cfg.lambda_2 * np.clip(feats @ feats[3], 0.0, 1.0))
    assert np.array_equal(s, expected)
