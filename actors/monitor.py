"""BatteryMonitorActor: an example of a user actor whose message changes what the mission does.

It models a battery that drains with clock time (and faster while the robot moves) and sends a
``HealthAlert("battery", ...)`` to the mission once the charge falls below ``warn_fraction``. The
``find_and_return`` mission guards its search with ``HealthOk``, so the alert preempts the search
(``terminate(INVALID)`` cancels its goal) and the robot returns to its start. Add it to a mission
with ``build_mission(...).nodes.append(BatteryMonitorNode(...))`` or by import path in config
(``hiconav.actors.monitor:BatteryMonitorNode``). It reads nothing but the driver's frames.
"""

from __future__ import annotations

from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor

from hiconav.messages import FrameMsg, HealthAlert


class BatteryMonitorActor(NodeActor):
    """pykka actor of the battery monitor."""


class BatteryMonitorNode(Node):
    """Battery model: ``capacity_s`` seconds idle; moving drains ``move_factor`` times faster."""

    name = "battery"
    actor_class = BatteryMonitorActor

    def __init__(self, capacity_s: float = 600.0, *, warn_fraction: float = 0.2, move_factor: float = 2.0,
                 rate_hz: float = 1.0, to: str = "mission") -> None:
        super().__init__(rate_hz)
        if capacity_s <= 0 or not 0 < warn_fraction < 1:
            raise ValueError("capacity_s must be > 0 and warn_fraction in (0, 1)")
        self.capacity_s = capacity_s
        self.warn_fraction = warn_fraction
        self.move_factor = move_factor
        self.to = to
        self.charge = 1.0
        self.alerted = False
        self._last: float | None = None
        self._moved = False
        self.on(FrameMsg, lambda m, now: setattr(self, "_moved", True))

    def tick(self, now: float) -> None:
        if self._last is not None:
            rate = self.move_factor if self._moved else 1.0
            self.charge = max(0.0, self.charge - rate * (now - self._last) / self.capacity_s)
        self._last, self._moved = now, False
        if not self.alerted and self.charge < self.warn_fraction:
            self.alerted = True
            self.emit(self.to, HealthAlert("battery", f"battery at {100 * self.charge:.0f}%: return to start", now))
