"""Linger: look around an undecided instance of the target's category that the robot comes upon.

A described instance ("the chair next to the fridge") is confirmed only by the reasoning layer,
on what the memory holds of the instance and of what stands around it. A robot that drives past
an instance of the category, close by, before the memory has seen enough of it or of its
neighbours (its related object not yet in view, too few observations, its room not yet clear),
drives on with the exploration plan, and when the verdict comes, a few seconds later, drives back.
Turning in place beside it instead shows the memory the instance and its surroundings, from
where a related object next to it would be seen, at the cost of a few turns and no path.

Pure: plain memory objects in, an object id out. The Explore behaviour sends the turns.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from typing import Any

import numpy as np

from hiconav.geometry import footprint_distance
from hiconav.types import label_key


def undecided_near(objects: Iterable[Any], targets: Iterable[str], robot_xy: np.ndarray, within_m: float,
                   ruled_out: Collection[int], done: Collection[int], excluded: Any = None) -> int | None:
    """The id of the nearest memory object whose label is one of ``targets``, whose footprint lies
    within ``within_m`` of ``robot_xy`` (2,) world, that the reasoning layer has not ruled out
    (``ruled_out``), the robot has not lingered by (``done``) and the mission has not excluded
    (``excluded(id)`` True: rejected or deferred); None when there is none."""
    keys = {label_key(t) for t in targets}
    xy = np.asarray(robot_xy, dtype=np.float64)[:2]
    best: tuple[float, int] | None = None
    for o in objects:
        oid = int(o.id)
        if label_key(o.label) not in keys or oid in ruled_out or oid in done:
            continue
        if excluded is not None and excluded(oid):
            continue
        gap = footprint_distance(np.asarray(o.box_min), np.asarray(o.box_max), xy)
        if gap <= within_m and (best is None or gap < best[0]):
            best = (gap, oid)
    return None if best is None else best[1]


__all__ = ["undecided_near"]
