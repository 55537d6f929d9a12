"""Actors of a mission: thin pykka shells, one per layer, around synchronous ``Node`` cores.

``DriverNode`` (simulator/robot), ``PerceptionNode``, ``MemoryNode``, ``ReasoningNode``,
``ExplorationNode``, ``ControlNode`` and ``MissionNode`` (the py_trees mission tree) exchange the
frozen messages of ``hiconav.messages``. ``RealtimeRuntime`` runs them as pykka ThreadingActors on
wall-clock timers; ``SteppedRuntime`` drives the same nodes with the same messages on a virtual
clock (reproducible). Core algorithms live in ``hiconav/``; nothing here implements one.
"""

from hiconav.actors.node import Node, NodeStats, Outgoing
from hiconav.actors.runtime import RUNTIME, NodeActor, RealtimeRuntime, RunReport, SteppedRuntime

#: Start order (dependency order) of a mission's actors; they stop in reverse.
START_ORDER: tuple[str, ...] = ("driver", "perception", "memory", "reasoning", "exploration", "control", "mission")
#: The fixed order in which the stepped scheduler ticks the nodes due at one virtual instant.
TICK_ORDER: tuple[str, ...] = ("driver", "perception", "memory", "reasoning", "exploration", "mission", "control")

__all__ = [
           "RUNTIME",
           "START_ORDER",
           "TICK_ORDER",
           "Node",
           "NodeActor",
           "NodeStats",
           "Outgoing",
           "RealtimeRuntime",
           "RunReport",
           "SteppedRuntime",
]
