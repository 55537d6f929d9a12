"""Subgraph decomposition (eqs. 8-11) on hand-made snapshots: order, sizes, signatures."""

from __future__ import annotations

import numpy as np
import pytest

from hiconav.memory import AnchorView, MemorySnapshot, ObjectView, decompose
from hiconav.types import CameraIntrinsics, Pose2D, TaskSpec

INTR = CameraIntrinsics.from_hfov(160, 120, 79.0)
SIM = {("bed", "bed"): 1.0, ("nightstand", "bed"): 0.6, ("lamp", "bed"): 0.3, ("sofa", "bed"): 0.4,
       ("toilet", "bed"): 0.05, ("sink", "bed"): 0.1, ("chair", "bed"): 0.2, ("fridge", "bed"): 0.0}


def similarity(a: str, b: str) -> float:
    a, b = a.replace(" ", "_"), b.replace(" ", "_")
    if a == b:
        return 1.0
    if b.startswith("find"):  # the instruction: score by the target word "bed"
        b = "bed"
    return SIM.get((a, b), SIM.get((b, a), 0.0))


def obj(i: int, label: str, anchors: tuple[int, ...], conf: float = 0.9) -> ObjectView:
    c = np.array([i, 0.0, 0.5])
    return ObjectView(i, label, conf, c, c - 0.2, c + 0.2, len(anchors), np.ones(4, np.float32) / 2,
                      anchors)


def anchor(i: int, objects: dict[int, tuple[float, float, float, float]],
           labels_seen: tuple[str, ...] | None = None, objs: dict[int, ObjectView] | None = None
           ) -> AnchorView:
    ids = tuple(sorted(objects))
    boxes = np.array([objects[k] for k in ids], np.float32).reshape(-1, 4)
    seen = labels_seen if labels_seen is not None else tuple(objs[k].label for k in ids) if objs else ()
    return AnchorView(i, Pose2D(float(i), 0.0, 0.0), np.eye(4), INTR, float(i),
                      np.zeros((120, 160, 3), np.uint8), ids, boxes, seen)


def snapshot_from(edges: dict[int, dict[int, tuple]], labels: dict[int, str],
                  labels_seen: dict[int, tuple[str, ...]] | None = None) -> MemorySnapshot:
    observers: dict[int, list[int]] = {o: [] for o in labels}
    for a, objs in edges.items():
        for o in objs:
            observers[o].append(a)
    objects = {o: obj(o, lab, tuple(sorted(observers[o]))) for o, lab in labels.items()}
    anchors = [anchor(a, objs, (labels_seen or {}).get(a), objects) for a, objs in sorted(edges.items())]
    return MemorySnapshot(1, 0.0, tuple(objects[o] for o in sorted(objects)), tuple(anchors))


BOX = (0.1, 0.1, 0.3, 0.3)
BIG = (0.0, 0.0, 0.9, 0.9)
LABELS = {0: "bed", 1: "nightstand", 2: "lamp", 3: "toilet", 4: "sink", 5: "sofa", 6: "chair",
          7: "fridge"}
EDGES = {
    0: {0: BOX, 1: BOX},  # bed + nightstand
    1: {0: BIG},  # bed, large view
    2: {1: BOX, 2: BOX},  # nightstand + lamp (related)
    3: {3: BOX, 4: BOX},  # bathroom
    4: {5: BOX, 6: BOX},  # living room
    5: {7: BOX},  # kitchen
    6: {},  # empty view, a bed seen far away
}
TASK = TaskSpec("find the bed", ("bed",), ("nightstand",))


def test_order_target_then_related_then_remaining_by_score():
    snap = snapshot_from(EDGES, LABELS, {6: ("bed",)})
    sgs = decompose(snap, TASK, similarity, k=5, label_match_threshold=1.0, far_evidence_weight=0.0)
    kinds = [g.kind for g in sgs]
    assert kinds[0] == "target" and sgs[0].focus_object_id == 0
    assert sgs[0].anchor_ids == (0, 1)  # eq. (10): every anchor observing the bed
    assert sgs[0].object_ids == (0, 1)  # eq. (9): all objects of those anchors
    assert kinds[1] == "related" and sgs[1].focus_object_id == 1
    assert sgs[1].anchor_ids == (0, 2)  # eq. (10) for the related object: all its observers
    rest = sgs[2:]
    assert all(g.kind == "remaining" for g in rest)
    assert [g.priority for g in rest] == sorted((g.priority for g in rest), reverse=True)
    # every anchor appears somewhere; remaining subgraphs never repeat an anchor
    assert {a for g in sgs for a in g.anchor_ids} == set(EDGES)
    assert sorted(a for g in rest for a in g.anchor_ids) == [3, 4, 5, 6]


def test_remaining_priority_is_sum_of_object_task_similarity():
    snap = snapshot_from(EDGES, LABELS)
    sgs = decompose(snap, TaskSpec("find the bed", ("bed",)), similarity, k=1,
                    label_match_threshold=1.0, far_evidence_weight=0.0)
    rest = {g.anchor_ids: g for g in sgs if g.kind == "remaining"}
    # eq. (11): S = sum_i s(o_i, T); living room: sofa 0.4 + chair 0.2
    assert rest[(4,)].priority == pytest.approx(0.6)
    assert rest[(3,)].priority == pytest.approx(0.15)  # toilet 0.05 + sink 0.1
    order = [g.anchor_ids for g in sgs if g.kind == "remaining"]
    assert order.index((2,)) < order.index((4,)) < order.index((3,)) < order.index((5,))
    assert [g.kind for g in sgs[:1]] == ["target"] and sgs[0].anchor_ids == (1,)  # k = 1: the largest view


def test_far_evidence_raises_priority_of_an_anchor_that_saw_the_target_far_away():
    snap = snapshot_from(EDGES, LABELS, {6: ("bed",)})
    task = TaskSpec("find the bed", ("sofa",))
    plain = decompose(snap, task, similarity, k=1, label_match_threshold=1.0, far_evidence_weight=0.0)
    boosted = decompose(snap, task, similarity, k=1, label_match_threshold=1.0, far_evidence_weight=0.5)
    p = {g.anchor_ids: g.priority for g in plain}
    q = {g.anchor_ids: g.priority for g in boosted}
    assert p[(6,)] == 0.0 and q[(6,)] == pytest.approx(0.5)


def test_subgraphs_hold_at_most_k_anchors():
    edges = {a: {0: (0.0, 0.0, 0.1 * (a + 1), 0.1 * (a + 1))} for a in range(8)}
    edges.update({10 + a: {1 + a: BOX} for a in range(7)})
    labels = {0: "bed", **{1 + a: "chair" for a in range(7)}}
    snap = snapshot_from(edges, labels)
    sgs = decompose(snap, TASK, similarity, k=3, label_match_threshold=1.0)
    assert all(1 <= len(g.anchors) <= 3 for g in sgs)
    assert sgs[0].kind == "target" and sgs[0].anchor_ids == (5, 6, 7)  # largest views of the bed
    assert sorted(a for g in sgs for a in g.anchor_ids) == sorted(edges)


def test_signature_changes_iff_content_changes():
    snap = snapshot_from(EDGES, LABELS)
    again = snapshot_from(EDGES, LABELS)
    a = decompose(snap, TASK, similarity)
    b = decompose(again, TASK, similarity)
    assert [g.signature for g in a] == [g.signature for g in b]
    edges = {k: dict(v) for k, v in EDGES.items()}
    edges[1][2] = BOX  # the bed's large view now also observes the lamp
    c = decompose(snapshot_from(edges, LABELS), TASK, similarity)
    assert c[0].signature != a[0].signature
    assert {g.signature for g in c[1:]} & {g.signature for g in a[1:]}  # others unchanged


def test_label_match_by_similarity_threshold():
    snap = snapshot_from({0: {0: BOX}}, {0: "nightstand"})
    strict = decompose(snap, TaskSpec("find the bed", ("bed",)), similarity, label_match_threshold=1.0)
    loose = decompose(snap, TaskSpec("find the bed", ("bed",)), similarity, label_match_threshold=0.5)
    assert strict[0].kind == "remaining" and loose[0].kind == "target"


def test_a_described_target_subgraph_carries_the_nodes_mapped_near_it():
    """ "the bed near the lamp": the lamp (1.6 m from the bed's box) is in no anchor of the bed's
    subgraph, but on the map beside it; the toilet 2.6 m off is not carried (context_m 2.5)."""
    snap = snapshot_from(EDGES, LABELS)
    described = TaskSpec("the bed near the lamp", ("bed",), ("lamp",), relations=(("bed", "near", "lamp"),))
    target = decompose(snap, described, similarity, k=5)[0]
    assert target.kind == "target" and target.focus_object_id == 0
    assert 2 not in target.object_ids and [o.id for o in target.context] == [2]
    assert target.signature[-1] == ((2, "lamp"),)  # a node mapped nearby makes the subgraph due again
    plain = decompose(snap, TASK, similarity, k=5)[0]
    assert plain.context == () and plain.signature == target.signature[:-1]
    assert decompose(snap, described, similarity, k=5, context_m=0.0)[0].context == ()


def test_every_instance_a_subgraph_shows_carries_the_nodes_mapped_near_it():
    """ "the bed near the lamp", a second bed (node 8, at x = 8 m) also seen at the edge of the
    view that centres the fridge (node 7): it is judged on that subgraph too, so the sink beside it (node
    9, 1.6 m off, in no anchor of that subgraph) comes with it."""
    labels = {**LABELS, 8: "bed", 9: "sink"}
    edges = {k: dict(v) for k, v in EDGES.items()}
    edges[7] = {7: BIG, 8: BOX}  # the fridge's view shows the second bed at its edge
    edges[8] = {9: BOX}  # the sink, from elsewhere
    edges[11] = {8: BIG}  # the second bed's own best view, its target subgraph (k = 1)
    described = TaskSpec("the bed near the lamp", ("bed",), ("fridge",), relations=(("bed", "near", "lamp"),))
    subgraphs = decompose(snapshot_from(edges, labels), described, similarity, k=1)
    shown = {g.focus_object_id: g for g in subgraphs if g.kind == "related"}
    fridge = shown[7]
    assert 8 in fridge.object_ids and 9 not in fridge.object_ids
    assert 9 in [o.id for o in fridge.context]  # mapped 1.6 m from the bed it shows
    assert fridge.signature[-1] == tuple((o.id, o.label) for o in fridge.context)
    # the focus's neighbours come first in a target subgraph
    first = next(g for g in subgraphs if g.kind == "target" and g.focus_object_id == 0)
    assert [o.id for o in first.context][:2] == [1, 2]  # the nightstand and lamp beside bed 0
    # without a description no subgraph carries anything
    plain = decompose(snapshot_from(edges, labels), TaskSpec("find the bed", ("bed",), ("fridge",)), similarity, k=1)
    assert all(g.context == () for g in plain)
