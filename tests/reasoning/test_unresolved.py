"""The best unresolved candidate of a described instance once the search explored out."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from hiconav.reasoning.unresolved import best_unresolved, unresolved_hypothesis


def _node(i: int, label: str, confidence: float = 0.5, n_obs: int = 4):
    return SimpleNamespace(id=i, label=label, confidence=confidence, n_obs=n_obs)


def _anchor(i: int, ids: tuple[int, ...], boxes: list[list[float]]):
    return SimpleNamespace(id=i, object_ids=ids, boxes=np.asarray(boxes, dtype=float))


def test_holds_before_unknown_before_fails_then_evidence_then_id():
    nodes = [_node(1, "tv", 0.9, 20), _node(2, "tv", 0.4, 3), _node(3, "tv", 0.3, 2), _node(4, "tv", 0.6, 5)]
    assert best_unresolved(nodes, {1: "fails", 2: "unknown", 3: "holds"}, ["tv"]).id == 3
    assert best_unresolved(nodes, {1: "fails", 2: "unknown", 4: "unknown"}, ["tv"]).id == 4  # 0.6x5 > 0.4x3
    assert best_unresolved(nodes, {1: "fails"}, ["tv"]).id == 1  # a ruled-out one is the last resort
    same = [_node(7, "tv", 0.5, 4), _node(6, "tv", 0.5, 4)]
    assert best_unresolved(same, {6: "unknown", 7: "unknown"}, ["tv"]).id == 6


def test_only_judged_nodes_of_the_target_not_excluded_are_offered():
    nodes = [_node(1, "sofa"), _node(2, "tv"), _node(3, "TV")]
    verdicts = {1: "unknown", 2: "unknown", 3: "fails"}
    assert best_unresolved(nodes, verdicts, ["tv"]).id == 2  # a sofa is never the TV
    assert best_unresolved(nodes, verdicts, ["tv"], exclude={2}).id == 3  # labels compare normalised
    assert best_unresolved(nodes, verdicts, ["tv"], exclude={2, 3}) is None
    assert best_unresolved([_node(5, "tv")], {}, ["tv"]) is None  # never judged: nothing to say of it
    assert best_unresolved([_node(5, "tv")], {5: "maybe"}, ["tv"]) is None


def test_the_hypothesis_uses_the_largest_view_and_says_it_is_a_fallback():
    memory = SimpleNamespace(objects=[_node(2, "tv", 0.37, 4)],
                             anchors=[_anchor(10, (2,), [[0.1, 0.1, 0.2, 0.2]]),
                                      _anchor(11, (5, 2), [[0, 0, 1, 1], [0.2, 0.2, 0.6, 0.7]])])
    hyp = unresolved_hypothesis(memory, {2: "unknown"}, ["tv"])
    assert hyp.object_id == 2 and hyp.anchor_id == 11 and np.allclose(hyp.bbox, [0.2, 0.2, 0.6, 0.7])
    assert hyp.source == "offline" and "fallback" in hyp.evidence and "relations unknown" in hyp.evidence
    assert hyp.confidence == 0.37 and hyp.label == "tv"
    # no anchor holds a box of it: no hypothesis
    assert unresolved_hypothesis(SimpleNamespace(objects=memory.objects, anchors=[]), {2: "unknown"}, ["tv"]) is None
