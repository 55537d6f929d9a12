"""A node's geometry is its majority label's cloud (``MemoryConfig.node_geometry``): a one-frame
spurious box of another label that eq. (4) merged does not stretch the node's box."""

from __future__ import annotations

import numpy as np

from hiconav.memory.config import MemoryConfig
from hiconav.memory.objects import ObjectNode, ObjectObservation


def _slab(lo, hi, n=400, seed=0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(lo, hi, size=(n, 3)).astype(np.float32)


def _obs(label: str, lo, hi, seed=0, score=0.8) -> ObjectObservation:
    pts = _slab(lo, hi, seed=seed)
    f = np.zeros(8, np.float32)
    f[sum(map(ord, label)) % 8] = 1.0  # a fixed one-hot per label (str hash varies by process)
    return ObjectObservation(label, score, pts, pts.min(0).astype(np.float64), pts.max(0).astype(np.float64),
                             f, None, np.zeros(4, np.float32), 2.0)


PLANT = ([-5.30, 1.62, 0.0], [-5.11, 1.78, 0.9])  # 0.19 x 0.16 m
SPURIOUS = ([-5.95, 1.40, 0.0], [-4.97, 2.67, 1.2])  # a 1 x 1.3 m chunk around it


def _box_xy(node):
    return np.round(np.r_[node.box_min[:2], node.box_max[:2]], 2)


def test_a_spurious_box_that_founded_the_node_goes_once_the_plant_outvotes_it():
    cfg = MemoryConfig()
    node = ObjectNode.from_observation(0, _obs("chair", *SPURIOUS), 0.0, cfg)
    assert node.label == "chair" and node.box_max[1] > 2.5
    for k in range(4):
        node.absorb(_obs("plant", *PLANT, seed=k + 1), float(k + 1), cfg)
    assert node.label == "plant" and node.n_obs == 5
    lo, hi = np.array(PLANT[0]), np.array(PLANT[1])
    assert np.all(node.box_min[:2] >= lo[:2] - 0.03) and np.all(node.box_max[:2] <= hi[:2] + 0.03)
    assert node.view().points.shape[0] == node.label_points["plant"].shape[0]
    # eq. (3)'s union of every observation's cloud keeps the spurious extent
    old = MemoryConfig(node_geometry="all")
    union = ObjectNode.from_observation(0, _obs("chair", *SPURIOUS), 0.0, old)
    for k in range(4):
        union.absorb(_obs("plant", *PLANT, seed=k + 1), float(k + 1), old)
    assert union.label == "plant" and union.box_max[1] > 2.5 and not union.label_points


def test_a_spurious_box_absorbed_later_does_not_stretch_the_node():
    cfg = MemoryConfig()
    node = ObjectNode.from_observation(0, _obs("plant", *PLANT), 0.0, cfg)
    node.absorb(_obs("plant", *PLANT, seed=1), 1.0, cfg)
    before = _box_xy(node)
    node.absorb(_obs("bottle", *SPURIOUS, seed=2), 2.0, cfg)
    assert node.label == "plant" and np.array_equal(_box_xy(node), before)


def test_node_merge_keeps_each_labels_cloud_and_the_majority_decides():
    cfg = MemoryConfig()
    a = ObjectNode.from_observation(0, _obs("sofa", [0, 0, 0], [2.0, 0.9, 0.8]), 0.0, cfg)
    a.absorb(_obs("sofa", [0, 0, 0], [2.0, 0.9, 0.8], seed=1), 1.0, cfg)
    b = ObjectNode.from_observation(1, _obs("chair", [0.0, 0.0, 0.0], [0.6, 0.9, 0.8], seed=2), 2.0, cfg)
    a.absorb_node(b, cfg)
    assert a.label == "sofa" and set(a.label_points) == {"sofa", "chair"}
    assert a.box_max[0] > 1.9  # the sofa's cloud
    # votes turn: three more chair views make it a chair, and the chair's cloud its geometry
    for k in range(3):
        a.absorb(_obs("chair", [0.0, 0.0, 0.0], [0.6, 0.9, 0.8], seed=3 + k), 3.0 + k, cfg)
    assert a.label == "chair" and a.box_max[0] < 0.65


def test_node_merge_whose_majority_is_a_label_the_node_lacked():
    """The absorbed node's label outvotes the keeper's: its cloud becomes the geometry."""
    cfg = MemoryConfig()
    keep = ObjectNode.from_observation(0, _obs("sofa", [0, 0, 0], [2.0, 0.9, 0.8], score=0.5), 0.0, cfg)
    # founded by a one-frame table box, then seen twice as an armchair: its clouds come table first
    drop = ObjectNode.from_observation(1, _obs("table", [0, 0, 0], [0.5, 0.5, 0.5], seed=3, score=0.3), 1.0, cfg)
    drop.absorb(_obs("armchair", [0, 0, 0], [0.8, 0.8, 0.8], seed=1), 2.0, cfg)
    drop.absorb(_obs("armchair", [0, 0, 0], [0.8, 0.8, 0.8], seed=2), 3.0, cfg)
    keep.absorb_node(drop, cfg)
    assert keep.label == "armchair" and keep.box_max[0] < 0.85
    assert set(keep.label_points) == {"sofa", "armchair", "table"}
