"""MemoryActor: integrates observations into the occupancy grid and the cognitive memory graph.

Owns one ``OccupancyGrid`` and one ``CognitiveMemoryGraph`` (either may be None in tests).
Observations are latest-wins; after each integration it publishes one immutable ``WorldSnapshot``
(grid snapshot + memory snapshot + pose) to exploration, reasoning, mission and control. ILP
pruning runs every ``prune_every`` integrations when enabled. It never plans or decides.
"""

from __future__ import annotations

from typing import Any

from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor

from hiconav.messages import HypothesisMsg, Observation, TaskMsg, WorldSnapshot


class MemoryActor(NodeActor):
    """pykka actor of the memory layer."""


class MemoryNode(Node):
    name = "memory"
    event_driven = True  # per-frame chain: see Node.event_driven
    actor_class = MemoryActor

    def __init__(self, grid: Any, cmg: Any = None, *, rate_hz: float = 10.0, prune_every: int = 0,
                 to: tuple[str, ...] = ("exploration", "reasoning", "mission", "control", "recorder")) -> None:
        super().__init__(rate_hz)
        self.grid = grid
        self.cmg = cmg
        self.prune_every = prune_every
        self.to = to
        self.seq = 0
        self.hypotheses: list[Any] = []
        self.task = None
        self.latest_wins(Observation)
        self.on(HypothesisMsg, lambda m, now: self.hypotheses.append(m.hypothesis))
        self.on(TaskMsg, lambda m, now: setattr(self, "task", m.task))

    def tick(self, now: float) -> None:
        obs = self.take(Observation)
        if obs is None:
            return
        self.grid.integrate(obs.frame)
        memory = None
        if self.cmg is not None:
            self.cmg.update(obs.frame, list(obs.detections))
            if self.prune_every and (self.seq + 1) % self.prune_every == 0:
                self.cmg.prune()
            memory = self.cmg.snapshot()
        self.seq += 1
        self.emit(self.to, WorldSnapshot(self.seq, now, obs.frame.base_pose, self.grid.snapshot(), memory,
                                         int(obs.frame.seq)))
