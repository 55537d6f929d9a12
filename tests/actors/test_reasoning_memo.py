"""ReasoningNode reuses the last decomposition while the memory's views are the very same objects."""

from __future__ import annotations

from types import SimpleNamespace

from hiconav.actors.reasoning import ReasoningNode

from hiconav.messages import WorldSnapshot
from hiconav.types import Pose2D


class _Reasoner:
    done = False

    def __init__(self) -> None:
        self.updates: list[list] = []

    def update(self, subgraphs: list) -> None:
        self.updates.append(list(subgraphs))

    def next(self) -> None:  # nothing to verify: the tick ends after the update
        return None


class _Queue(_Reasoner):
    """Always one target subgraph to verify; results are dropped."""

    def next(self):
        return SimpleNamespace(kind="target", signature=(1,))

    def accept(self, result):
        pass


def _node() -> tuple[ReasoningNode, list, _Reasoner]:
    calls: list = []
    reasoner = _Reasoner()

    def decompose(memory, task, similarity, k=5):
        calls.append(memory)
        return [("subgraph", len(calls))]

    node = ReasoningNode(parse=lambda text: text, make_reasoner=lambda task: reasoner, verifier=object(),
                         decompose=decompose, similarity=lambda a, b: 0.0)
    node._set_task("find the bed")
    return node, calls, reasoner


def _tick(node: ReasoningNode, memory, t: float) -> None:
    node.receive(WorldSnapshot(int(t * 10), t, Pose2D(0.0, 0.0, 0.0), None, memory), t)
    node.run_tick(t)


def test_same_views_reuse_the_decomposition_and_changed_views_recompute_it():
    node, calls, reasoner = _node()
    bed, chair, anchor = object(), object(), object()
    _tick(node, SimpleNamespace(objects=(bed,), anchors=(anchor,), stamp=0.1), 0.1)
    # a new snapshot object (new stamp) holding the identical views: decomposition reused
    _tick(node, SimpleNamespace(objects=(bed,), anchors=(anchor,), stamp=0.2), 0.2)
    assert len(calls) == 1 and node.decompose_reused == 1
    assert reasoner.updates[0] == reasoner.updates[1] == [("subgraph", 1)]
    # a changed view (new object) or a new task: decomposed again
    _tick(node, SimpleNamespace(objects=(bed, chair), anchors=(anchor,), stamp=0.3), 0.3)
    assert len(calls) == 2
    node._set_task("find the chair")
    _tick(node, SimpleNamespace(objects=(bed, chair), anchors=(anchor,), stamp=0.4), 0.4)
    assert len(calls) == 3 and node.decompose_reused == 1
    assert reasoner.updates[-1] == [("subgraph", 3)]


def test_a_replaced_view_of_the_same_object_is_a_change():
    node, calls, _ = _node()
    _tick(node, SimpleNamespace(objects=(object(),), anchors=(), stamp=0.1), 0.1)
    _tick(node, SimpleNamespace(objects=(object(),), anchors=(), stamp=0.2), 0.2)  # rebuilt view
    assert len(calls) == 2 and node.decompose_reused == 0


def test_relations_that_fail_rule_instances_out_for_exploration_until_judged_again():
    from hiconav.messages import RuledOut

    replies = iter([{4: "fails", 5: "unknown"}, {4: "fails", 5: "fails"}, {4: "holds"}, {5: "fails"}])

    class _Verifier:
        def verify(self, subgraph, task):
            return SimpleNamespace(found=False, hypothesis=None, reason="relation_failed", detail="",
                                   latency_s=0.0, source="offline", verdicts=next(replies))

    node = ReasoningNode(parse=lambda text: text, make_reasoner=lambda task: _Queue(), verifier=_Verifier(),
                         decompose=lambda memory, task, similarity, k=5: [], latency_s=0.0)
    node._set_task("find the bed by the lamp")
    posted = []
    for t in (0.1, 0.2, 0.3):
        _tick(node, SimpleNamespace(objects=(), anchors=(), stamp=t), t)
        posted += [o.msg.object_ids for o in node.drain() if isinstance(o.msg, RuledOut) and o.dest == "exploration"]
    assert posted == [frozenset({4}), frozenset({4, 5}), frozenset({5})]
    # a new task: exploration forgets its set, so the same set is sent again
    node._set_task("find the bed by the sofa")
    _tick(node, SimpleNamespace(objects=(), anchors=(), stamp=0.4), 0.4)
    out = [(o.dest, o.msg.object_ids) for o in node.drain() if isinstance(o.msg, RuledOut)]
    # the mission hears the same set (Explore lingers only by instances not ruled out)
    assert sorted(out) == [("exploration", frozenset({5})), ("mission", frozenset({5}))]


def _two_tvs(verdicts: dict, relation: tuple, **kw) -> tuple[ReasoningNode, SimpleNamespace]:
    """A reasoning node whose verifier always judges two tv nodes (4: seen 3 times at 0.4, 5: seen
    9 times at 0.9) with ``verdicts``, and the memory holding them."""
    import numpy as np

    class _Verifier:
        def verify(self, subgraph, task):
            return SimpleNamespace(found=False, hypothesis=None, reason="relation_unknown", detail="",
                                   latency_s=0.0, source="offline", verdicts=dict(verdicts))

    node = ReasoningNode(parse=lambda text: text, make_reasoner=lambda task: _Queue(), verifier=_Verifier(),
                         decompose=lambda memory, task, similarity, k=5: [], latency_s=0.0, **kw)
    node._set_task(SimpleNamespace(targets=("tv",), relations=(relation,)))
    objects = (SimpleNamespace(id=4, label="tv", confidence=0.4, n_obs=3),
               SimpleNamespace(id=5, label="tv", confidence=0.9, n_obs=9))
    anchors = (SimpleNamespace(id=1, object_ids=(4, 5), boxes=np.array([[0.1, 0.1, 0.3, 0.3], [0.5, 0.5, 0.9, 0.9]])),)
    return node, SimpleNamespace(objects=objects, anchors=anchors, stamp=0.1)


def test_explored_out_offers_the_best_unresolved_candidate_once_each():
    from hiconav.messages import ExploredOut, HypothesisMsg

    node, memory = _two_tvs({4: "unknown", 5: "fails"}, ("tv", "in", "bedroom"))
    _tick(node, memory, 0.1)
    node.drain()

    def offered(t: float) -> list:
        node.receive(ExploredOut(t), t)
        _tick(node, memory, t)
        return [o.msg.hypothesis.object_id for o in node.drain() if isinstance(o.msg, HypothesisMsg) and o.dest == "mission"]

    assert offered(0.2) == [4]  # unknown before ruled out
    assert offered(0.3) == [5]  # then the next one, never the same twice
    assert offered(0.4) == []  # none left
    assert [e["found"] for e in node.events if e["kind"] == "unresolved"] == [True, True, False]
    # nothing asked: nothing offered
    _tick(node, memory, 0.5)
    assert not [o for o in node.drain() if isinstance(o.msg, HypothesisMsg)]


def test_a_marginal_candidate_is_offered_once_its_patience_runs_out():
    from hiconav.messages import HypothesisMsg

    verdicts, relation = {4: "marginal", 5: "unknown"}, ("tv", "next to", "sofa")
    node, memory = _two_tvs(verdicts, relation, marginal_patience_s=1.0)
    offered = []
    for k in range(1, 25):  # 0.1 s ticks: marginal since 0.1 s, due at 1.1 s
        _tick(node, memory, round(0.1 * k, 1))
        offered += [(round(0.1 * k, 1), o.msg.hypothesis.object_id) for o in node.drain()
                    if isinstance(o.msg, HypothesisMsg) and o.dest == "mission"]
    assert offered == [(1.1, 4)]  # once, the marginal one only (never the unknown one, however well seen)
    assert [e["reason"] for e in node.events if e["kind"] == "unresolved"] == ["marginal"]
    # without patience, a marginal candidate waits for the search to explore out
    quiet, memory = _two_tvs(verdicts, relation)
    for k in range(1, 25):
        _tick(quiet, memory, round(0.1 * k, 1))
    assert not [o for o in quiet.drain() if isinstance(o.msg, HypothesisMsg)]


def test_a_marginal_offer_that_fails_later_is_withdrawn_for_good_an_explored_out_one_is_not():
    from hiconav.messages import ExploredOut, RuledOut

    def withdrawn(node, t) -> frozenset | None:
        _tick(node, memory, t)
        posted = [o.msg.withdrawn for o in node.drain() if isinstance(o.msg, RuledOut) and o.dest == "mission"]
        return posted[-1] if posted else None

    verdicts, relation = {4: "marginal", 5: "unknown"}, ("tv", "next to", "sofa")
    node, memory = _two_tvs(verdicts, relation, marginal_patience_s=1.0)
    for k in range(1, 13):  # offered at 1.1 s
        _tick(node, memory, round(0.1 * k, 1))
    node.drain()
    verdicts[4] = "fails"  # judged on the nodes mapped since: another room
    assert withdrawn(node, 1.3) == frozenset({4})
    verdicts[4] = "marginal"  # the next subgraph holds fewer cues: the posterior sways back
    assert withdrawn(node, 1.4) == frozenset({4})  # taken back for good (the set changed: posted)
    # an explored-out offer is the last resort: a verdict that fails after it takes nothing back
    verdicts2 = {4: "unknown", 5: "fails"}
    last, memory = _two_tvs(verdicts2, ("tv", "in", "bedroom"))
    _tick(last, memory, 0.1)
    last.receive(ExploredOut(0.2), 0.2)
    _tick(last, memory, 0.2)
    last.drain()
    verdicts2[4] = "fails"
    assert withdrawn(last, 0.3) == frozenset()
