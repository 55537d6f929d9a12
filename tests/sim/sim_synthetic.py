"""Helpers for simulator tests: small synthetic houses built in code."""

from __future__ import annotations

import numpy as np

from hiconav.sim.house import House, Room, SimObject, Wall, assemble_house


def box_room(size: float = 6.0, objects: list[SimObject] | None = None,
             extra_walls: list[Wall] | None = None, name: str = "synthetic") -> House:
    """A square room [0, size]^2 closed by four 0.1 m walls (centred on the edges)."""
    s = size
    walls = [Wall((0.0, 0.0), (s, 0.0), 2.5, 0.1), Wall((s, 0.0), (s, s), 2.5, 0.1),
             Wall((s, s), (0.0, s), 2.5, 0.1), Wall((0.0, s), (0.0, 0.0), 2.5, 0.1)]
    walls += extra_walls or []
    room = Room("room|0", "LivingRoom", np.array([[0, 0], [s, 0], [s, s], [0, s]], float))
    return assemble_house(name, [room], walls, objects or [])


def obj(iid: int, category: str, center, size, yaw: float = 0.0) -> SimObject:
    return SimObject(iid, category, np.array(center, float), np.array(size, float), yaw,
                     category)


