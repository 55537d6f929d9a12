"""MissionActor: ticks the py_trees mission tree over the results the other actors deliver.

Owns the ``MissionTree`` and its ``MissionContext`` (the blackboard belongs to this actor alone).
Incoming results (task, world snapshot, exploration plan, hypotheses, navigation status, health
alerts) are written into the context; after each tick the context's requests become messages:
``ParseRequest`` -> reasoning, ``GoalMsg``/``StopRequest`` -> control, ``TargetRejected`` ->
reasoning and exploration. When the tree finishes it reports ``MissionFinished`` to the runtime. On stop the
running branch is preempted (``terminate(INVALID)`` all the way down).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor
from hiconav.decisions.config import DecisionsConfig
from hiconav.trees.context import MissionContext
from hiconav.trees.mission_tree import MissionTree

from hiconav.messages import (
    EpisodeEnded,
    ExploredOut,
    GoalMsg,
    HealthAlert,
    HypothesisMsg,
    KeyframeRequest,
    MissionFinished,
    NavStatus,
    ParseRequest,
    PlanMsg,
    RuledOut,
    StopRequest,
    TargetRejected,
    TaskMsg,
    TreeStatus,
    WorldSnapshot,
)

_ROUTES = {ParseRequest: "reasoning", GoalMsg: "control", StopRequest: "control", TargetRejected: "reasoning",
           ExploredOut: "reasoning", KeyframeRequest: "memory"}


class MissionActor(NodeActor):
    """pykka actor of the mission tree."""


class MissionNode(Node):
    name = "mission"
    event_driven = True  # per-frame chain: see Node.event_driven
    actor_class = MissionActor

    def __init__(self, tree: str | Path, instruction: str, *, rate_hz: float = 10.0,
                 blackboard: dict[str, Any] | None = None, success_distance: float = 1.0, verify: bool = True,
                 use_memory_labels: bool = True, reasoning: bool = True, record_tree: bool = False,
                 requalify_observations: int = 3, remap_area_m2: float = 1.0,
                 decisions: DecisionsConfig | None = None, time_scale: float = 1.0) -> None:
        super().__init__(rate_hz)
        self.tree_source = tree
        self.instruction = instruction
        self.blackboard = dict(blackboard or {})
        self.success_distance = success_distance
        self.verify = verify
        self.use_memory_labels = use_memory_labels
        self.reasoning = reasoning
        self.requalify_observations = requalify_observations
        self.remap_area_m2 = remap_area_m2
        # the decisions' durations are robot time; ``time_scale`` (the clock's seconds per second of
        # robot time: 1 on a robot, ``hiconav.mission.stepped_time_scale`` on the simulator) puts
        # them on this actor's clock, the tree's own settings too (``MissionContext.time_scale``)
        self.time_scale = float(time_scale)
        self.decisions = (decisions if decisions is not None else DecisionsConfig()).in_clock(self.time_scale)
        self.record_tree = record_tree
        self._now = 0.0
        self.context: MissionContext | None = None
        self.tree: MissionTree | None = None
        self.finished: MissionFinished | None = None
        self.episode: EpisodeEnded | None = None
        self.history: list[TreeStatus] = []
        self._sent_rejections = 0
        self.latest_wins(WorldSnapshot, PlanMsg)
        self.on(TaskMsg, lambda m, now: setattr(self.context, "task", m.task))
        self.on(HypothesisMsg, lambda m, now: self.context.hypotheses.append(m.hypothesis))
        self.on(NavStatus, self._on_nav)
        self.on(HealthAlert, lambda m, now: self.context.alerts.append(m))
        self.on(RuledOut, self._on_ruled_out)
        self.on(EpisodeEnded, lambda m, now: setattr(self, "episode", m))

    def _on_ruled_out(self, msg: RuledOut, now: float) -> None:
        self.context.ruled_out = frozenset(msg.object_ids)
        self.context.withdrawn = frozenset(msg.withdrawn)

    def _on_nav(self, msg: NavStatus, now: float) -> None:
        if msg.goal_seq == self.context.goal_seq:
            self.context.nav = msg
        else:  # status of a goal the tree has already replaced
            self.stats.dropped["NavStatus"] = self.stats.dropped.get("NavStatus", 0) + 1

    def start(self, now: float) -> None:
        self._now = now
        self.context = MissionContext(instruction=self.instruction, clock=lambda: self._now,
                                      success_distance=self.success_distance, verify=self.verify,
                                      use_memory_labels=self.use_memory_labels, reasoning=self.reasoning,
                                      requalify_observations=self.requalify_observations,
                                      remap_area_m2=self.remap_area_m2, decisions=self.decisions,
                                      time_scale=self.time_scale)
        self.tree = MissionTree(self.tree_source, self.context, self.blackboard)

    def stop(self, now: float) -> None:
        if self.tree is not None:
            self._now = now
            self.tree.stop()
            self._flush(now)

    def _flush(self, now: float) -> None:
        ctx = self.context
        for msg in ctx.outbox:
            dest = _ROUTES.get(type(msg))
            if dest is not None:
                self.emit(dest, msg)
        ctx.outbox.clear()
        for oid, reason in ctx.rejections[self._sent_rejections:]:
            self.emit(("reasoning", "exploration"), TargetRejected(oid, reason, now, oid in ctx.rejected,
                                                                        oid in ctx.out_of_reach))
        self._sent_rejections = len(ctx.rejections)

    def tick(self, now: float) -> None:
        self._now = now
        ctx = self.context
        world = self.take(WorldSnapshot)
        if world is not None:
            ctx.world = world
            if ctx.start_pose is None:
                ctx.start_pose = world.pose
        plan = self.take(PlanMsg)
        if plan is not None:
            ctx.plan = plan
        if self.finished is not None or self.episode is not None:
            return
        status = self.tree.tick()
        self._flush(now)
        entry = TreeStatus(self.tree.ticks, now, status.value, self.tree.tip_name(),
                           self.tree.ascii() if self.record_tree else "")
        self.history.append(entry)
        if self.record_tree:
            self.emit("recorder", entry)
        if status.value in ("SUCCESS", "FAILURE"):
            tip = self.tree.root.tip()
            feedback = "" if tip is None else f"{tip.name}: {tip.feedback_message}"
            self.finished = MissionFinished(status.value, now, feedback)
            self.emit("runtime", self.finished)
