"""Node: the synchronous core of an actor (what its mailbox handler runs), clock-agnostic.

Every actor of a mission is a ``Node`` wrapped either by a pykka ThreadingActor (real time:
``actors/runtime.py`` ``RealtimeRuntime``) or driven directly by the virtual-clock scheduler
(stepped time: ``SteppedRuntime``). In both cases the same messages reach the same two methods:

- ``receive(msg, now)``: store the message (frames and snapshots go to latest-wins slots: a newer
  one replaces an unprocessed older one, which is dropped and counted) - cheap, never blocks;
- ``tick(now)``: do the work at the node's rate and ``emit(dest, msg, delay)`` results.

``delay`` is how long after ``now`` the message becomes visible (the VLM's measured or configured
latency in stepped time; in real time the work really took that long, so it is sent at once).
A node owns its core objects and never shares them; it never calls another node. No threads,
no pykka, no sleeping here.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class Outgoing:
    """A message leaving a node: destination name, the message, visibility delay (s)."""

    dest: str
    msg: Any
    delay: float = 0.0


@dataclass
class NodeStats:
    """Counters of one node: ticks run, messages handled, stale messages dropped per slot, busy time."""

    ticks: int = 0
    handled: int = 0
    dropped: dict[str, int] = field(default_factory=dict)
    busy_s: float = 0.0


class Node:
    """Base class of the actor cores. Subclasses set ``name`` and register handlers by type."""

    name: str = "node"
    #: real time only: work on new input at once instead of at the next timer tick. For the nodes
    #: of the per-frame chain (perception, memory, control, mission), whose input arrives at the
    #: driver's rate; heavy periodic nodes (exploration, reasoning) keep their own slower rate.
    event_driven: bool = False

    def __init__(self, rate_hz: float) -> None:
        if rate_hz <= 0:
            raise ValueError(f"{self.name}: rate must be > 0 Hz, got {rate_hz}")
        self.rate_hz = float(rate_hz)
        self.stats = NodeStats()
        self._outbox: list[Outgoing] = []
        self._slots: dict[str, Any] = {}
        self._handlers: dict[type, Callable[[Any, float], None]] = {}

    @property
    def period(self) -> float:
        return 1.0 / self.rate_hz

    # -- wiring ----------------------------------------------------------------------------------
    def on(self, msg_type: type, handler: Callable[[Any, float], None]) -> None:
        self._handlers[msg_type] = handler

    def latest_wins(self, *msg_types: type) -> None:
        """Store messages of these types in a latest-wins slot named after the type."""
        for t in msg_types:
            self._handlers[t] = self._slot_handler(t.__name__)

    def _slot_handler(self, slot: str) -> Callable[[Any, float], None]:
        def handler(msg: Any, now: float) -> None:
            if slot in self._slots:
                self.stats.dropped[slot] = self.stats.dropped.get(slot, 0) + 1
            self._slots[slot] = msg
        return handler

    def take(self, slot: str | type) -> Any:
        """Pop the newest unprocessed message of a latest-wins slot (None when there is none)."""
        key = slot if isinstance(slot, str) else slot.__name__
        return self._slots.pop(key, None)

    def peek(self, slot: str | type) -> Any:
        key = slot if isinstance(slot, str) else slot.__name__
        return self._slots.get(key)

    # -- life cycle (called by the runtime) ------------------------------------------------------
    def start(self, now: float) -> None:
        """Acquire resources (open the simulator, load models); called in dependency order."""

    def stop(self, now: float) -> None:
        """Release resources; called in reverse dependency order."""

    def receive(self, msg: Any, now: float) -> None:
        handler = self._handlers.get(type(msg))
        if handler is None:
            raise TypeError(f"{self.name} has no handler for {type(msg).__name__}")
        self.stats.handled += 1
        handler(msg, now)

    def run_tick(self, now: float) -> None:
        t0 = time.perf_counter()
        self.tick(now)
        self.stats.busy_s += time.perf_counter() - t0
        self.stats.ticks += 1

    def tick(self, now: float) -> None:
        """The node's periodic work (override)."""

    def emit(self, dest: str | tuple[str, ...], msg: Any, delay: float = 0.0) -> None:
        for d in (dest,) if isinstance(dest, str) else dest:
            self._outbox.append(Outgoing(d, msg, delay))

    def drain(self) -> list[Outgoing]:
        out, self._outbox = self._outbox, []
        return out

    def emergency_stop(self, reason: str, now: float) -> None:
        """Stop moving now (only the driver node does something here)."""
