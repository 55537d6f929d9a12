"""ExplorationNode hands the planner the nodes the reasoning ruled out (the latest set wins) and
the nodes the mission's verification rejected for good."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from hiconav.actors.exploration import ExplorationNode
from hiconav.messages import RuledOut, TargetRejected, TaskMsg, WorldSnapshot
from hiconav.types import Pose2D


class _Tracker:
    def update(self, grid, xy):
        return []


class _Planner:
    def __init__(self) -> None:
        self.ruled_out: list[frozenset] = []
        self.drawn: list[frozenset] = []
        self.rejected: list[frozenset] = []

    def plan(self, grid, frontiers, memory, task, pose, velocity, similarity, now, ruled_out=(), drawn=(), rejected=()):
        self.ruled_out.append(frozenset(ruled_out))
        self.rejected.append(frozenset(rejected))
        self.drawn.append(frozenset(drawn))
        return SimpleNamespace(goal=None, order=())


def _tick(node: ExplorationNode, t: float, *msgs) -> None:
    for m in msgs:
        node.receive(m, t)
    node.receive(WorldSnapshot(int(t * 10), t, Pose2D(0.0, 0.0, 0.0), np.zeros((2, 2)), None), t)
    node.run_tick(t)


def test_ruled_out_nodes_reach_the_planner_and_a_new_task_forgets_them():
    planner = _Planner()
    node = ExplorationNode(_Tracker(), planner)
    _tick(node, 0.5, TaskMsg(SimpleNamespace(targets=("bed",)), 0.0))
    _tick(node, 1.0, RuledOut(frozenset({4, 5}), 1.0))
    _tick(node, 1.5, RuledOut(frozenset({5}), 1.5))  # a later verdict took #4 back
    assert planner.ruled_out == [frozenset(), frozenset({4, 5}), frozenset({5})]
    _tick(node, 2.0, TaskMsg(SimpleNamespace(targets=("chair",)), 2.0))
    assert planner.ruled_out[-1] == frozenset()


def test_rejected_nodes_are_no_target_evidence_and_ones_out_of_reach_draw_the_search():
    planner = _Planner()
    node = ExplorationNode(_Tracker(), planner)
    _tick(node, 0.5, TaskMsg(SimpleNamespace(targets=("bed",)), 0.0))
    _tick(node, 1.0, TargetRejected(7, "detected in 0 of 4 frames in view", 1.0, permanent=True),
          TargetRejected(8, "no reachable view point", 1.0, permanent=False, out_of_reach=True),
          TargetRejected(9, "label is now 'sofa'", 1.0, permanent=False))
    assert planner.rejected[-1] == frozenset({7}) and planner.drawn[-1] == frozenset({8})
    _tick(node, 1.5, RuledOut(frozenset({4}), 1.5))
    assert planner.ruled_out[-1] == frozenset({4}) and planner.rejected[-1] == frozenset({7})
    _tick(node, 1.8, TargetRejected(8, "detected in 0 of 4 frames in view", 1.8, permanent=True))
    assert planner.rejected[-1] == frozenset({7, 8}) and planner.drawn[-1] == frozenset()
    _tick(node, 2.0, TaskMsg(SimpleNamespace(targets=("chair",)), 2.0))
    assert planner.rejected[-1] == frozenset() and planner.drawn[-1] == frozenset()


def test_the_mission_posts_each_rejection_to_reasoning_and_exploration_saying_whether_it_is_for_good():
    from hiconav.actors.mission import MissionNode

    node = MissionNode("objectnav", "find the bed")
    node.start(0.0)
    node.context.reject(7, "detected in 0 of 4 frames in view")
    node.context.reject(8, "no reachable view point", permanent=False, remap=True, out_of_reach=True)
    node._flush(1.0)
    sent = [(o.dest, o.msg) for o in node.drain() if isinstance(o.msg, TargetRejected)]
    assert {d for d, _ in sent} == {"reasoning", "exploration"}
    assert {(m.object_id, m.permanent, m.out_of_reach) for d, m in sent if d == "exploration"} == {
        (7, True, False), (8, False, True)}
    node._flush(2.0)  # each rejection goes once
    assert not [o for o in node.drain() if isinstance(o.msg, TargetRejected)]
