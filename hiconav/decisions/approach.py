"""The approach planner: how far the robot is from its target, which rings to look for a cell on,
whether to step straight in, where a creep goes, and when the approach is done.

``Approach`` (``trees/behaviours/approach.py``) polls these and posts the goals they name. Pure:
a grid snapshot, the robot's xy, the target's box and points, memory boxes and a
``decisions.approach`` section (``ApproachSettings``) in; distances, ring orders, goal points and
verdicts out. Nothing here ticks, sends goals or reads the mission context.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from hiconav.decisions.config import ApproachSettings
from hiconav.decisions.geometry import facing, wall_clear
from hiconav.geometry import rounded_box_distance
from hiconav.mapping.occupancy import lethal_mask
from hiconav.types import Goal, wrap_angle


class Gap(NamedTuple):
    """The robot's planar distance to the object (m) and the object's point it is measured to,
    ``near`` (2,) world xy."""

    distance: float
    near: np.ndarray


class RingTry(NamedTuple):
    """One cell search of the ring order: the ring (m from the footprint), whether cells must see
    the footprint past every wall (``strict``), and ``approach_cell``'s ``box_weight``."""

    strict: bool
    ring: float
    box_weight: float


def gap(robot_xy: np.ndarray, box_min: np.ndarray, box_max: np.ndarray, points: Any,
        settings: ApproachSettings) -> Gap:
    """The robot's distance from ``robot_xy`` (2,) world to the object by ``settings.measure``: to
    its box's footprint (``box_min``/``box_max`` (3,) world) with the corners rounded by
    ``settings.corner_radius`` (``near``: the box's nearest point), or, with
    ``points`` (N, 3) world and at least ``min_points`` of them, to its points'
    ``points_quantile`` planar distance.

    An axis-aligned box reaches past a round or slanted object at its corners, so from the box's
    diagonal the box is nearer than anything of the object; the points are what the camera saw
    of it, and their lowest quantile drops the few stray points nearer than the object."""
    robot = robot_xy
    lo, hi = np.asarray(box_min, dtype=np.float64), np.asarray(box_max, dtype=np.float64)
    if settings.measure == "points" and points is not None:
        pts = np.asarray(points, dtype=np.float64)
        if pts.ndim == 2 and len(pts) >= settings.min_points:
            d = np.hypot(pts[:, 0] - robot[0], pts[:, 1] - robot[1])
            k = int(settings.points_quantile * (len(d) - 1))
            i = int(np.argpartition(d, k)[k])
            return Gap(float(d[i]), pts[i, :2].copy())
    near = np.clip(robot, lo[:2], hi[:2])
    return Gap(float(rounded_box_distance(robot[0], robot[1], lo, hi, settings.corner_radius)), near)


#: the spacing of a last resort's rings beyond the usual ones (m; ``rings(wide=True)``)
WIDE_STEP_M = 0.5


def rings(settings: ApproachSettings, wide: bool = False) -> list[float]:
    """The rings to look for an approach cell on (m from the footprint), inner first.

    Aim well inside the distance first; near walls and furniture the inflated map may only have
    free cells farther out, so widen the ring up to the distance itself. Furniture in front of
    the target (a sofa under a wall-mounted tv) can leave no free cell within the distance: then
    settle for the closest ring that has one, up to ``max_distance``, and stop there rather than
    give up (the success check is the judge, not this estimate). ``wide``: a last resort
    (``hiconav.decisions.last_resort``) goes on every ``WIDE_STEP_M`` out to ``last_resort_m``."""
    distance, inner, low = settings.distance, settings.inner_margin, settings.min_ring
    out = sorted({max(distance - inner, low), max(distance - min(inner, settings.second_margin), low), distance})
    out += [r for r in settings.settle_rings if distance < r <= settings.max_distance]
    r = max(out) + WIDE_STEP_M
    while wide and r <= settings.last_resort_m + 1e-9:
        out.append(round(r, 6))
        r += WIDE_STEP_M
    return out


def ring_order(settings: ApproachSettings, wide: bool = False) -> list[RingTry]:
    """The order of cell searches: cells that see the footprint past every wall on the rings out
    to ``strict_within`` (a cell behind a wall is never by the target; one a little farther that
    sees it may be); then any cell within the distance; then the rest, strict first. Beyond the
    distance a ring's cell is the one nearest the object, not the robot (``settle_box_weight``).
    ``wide``: with a last resort's rings (``rings``)."""
    distance, all_rings = settings.distance, rings(settings, wide)
    order = [(True, r) for r in all_rings if r <= max(distance, settings.strict_within)]
    order += [(False, r) for r in all_rings if r <= distance]
    order += [(strict, r) for strict in (True, False) for r in all_rings
              if r > distance and (strict, r) not in order]
    weight = settings.settle_box_weight
    return [RingTry(strict, ring, weight if ring > distance else 0.0) for strict, ring in order]


def straight_way_in(grid: Any, robot_xy: np.ndarray, box_min: np.ndarray, box_max: np.ndarray, measured: Gap,
                    settings: ApproachSettings, furniture: list[tuple[np.ndarray, np.ndarray]],
                    heights: tuple[float, float] | None) -> bool:
    """True when the robot at ``robot_xy`` (2,) world, ``measured`` from the object (box (3,)
    world) and at most ``straight_within`` beyond the distance, may step straight toward the
    object's nearest point: the way there is clear on the map (no cell the robot centre may not
    enter, nor an occupied one, up to ``straight_step``
    past the ring; the robot's own cell may lie in the margin of what it stands by), and the ring
    point on that line sees the footprint's centre past every wall (``wall_clear``, ``furniture``
    (lo, hi) boxes see-through, ``heights`` as there).

    A robot that viewed the object from a ring a little wider than the distance stands facing
    it; the ring cell nearest the robot and in front of the box's middle lies off that line, and
    reaching it takes steps and a turn where one step straight in would do. From a point that
    does not see the footprint's centre (an object's far end, a painting along its wall) the ring
    cells decide."""
    robot = robot_xy
    lo, hi = np.asarray(box_min, dtype=np.float64), np.asarray(box_max, dtype=np.float64)
    gap_m, near = measured
    distance = settings.distance
    if gap_m <= distance or gap_m > distance + settings.straight_within:
        return False
    u = (near - robot) / gap_m
    run = gap_m - distance + settings.straight_step  # a step may end up to a step inside the ring
    n = max(int(math.ceil(run / (0.5 * grid.resolution))), 2)
    pts = robot[None, :] + np.linspace(0.0, run, n)[:, None] * u[None, :]
    res, origin = float(grid.resolution), np.asarray(grid.origin, dtype=np.float64)
    rows = np.floor((pts[:, 1] - origin[1]) / res).astype(np.int64)
    cols = np.floor((pts[:, 0] - origin[0]) / res).astype(np.int64)
    state = np.asarray(grid.state)
    h, w = state.shape
    if not np.all((rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)):
        return False
    blocked = lethal_mask(grid)[rows, cols] | (state[rows, cols] == 1)
    if blocked[1:].any():
        return False
    ring_xy = robot + (gap_m - distance) * u
    centre = 0.5 * (lo[:2] + hi[:2])
    return bool(wall_clear(grid, ring_xy[None, :], centre, [(lo, hi), *furniture], heights=heights)[0])


def creep_goal(measured: Gap, object_id: int, settings: ApproachSettings) -> Goal | None:
    """The creep's goal: a ``straight`` goal through unknown floor (the robot steps toward it until
    a step is blocked, without a plan on the map's margins) to the object's nearest point,
    reached within the distance (a step may end nearer); None when the robot is already within it.

    The camera sees no floor near the robot, so the floor by an object is often unknown and no
    approach cell lies there; a robot settled on a wider ring, or stopped by the navigator's
    tolerance short of its cell's ring, steps straight toward the object through that floor until
    a step is blocked, as a real robot inches closer. The goal is the object's point itself, not
    a point short of it: a point short of the box may lie next to the robot and be reached at once."""
    if measured.distance <= settings.distance:
        return None
    near = measured.near
    return Goal(float(near[0]), float(near[1]), None, settings.distance, "approach", object_id,
                through_unknown=True, straight=True)


def face_goal(x: float, y: float, centre: np.ndarray, object_id: int, settings: ApproachSettings) -> Goal:
    """A turn in place at (``x``, ``y``) world toward the object's ``centre``: where no approach cell
    is found and the robot is already close, or where a creep ended."""
    return Goal(x, y, facing(np.array([x, y]), centre), settings.face_tolerance, "look", object_id)


def without_cell(gap_m: float, wide: bool, turned: bool, crept: bool, settings: ApproachSettings) -> str | None:
    """What the approach does, ``gap_m`` from the object, where no ring had a cell: "creep" (a
    ``creep_goal``), "face" (a ``face_goal``) or None (no reachable approach cell). A last resort
    (``wide``; ``hiconav.decisions.last_resort``) stops where it stands: a creep toward the object
    first when beyond the distance, then a turn to face it. Otherwise only a robot already within
    the distance turns to face it, once (``turned``)."""
    if wide and not (turned or crept):
        return "creep" if gap_m > settings.distance and settings.creep else "face"
    if gap_m <= settings.distance and not turned:
        return "face"
    return None


def settled_beyond(ring: float, settings: ApproachSettings) -> bool:
    """Done on a ring wider than the distance: creep on toward the object (``creep``)."""
    return ring > settings.distance and settings.creep


def creeps_on(ring: float, settings: ApproachSettings) -> bool:
    """At a cell of a ring out to ``creep_within`` but not within its ring: step straight toward
    the object rather than drive to another cell. Not on the wider settle rings, where a blocked
    creep would end far off and another cell may yet come nearer."""
    return ring <= max(settings.distance, settings.creep_within) and settings.creep


def done(robot_xy: np.ndarray, yaw: float, gap_m: float, ring: float, cell: np.ndarray | None, turned: bool,
         centre: np.ndarray, settings: ApproachSettings) -> bool:
    """The approach is done: the robot at ``robot_xy`` (2,) world heading ``yaw`` (rad) is within
    the distance (or the ``ring`` settled for) of the object (``gap_m``), facing its ``centre``
    within ``facing_tolerance_deg``, and at the approach ``cell`` ((2,) world, ``arrive_radius``),
    or, where no cell was found, ``turned`` toward it in place.

    Passing within the distance on the way to a cell is not arriving: the cell lies in front of
    the object, the first point within the distance may be off its end. Nor is standing anywhere
    before a cell was chosen."""
    close = gap_m <= max(settings.distance, ring)
    arrived = turned if cell is None else \
        math.hypot(robot_xy[0] - cell[0], robot_xy[1] - cell[1]) <= settings.arrive_radius
    err = abs(wrap_angle(facing(robot_xy, centre) - yaw))
    return close and arrived and math.degrees(err) <= settings.facing_tolerance_deg


__all__ = ["Gap", "RingTry", "WIDE_STEP_M", "creep_goal", "creeps_on", "done", "face_goal", "gap", "ring_order",
           "rings", "settled_beyond", "straight_way_in", "without_cell"]
