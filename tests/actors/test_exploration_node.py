"""ExplorationNode hands the planner the nodes the reasoning ruled out (the latest set wins)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from hiconav.actors.exploration import ExplorationNode
from hiconav.messages import RuledOut, TaskMsg, WorldSnapshot
from hiconav.types import Pose2D


class _Tracker:
    def update(self, grid, xy):
        return []


class _Planner:
    def __init__(self) -> None:
        self.ruled_out: list[frozenset] = []

    def plan(self, grid, frontiers, memory, task, pose, velocity, similarity, now, ruled_out=()):
        self.ruled_out.append(frozenset(ruled_out))
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
