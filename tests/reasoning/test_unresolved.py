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
    # a relation held within the boxes' noise margin only is more than none seen
    assert best_unresolved(nodes, {2: "unknown", 4: "marginal"}, ["tv"]).id == 4
    assert best_unresolved(nodes, {1: "unknown", 2: "marginal"}, ["tv"]).id == 2
    assert best_unresolved(nodes, {2: "marginal", 3: "holds"}, ["tv"]).id == 3
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


def test_a_marginal_verdict_is_timed_from_when_it_began_without_a_break():
    from hiconav.reasoning.unresolved import track_marginal

    since = track_marginal({}, {1: "marginal", 2: "unknown"}, now=3.0)
    assert since == {1: 3.0}
    since = track_marginal(since, {1: "marginal", 2: "marginal"}, now=5.0)
    assert since == {1: 3.0, 2: 5.0}  # 1 keeps its start
    since = track_marginal(since, {1: "holds", 2: "marginal"}, now=6.0)
    assert since == {2: 5.0}  # a verdict that changed starts over if it comes back
    assert track_marginal(since, {1: "marginal", 2: "marginal"}, now=7.0) == {1: 7.0, 2: 5.0}


def test_a_marginal_candidate_is_due_once_its_patience_ran_out_and_not_offered_before():
    from hiconav.reasoning.unresolved import due_marginal

    since = {1: 3.0, 2: 8.0}
    assert due_marginal(since, now=12.9, patience_s=10.0) == {}
    assert due_marginal(since, now=13.0, patience_s=10.0) == {1: "marginal"}
    assert due_marginal(since, now=20.0, patience_s=10.0, exclude={1}) == {2: "marginal"}
    assert due_marginal(since, now=1e6, patience_s=0.0) == {}  # 0: only when explored out
    nodes = [_node(1, "tv", 0.5, 4), _node(2, "tv", 0.9, 9), _node(3, "tv", 0.9, 30)]
    # offered among the due ones alone, by evidence: never a node that is not marginal
    assert best_unresolved(nodes, due_marginal(since, now=20.0, patience_s=10.0), ["tv"]).id == 2


def test_an_offer_whose_verdict_turns_to_fails_is_withdrawn_for_good():
    from hiconav.reasoning.unresolved import withdrawn_offers

    offered = {14: "marginal", 20: "fails", 31: None}
    assert withdrawn_offers(offered, {14: "fails", 20: "fails", 31: "fails"}) == {14, 31}
    assert withdrawn_offers(offered, {14: "marginal", 20: "fails"}) == set()  # the last resort stays
