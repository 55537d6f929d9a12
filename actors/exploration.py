"""ExplorationActor: frontiers -> utilities -> WTRP order, at its own (low) rate.

Owns one ``FrontierTracker`` and one ``ExplorationPlanner``. On each tick it takes the newest
``WorldSnapshot`` (older ones were dropped and counted), updates the frontiers, plans, and sends a
``PlanMsg`` to the mission. Without a planner it orders frontiers by straight-line distance: a
clearly labelled fallback (``solver="nearest-fallback"``). It never sends goals to control.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor

from hiconav.messages import PlanMsg, RuledOut, TargetRejected, TaskMsg, WorldSnapshot
from hiconav.types import Frontier


class ExplorationActor(NodeActor):
    """pykka actor of the exploration layer."""


@dataclass(frozen=True)
class NearestPlan:
    """FALLBACK plan (no ExplorationPlanner): frontiers ordered by distance from the robot."""

    goal: Frontier | None
    order: tuple[int, ...]
    solver: str = "nearest-fallback"
    switched: bool = False


class ExplorationNode(Node):
    name = "exploration"
    actor_class = ExplorationActor

    def __init__(self, tracker: Any, planner: Any = None, *, rate_hz: float = 2.0,
                 similarity: Callable[[str, str], float] | None = None, to: tuple[str, ...] = ("mission", "recorder")) -> None:
        super().__init__(rate_hz)
        self.tracker = tracker
        self.planner = planner
        self.similarity = similarity
        self.to = to
        self.task = None
        self._snapshot: WorldSnapshot | None = None
        self._last_pose = None
        self._last_stamp = None
        self.plans = 0
        self.latest_wins(WorldSnapshot)
        self.ruled_out: frozenset[int] = frozenset()  # target-category nodes the reasoning ruled out
        self.on(TaskMsg, self._on_task)
        self.on(RuledOut, lambda m, now: setattr(self, "ruled_out", frozenset(m.object_ids)))
        # nodes the mission's verification rejected for good (the oracle's spurious boxes, a
        # look-alike): the planner leaves them out of S_struct with exclude_rejected
        self.rejected: frozenset[int] = frozenset()
        # candidates set aside only as out of reach (no view point on the map yet): they draw the
        # search, until a later verdict on them says otherwise
        self.out_of_reach: frozenset[int] = frozenset()
        self.on(TargetRejected, self._on_rejected)

    def _on_rejected(self, msg: TargetRejected, now: float) -> None:
        oid = int(msg.object_id)
        if msg.permanent:
            self.rejected = self.rejected | {oid}
        self.out_of_reach = self.out_of_reach | {oid} if msg.out_of_reach else self.out_of_reach - {oid}

    def _on_task(self, msg: TaskMsg, now: float) -> None:
        self.task = msg.task
        self.ruled_out = self.rejected = self.out_of_reach = frozenset()

    def tick(self, now: float) -> None:
        snap = self.take(WorldSnapshot)
        if snap is None:
            return
        pose = snap.pose
        frontiers = list(self.tracker.update(snap.grid, np.array([pose.x, pose.y])))
        velocity = np.zeros(2)
        if self._last_pose is not None and self._last_stamp is not None and now > self._last_stamp:
            velocity = (np.array([pose.x, pose.y]) - np.array([self._last_pose.x, self._last_pose.y])) / (
                now - self._last_stamp)
        self._last_pose, self._last_stamp = pose, now
        if self.planner is not None and self.task is not None:
            plan = self.planner.plan(snap.grid, frontiers, snap.memory, self.task, pose, velocity,
                                     self.similarity, now,
                                     ruled_out=self.ruled_out, drawn=self.out_of_reach, rejected=self.rejected)
        else:
            order = sorted(frontiers, key=lambda f: (math.hypot(f.viewpoint[0] - pose.x, f.viewpoint[1] - pose.y), f.id))
            plan = NearestPlan(order[0] if order else None, tuple(f.id for f in order))
        self.plans += 1
        self.emit(self.to, PlanMsg(plan, tuple(frontiers), now, snap.seq))
