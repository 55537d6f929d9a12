"""Linger: look around an undecided instance of the target's category that the robot comes upon.

A described instance ("the chair next to the fridge") is confirmed only by the reasoning layer,
on what the memory holds of the instance and of what stands around it. A robot that drives past
an instance of the category, close by, before the memory has seen enough of it or of its
neighbours (its related object not yet in view, too few observations, its room not yet clear),
drives on with the exploration plan, and when the verdict comes, a few seconds later, drives back.
Turning in place beside it instead shows the memory the instance and its surroundings, from
where a related object next to it would be seen, at the cost of a few turns and no path.

An instance described as below something ("the bed below the painting") is stepped back from
after the turns (``step_back_goal``): beside it the camera's view stops below what hangs over it.

Pure: plain memory objects and the grid in, an object id or a goal out. The Explore behaviour
sends the turns and the step back.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from typing import Any

import math

import numpy as np

from hiconav.decisions.geometry import approach_cell
from hiconav.geometry import footprint_distance
from hiconav.types import label_key

# the words that put what the description names above the described instance
BENEATH_WORDS = ("below", "under", "beneath", "underneath")
# m: the centre of what hangs or stands above furniture (a painting, a wall TV, a lamp on a desk)
# is seldom higher than this
ABOVE_CENTRE_M = 1.8


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


def beneath(relations: Iterable[Any], targets: Iterable[str]) -> bool:
    """True when the instruction places the target below something ("the bed below the
    painting"): from beside the instance that thing is above the camera's view."""
    keys = {label_key(t) for t in targets}
    return any(label_key(str(r[0])) in keys and str(r[1]).strip().lower() in BENEATH_WORDS for r in relations)


def step_back_ring(camera: tuple[float, float] | None, spare_deg: float) -> float:
    """The distance (m from the footprint) from which the camera (height m, vertical field of
    view rad) holds a point ``ABOVE_CENTRE_M`` up inside its view with ``spare_deg`` to spare;
    0 without a camera."""
    if camera is None:
        return 0.0
    height, vfov = camera
    half = 0.5 * vfov - math.radians(spare_deg)
    if half <= math.radians(5.0):
        return 0.0
    return max(ABOVE_CENTRE_M - height, 0.0) / math.tan(half)


def step_back_cell(grid: Any, box_min: np.ndarray, box_max: np.ndarray, robot_xy: np.ndarray,
                   ring: float) -> np.ndarray | None:
    """A free cell connected to the robot about ``ring`` m from the footprint, on the robot's side
    of it (the point ``ring`` out from the footprint's centre through the robot is preferred),
    from which what stands above the instance is in view; None when the map has none at least
    ``ring`` - 0.5 m out."""
    lo, hi = np.asarray(box_min, float), np.asarray(box_max, float)
    centre = 0.5 * (lo[:2] + hi[:2])
    xy = np.asarray(robot_xy, float)[:2]
    d = xy - centre
    n = float(np.hypot(*d))
    u = d / n if n > 1e-6 else np.array([1.0, 0.0])
    half = 0.5 * float(np.hypot(*(hi[:2] - lo[:2])))
    want = centre + u * (half + ring)
    cell = approach_cell(grid, lo, hi, xy, ring + 0.3, prefer_xy=want, prefer_weight=4.0)
    if cell is None or footprint_distance(lo, hi, cell) < ring - 0.5:
        return None
    return cell


def step_back_goal(relations: Iterable[Any], targets: Iterable[str], box_min: np.ndarray, box_max: np.ndarray,
                   robot_xy: np.ndarray, grid: Any, camera: tuple[float, float] | None,
                   spare_deg: float) -> tuple[float, float, float] | None:
    """Where to stand, and facing where, after the turns beside an undecided instance (box
    ``box_min`` / ``box_max``) that the instruction places below something: (x, y, yaw) world on
    ``step_back_cell`` at ``step_back_ring``, facing the footprint's centre; None when the
    instruction says no such thing, or the camera or the map leaves no such place.

    The class: "the bed below the painting", "the toilet under the painting". Beside the
    instance, where the turns leave the robot, the camera's view stops well below a painting or
    a wall TV, so the memory never maps the related object over it and the verdict stays
    "unknown" while the robot drives on; from farther back the camera holds both."""
    if not beneath(relations, targets):
        return None
    ring = step_back_ring(camera, spare_deg)
    if ring <= 0.0:
        return None
    cell = step_back_cell(grid, box_min, box_max, robot_xy, ring)
    if cell is None:
        return None
    c = 0.5 * (np.asarray(box_min, float)[:2] + np.asarray(box_max, float)[:2])
    return float(cell[0]), float(cell[1]), math.atan2(c[1] - cell[1], c[0] - cell[0])


__all__ = ["ABOVE_CENTRE_M", "BENEATH_WORDS", "beneath", "step_back_cell", "step_back_goal", "step_back_ring",
           "undecided_near"]
