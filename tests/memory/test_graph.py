"""The cognitive memory graph: anchor gate (eq. 2), object merging (eq. 4), pruning (eqs. 5-7),
and immutable snapshots, on exact synthetic RGB-D views of boxes (tests/memory/synth.py)."""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from hiconav.memory import AnchorGate, CognitiveMemoryGraph, MemoryConfig
from hiconav.perception import HashingEmbedder
from hiconav.types import Pose2D

sys.path.insert(0, str(Path(__file__).parent))
from synth import Box, chair, detect, look_at, render


@pytest.fixture(scope="module")
def embedder():
    return HashingEmbedder()  # labelled fallback embedder: fast, and same label -> similarity 1


def graph(embedder, **kw) -> CognitiveMemoryGraph:
    return CognitiveMemoryGraph(MemoryConfig(**kw), embedder=embedder)


def observe(g: CognitiveMemoryGraph, pose: Pose2D, boxes: list[Box], stamp: float = 0.0):
    frame = render(pose, boxes, stamp=stamp)
    return g.update(frame, detect(frame, boxes))


# ------------------------------------------------------------------ anchor gate, eq. (2)
def test_gate_first_frame_is_an_anchor():
    assert AnchorGate().decide(Pose2D(0, 0, 0), False).reason == "first"


@pytest.mark.parametrize("pose, expected", [
    (Pose2D(0.9, 0.0, 0.0), ""),  # 0.9 m < delta_d
    (Pose2D(1.1, 0.0, 0.0), "translation"),
    (Pose2D(0.0, 0.0, math.radians(40)), ""),  # 40 deg < delta_theta
    (Pose2D(0.0, 0.0, math.radians(50)), "rotation"),
    (Pose2D(0.0, 0.0, math.radians(-50)), "rotation"),
])
def test_gate_translation_and_rotation_thresholds(pose, expected):
    gate = AnchorGate(delta_d=1.0, delta_theta_deg=45.0)
    gate.accept(Pose2D(0.0, 0.0, 0.0))
    d = gate.decide(pose, new_object=False)
    assert d.reason == expected and d.is_anchor == bool(expected)


def test_gate_new_object_and_reference_is_last_selected_anchor():
    gate = AnchorGate()
    gate.accept(Pose2D(0.0, 0.0, 0.0))
    assert gate.decide(Pose2D(0.1, 0.0, 0.0), new_object=True).reason == "new_object"
    # yaw wraps: 350 deg vs 0 deg is a 10 deg turn
    assert not gate.decide(Pose2D(0.0, 0.0, math.radians(350)), False).is_anchor
    # three 0.4 m steps without selection still add up against the last *selected* anchor
    assert not gate.decide(Pose2D(0.8, 0.0, 0.0), False).is_anchor
    assert gate.decide(Pose2D(1.2, 0.0, 0.0), False).reason == "translation"


def test_gate_makes_a_requested_frame_an_anchor_after_the_reasons_of_eq_2():
    gate = AnchorGate()
    gate.accept(Pose2D(0.0, 0.0, 0.0))
    glance = Pose2D(0.0, 0.0, math.radians(30))  # a glance from one spot: no reason of eq. 2
    assert not gate.decide(glance, False).is_anchor
    assert gate.decide(glance, False, requested=True).reason == "requested"
    assert gate.decide(Pose2D(0.0, 0.0, math.radians(50)), False, requested=True).reason == "rotation"


def test_keyframe_schedule_spaces_the_frames_asked_for_and_ends_with_the_request():
    from hiconav.memory import KeyframeSchedule

    ks = KeyframeSchedule()
    assert not ks.due(0.0)  # nothing asked yet
    ks.request(until=2.0, every_s=1.0)
    assert [ks.due(t) for t in (0.5, 1.0, 1.5, 2.0, 2.5)] == [True, False, True, False, False]
    ks.request(until=4.0, every_s=0.0)  # the newest request replaces the last
    assert ks.due(3.0) and ks.due(3.0) and not ks.due(4.5)


def test_graph_makes_a_requested_frame_an_anchor_that_records_what_it_saw(embedder):
    """Verification judges anchors: a robot glancing at a chair from one spot makes none by eq. 2,
    so each frame it judges is asked for (``KeyframeRequest``); a frame that misses the chair is an
    anchor too, and says so (its object ids do not include the chair's node)."""
    g = graph(embedder)
    boxes = [chair(3.0, 0.0)]
    observe(g, Pose2D(0, 0, 0), boxes)
    pose = Pose2D(0.0, 0.0, math.radians(25))
    assert observe(g, pose, boxes, stamp=1).reason == ""
    frame = render(pose, boxes, stamp=2)
    seen = g.update(frame, detect(frame, boxes), keyframe=True)
    missed = g.update(render(pose, boxes, stamp=3), [], keyframe=True)
    assert seen.reason == missed.reason == "requested"
    anchors = {a.id: a for a in g.snapshot().anchors}
    assert anchors[seen.anchor_id].object_ids and not anchors[missed.anchor_id].object_ids
    # and what it read each node as, row by row with object_ids (verification reads it)
    assert anchors[seen.anchor_id].object_labels == (("chair",),) and anchors[missed.anchor_id].object_labels == ()


def test_graph_gate_skips_frames_without_news(embedder):
    g = graph(embedder)
    boxes = [chair(3.0, 0.0)]
    assert observe(g, Pose2D(0, 0, 0), boxes).reason == "first"
    u = observe(g, Pose2D(0.3, 0, 0), boxes, stamp=1)  # same chair, small move
    assert not u.is_anchor and g.n_anchors == 1
    assert g.snapshot().object(0).n_obs == 1  # non-anchor frames leave nodes alone (paper)
    boxes2 = boxes + [Box("plant", (2.5, 1.0, 0.4), (0.3, 0.3, 0.8))]
    u = observe(g, Pose2D(0.4, 0, 0), boxes2, stamp=2)
    assert u.reason == "new_object" and len(u.new_object_ids) == 1


# ------------------------------------------------------------------ merging, eq. (4)
def test_two_views_of_one_chair_merge_into_one_node(embedder):
    g = graph(embedder)
    boxes = [chair(3.0, 0.0)]
    observe(g, look_at(0.0, 0.0, 3.0, 0.0), boxes, 0.0)
    u = observe(g, look_at(2.0, -1.6, 3.0, 0.0), boxes, 1.0)  # 1.9 m away, about 60 deg around
    assert u.is_anchor and u.updated_object_ids == (0,) and u.new_object_ids == ()
    snap = g.snapshot()
    assert len(snap.objects) == 1
    o = snap.objects[0]
    assert o.label == "chair" and o.n_obs == 2 and o.anchor_ids == (0, 1)
    # the merged cloud sees two faces: the box grows towards the true 0.5 x 0.5 footprint
    assert np.all(o.box_min[:2] <= [2.76, -0.24]) and np.all(o.box_max[:2] >= [3.2, 0.24])
    assert all(0 in snap.anchor(a).object_ids for a in o.anchor_ids)


def test_two_chairs_side_by_side_stay_two_nodes(embedder):
    g = graph(embedder)
    boxes = [chair(3.0, -0.35), chair(3.0, 0.35)]  # 0.2 m gap
    observe(g, look_at(0.0, 0.0, 3.0, 0.0), boxes, 0.0)
    observe(g, look_at(1.5, -1.5, 3.0, 0.0), boxes, 1.0)
    observe(g, look_at(1.5, 1.5, 3.0, 0.0), boxes, 2.0)
    snap = g.snapshot()
    chairs = snap.objects_with_label("chair")
    assert len(chairs) == 2
    ys = sorted(float(o.center[1]) for o in chairs)
    assert ys[0] < -0.1 and ys[1] > 0.1
    assert {o.gt_instance for o in chairs} == {0, 1}


def test_different_labels_on_distinct_objects_do_not_merge(embedder):
    g = graph(embedder)
    boxes = [chair(3.0, 0.0), Box("sofa", (3.3, 1.4, 0.4), (0.9, 1.8, 0.8))]
    observe(g, look_at(0.0, 0.5, 3.0, 0.5), boxes)
    assert sorted(o.label for o in g.snapshot().objects) == ["chair", "sofa"]


def test_detection_beyond_max_depth_is_only_a_label_seen(embedder):
    g = graph(embedder)
    boxes = [chair(2.5, 0.0), Box("bed", (8.0, 0.0, 0.3), (2.0, 1.6, 0.6))]  # bed 7 m away
    u = observe(g, Pose2D(0, 0, 0), boxes)
    snap = g.snapshot()
    assert [o.label for o in snap.objects] == ["chair"] and u.n_far == 1
    a = snap.anchors[0]
    assert set(a.labels_seen) == {"chair", "bed"}
    assert a.object_ids == (0,) and a.boxes.shape == (1, 4)
    assert np.all((a.boxes >= 0) & (a.boxes <= 1)) and a.boxes[0, 0] < a.boxes[0, 2]
    assert a.image.shape == (120, 160, 3) and a.image.dtype == np.uint8


def _partial(det, frac_lo: float, frac_hi: float):
    """The detection restricted to a band of its mask's columns (a detector seeing a part)."""
    from hiconav.types import Detection

    mask = np.array(det.mask)
    cols = np.nonzero(mask.any(axis=0))[0]
    lo = int(cols[0] + frac_lo * (cols[-1] - cols[0]))
    hi = int(cols[0] + frac_hi * (cols[-1] - cols[0]))
    mask[:, :lo] = False
    mask[:, hi + 1:] = False
    rows, cs = np.nonzero(mask)
    box = np.array([cs.min(), rows.min(), cs.max(), rows.max()], np.float32)
    return Detection(det.label, det.score, box, mask, None, det.source, det.instance_id)


def test_node_node_merge_when_views_come_to_overlap(embedder):
    # A long sofa first detected as two disjoint pieces (two nodes); a later whole view grows one
    # piece's node until it overlaps the other, and the two nodes merge (eq. 4 between nodes).
    g = graph(embedder)
    sofa = [Box("sofa", (3.0, 0.0, 0.4), (0.9, 2.6, 0.8))]
    f = render(Pose2D(0.0, 0.0, 0.0), sofa)
    g.update(f, [_partial(detect(f, sofa)[0], 0.0, 0.25)])
    f = render(Pose2D(0.0, 0.0, 0.0), sofa, stamp=1.0)
    u = g.update(f, [_partial(detect(f, sofa)[0], 0.75, 1.0)])
    assert u.reason == "new_object" and len(g.snapshot().objects) == 2
    f = render(Pose2D(-1.2, 0.0, 0.0), sofa, stamp=2.0)
    u = g.update(f, detect(f, sofa))
    assert u.is_anchor and u.merged == ((0, 1),)
    snap = g.snapshot()
    assert len(snap.objects) == 1 and snap.objects[0].anchor_ids == (0, 1, 2)
    assert snap.objects[0].n_obs == 3
    assert all(snap.anchor(a).object_ids == (0,) for a in (0, 1, 2))  # edges rewired
    assert all(snap.anchor(a).object_labels == (("sofa",),) for a in (0, 1, 2))  # with what was read
    assert float(snap.objects[0].size[1]) > 2.3


def test_merge_disabled_keeps_pieces_apart(embedder):
    g = graph(embedder, merge_nodes=False)
    sofa = [Box("sofa", (3.0, 0.0, 0.4), (0.9, 2.6, 0.8))]
    f = render(Pose2D(0.0, 0.0, 0.0), sofa)
    g.update(f, [_partial(detect(f, sofa)[0], 0.0, 0.25)])
    g.update(render(Pose2D(0.0, 0.0, 0.0), sofa, stamp=1.0),
             [_partial(detect(f, sofa)[0], 0.75, 1.0)])
    f = render(Pose2D(-1.2, 0.0, 0.0), sofa, stamp=2.0)
    g.update(f, detect(f, sofa))
    assert len(g.snapshot().objects) == 2


# ------------------------------------------------------------------ pruning, eqs. (5)-(7)
def test_prune_keeps_min_r_deg_observers_and_drops_edges(embedder):
    g = graph(embedder, r=2, keep_latest_anchor=False)
    boxes = [chair(3.0, 0.0)]
    for i, yaw_deg in enumerate(range(0, 360, 60)):  # orbit: 6 anchors (rotation gate)
        yaw = math.radians(yaw_deg)
        x, y = 3.0 - 2.2 * math.cos(yaw), -2.2 * math.sin(yaw)
        observe(g, look_at(x, y, 3.0, 0.0), boxes, float(i))
    snap = g.snapshot()
    assert len(snap.objects) == 1 and len(snap.anchors) == 6
    res = g.prune()
    assert res.status in ("optimal", "trivial") and res.proven_optimal
    assert len(res.kept_anchor_ids) == 2 and len(res.removed_anchor_ids) == 4
    snap = g.snapshot()
    assert len(snap.anchors) == 2 and snap.objects[0].anchor_ids == res.kept_anchor_ids
    assert snap.n_edges == 2
    # which anchors ever observed the node outlives the pruned images (co-visibility for rooms)
    assert snap.objects[0].observed_by == tuple(range(6))


def test_prune_keeps_an_object_seen_once_and_far_evidence(embedder):
    g = graph(embedder, r=2, keep_latest_anchor=False)
    observe(g, Pose2D(0, 0, 0), [chair(3.0, 0.0)], 0.0)  # chair seen once (deg 1)
    observe(g, Pose2D(0, 0, math.pi), [Box("bed", (-9.0, 0.0, 0.3), (2.0, 1.6, 0.6))], 1.0)
    for i in range(3):  # empty views: nothing to keep them for
        observe(g, Pose2D(0, 0, math.pi / 2 + i * 0.9), [], 2.0 + i)
    res = g.prune()
    snap = g.snapshot()
    assert len(snap.objects) == 1 and len(snap.objects[0].anchor_ids) == 1
    assert any("bed" in a.labels_seen for a in snap.anchors)  # out-of-range evidence kept
    assert len(snap.anchors) == 2 and len(res.removed_anchor_ids) == 3


# ------------------------------------------------------------------ snapshots
def test_snapshot_cannot_be_mutated(embedder):
    g = graph(embedder)
    observe(g, Pose2D(0, 0, 0), [chair(3.0, 0.0)])
    snap = g.snapshot()
    o, a = snap.objects[0], snap.anchors[0]
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.label = "sofa"
    with pytest.raises(dataclasses.FrozenInstanceError):
        snap.objects = ()
    for arr in (o.center, o.box_min, o.box_max, o.feature, o.points, a.image, a.boxes, a.T_world_cam):
        with pytest.raises(ValueError):
            arr[...] = 0
    with pytest.raises(TypeError):
        snap._objects_by_id[99] = o  # look-up tables are read-only mappings too


def test_snapshot_is_stable_and_shares_unchanged_views(embedder):
    g = graph(embedder)
    boxes = [chair(3.0, 0.0), Box("plant", (2.0, 2.0, 0.4), (0.3, 0.3, 0.8))]
    observe(g, look_at(0, 0, 3.0, 0.0), boxes[:1])
    s1 = g.snapshot()
    old = s1.objects[0]
    old_min = old.box_min.copy()
    observe(g, look_at(0.2, 0.2, 2.0, 2.0), boxes[1:], 1.0)  # a new anchor sees only the plant
    s2 = g.snapshot()
    assert s2.version > s1.version
    assert s2.object(old.id) is old  # unchanged node: the very same view object and arrays
    assert s2.anchor(0) is s1.anchor(0)
    assert len(s1.objects) == 1 and len(s2.objects) == 2  # the old snapshot did not change
    observe(g, look_at(2.0, -1.6, 3.0, 0.0), boxes[:1], 2.0)  # chair seen again: new view
    s3 = g.snapshot()
    assert s3.object(old.id) is not old and s3.object(old.id).n_obs == 2
    assert np.array_equal(old.box_min, old_min) and old.n_obs == 1
    with pytest.raises(KeyError, match="object 42"):
        s3.object(42)


def test_cached_node_arrays_follow_absorbed_observations(embedder):
    """Absorbing updates the node's row of the cached match arrays in place; they must equal a
    fresh stack of every node after each frame (a stale row would mis-match later detections)."""
    g = graph(embedder, update_objects_every_frame=True)
    boxes = [chair(3.0, 0.0), chair(3.0, 1.5)]
    for k, (x, y) in enumerate([(0.0, 0.0), (0.3, 0.1), (0.6, -0.1), (1.0, 0.2), (2.0, -1.6)]):
        observe(g, look_at(x, y, 3.0, 0.5), boxes, float(k))
        ids, mins, maxs, feats, _ = g._node_arrays()
        assert ids == list(g.objects)
        np.testing.assert_array_equal(mins, np.stack([g.objects[i].box_min for i in ids]))
        np.testing.assert_array_equal(maxs, np.stack([g.objects[i].box_max for i in ids]))
        np.testing.assert_array_equal(feats, np.stack([g.objects[i].feature for i in ids]))
    assert any(g.objects[i].n_obs > 1 for i in g.objects)
