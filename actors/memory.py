"""MemoryActor: integrates observations into the occupancy grid and the cognitive memory graph.

Owns one ``OccupancyGrid`` and one ``CognitiveMemoryGraph`` (either may be None in tests).
Observations are latest-wins; after each integration it publishes one immutable ``WorldSnapshot``
(grid snapshot + memory snapshot + pose) to exploration, reasoning, mission and control. ILP
pruning runs every ``prune_every`` integrations when enabled. It never plans or decides.

A frame the core refuses (``FrameError``: a pose that jumped farther than the robot can move,
see ``hiconav.mapping.PoseGate``; a depth that does not fit the camera; a pose so far off that
the grid would outgrow ``max_extent_m``) is dropped and counted (``stats.dropped["pose_jump"]``
or ``["bad_frame"]``, in the mission result's ``dropped``; the last reason in ``last_drop``):
no snapshot goes out for it and the mission goes on with the next frame.
"""

from __future__ import annotations

import logging
from typing import Any

from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor
from hiconav.errors import FrameError
from hiconav.mapping.pose_gate import PoseGate, PoseJumpError
from hiconav.memory import KeyframeSchedule
from hiconav.messages import HypothesisMsg, KeyframeRequest, Observation, TaskMsg, WorldSnapshot

log = logging.getLogger(__name__)


class MemoryActor(NodeActor):
    """pykka actor of the memory layer."""


class MemoryNode(Node):
    name = "memory"
    event_driven = True  # per-frame chain: see Node.event_driven
    actor_class = MemoryActor

    def __init__(self, grid: Any, cmg: Any = None, *, rate_hz: float = 10.0, prune_every: int = 0,
                 to: tuple[str, ...] = ("exploration", "reasoning", "mission", "control", "recorder"),
                 pose_gate: PoseGate | None = None) -> None:
        super().__init__(rate_hz)
        self.grid = grid
        self.cmg = cmg
        self.pose_gate = pose_gate if pose_gate is not None else PoseGate()
        self.last_drop: str | None = None  # why the newest dropped frame was refused
        self.prune_every = prune_every
        self.to = to
        self.seq = 0
        self.hypotheses: list[Any] = []
        self.task = None
        self.latest_wins(Observation)
        self.on(HypothesisMsg, lambda m, now: self.hypotheses.append(m.hypothesis))
        self.on(TaskMsg, lambda m, now: setattr(self, "task", m.task))
        self.keyframes = KeyframeSchedule()  # the frames the mission asked to be anchors
        self.on(KeyframeRequest, lambda m, now: self.keyframes.request(m.until, m.every_s))

    def tick(self, now: float) -> None:
        obs = self.take(Observation)
        if obs is None:
            return
        try:
            self.pose_gate.check(obs.frame)
            self.grid.integrate(obs.frame)  # validates before it changes anything
        except FrameError as exc:
            self._drop("pose_jump" if isinstance(exc, PoseJumpError) else "bad_frame", exc, obs)
            return
        self.pose_gate.accept(obs.frame)
        memory = None
        if self.cmg is not None:
            try:
                self.cmg.update(obs.frame, list(obs.detections), keyframe=self.keyframes.due(now))
            except FrameError as exc:  # the grid has the frame; only its objects are lost
                self._drop("bad_frame", exc, obs)
            if self.prune_every and (self.seq + 1) % self.prune_every == 0:
                self.cmg.prune()
            memory = self.cmg.snapshot()
        self.seq += 1
        self.emit(self.to, WorldSnapshot(self.seq, now, obs.frame.base_pose, self.grid.snapshot(), memory,
                                         int(obs.frame.seq)))

    def _drop(self, slot: str, exc: FrameError, obs: Observation) -> None:
        n = self.stats.dropped.get(slot, 0) + 1
        self.stats.dropped[slot] = n
        self.last_drop = str(exc)
        if n == 1 or n % 100 == 0:  # a sensor that stays broken must not flood the log
            log.warning("memory: frame %s dropped (%s #%d): %s", getattr(obs.frame, "seq", "?"), slot, n, exc)
