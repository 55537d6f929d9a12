"""The view planner: where to stand to see, and so verify, a candidate object.

A camera shows an object when the object's centre falls inside its vertical field of view and
nothing stands on the line between them. This module turns that into places on the robot's map:
the view ring (how far from the footprint the robot should stand for the object's height), the
close distance (within which frames are judged), the other objects' boxes that may hide it (the
blockers), the ``sight`` argument of ``approach_cell``, the point on the line along which the
object was detected, the closer cell and the view cell reached through unknown floor, and the
next move of a verification in progress (``next_view_move``: another view cell, a glance, a
closer cell, a way through unknown floor, or a verdict with its reason).

Pure: grid snapshots, memory objects and anchors, plain numbers and a ``VerifySettings``
section in; world xy points, distances and frozen decisions out. Nothing here reads the mission
context, sends a goal, ticks a tree or talks to an actor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterable, TypeVar

import numpy as np

from hiconav.decisions.config import VerifySettings
from hiconav.decisions.geometry import approach_cell, segments_blocked, wall_clear
from hiconav.geometry import footprint_distance

#: the nearest view ring (m from the footprint): nearer, the robot's body overlaps the object's
MIN_VIEW_RING = 0.3
#: the half field of view never counts as narrower than this (rad), whatever fov_spare_deg asks
MIN_HALF_FOV = math.radians(5.0)

#: the states of a navigation goal after which the robot stands where it is
DONE = ("reached", "failed")

C = TypeVar("C")


box_distance = footprint_distance  # planar distance from a point to a box's footprint


def view_ring(settings: VerifySettings, center_z: float, camera: tuple[float, float] | None) -> float:
    """The ring (m from the footprint) to view an object whose centre is ``center_z`` m up from:
    ``verify_distance`` less ``view_margin``, or farther for an object high above (or far below)
    the camera (``camera``: its height m and vertical field of view rad), so that its centre is
    inside the vertical field of view with ``fov_spare_deg`` to spare, up to ``max_view_ring``.

    A camera sees a band of heights that narrows toward it: an object high on a wall drops out
    of the top of the image as the robot walks up to it, so it is viewed from farther off."""
    base = max(settings.verify_distance - settings.view_margin, MIN_VIEW_RING)
    if camera is None:
        return base
    return max(base, min(nearest_view(settings, center_z, camera), settings.max_view_ring))


def nearest_view(settings: VerifySettings, center_z: float, camera: tuple[float, float] | None) -> float:
    """The nearest distance (m from the footprint) from which the camera holds an object whose
    centre is ``center_z`` m up inside its vertical field of view with ``fov_spare_deg`` to
    spare: ``view_ring``'s need alone, never nearer than ``MIN_VIEW_RING``."""
    if camera is None:
        return MIN_VIEW_RING
    height, vfov = camera
    half = max(0.5 * vfov - math.radians(settings.fov_spare_deg), MIN_HALF_FOV)
    return max(abs(float(center_z) - height) / math.tan(half), MIN_VIEW_RING)


def views_from_here(settings: VerifySettings, robot_xy: np.ndarray, gap: float, ring: float, center: np.ndarray,
                    camera: tuple[float, float] | None, sight_arg: tuple[np.ndarray, float, np.ndarray, np.ndarray] | None,
                    grid: Any, explained: list[tuple[np.ndarray, np.ndarray]] | None,
                    heights: tuple[float, float] | None, excluded: Iterable[np.ndarray] = ()) -> bool:
    """True when the robot, ``gap`` m from the candidate's footprint, already stands where a view
    cell would: no farther than the view ``ring``, no nearer than the camera holds the object
    (``nearest_view``), the line from the camera to the object's ``center`` clear of the boxes
    that may hide it (``sight_arg``, ``sight``'s value) and of walls on the map (``wall_clear``
    with the memory's boxes ``explained``), and not a spot set aside (``excluded``, 0.3 m).

    A robot that comes upon a candidate closer than the view ring (a described instance is
    often confirmed only once the robot stands beside it and sees what is near it) judges it
    from where it stands: a view cell out on the ring, or on the line it was first seen along,
    would take it away from the object and the approach would bring it back."""
    xy = np.asarray(robot_xy, dtype=np.float64)[:2]
    if not nearest_view(settings, float(np.asarray(center)[2]), camera) <= gap <= ring:
        return False
    if any(float(np.hypot(*(xy - np.asarray(e, dtype=np.float64)[:2]))) <= 0.3 for e in excluded):
        return False
    if sight_arg is not None:
        point, height, lo, hi = sight_arg
        if segments_blocked(np.array([[xy[0], xy[1], float(height)]]), point, lo, hi)[0]:
            return False
    if grid is not None and explained is not None:
        clear = wall_clear(grid, xy[None, :], np.asarray(center, dtype=np.float64)[:2], explained, heights=heights)
        if not bool(clear[0]):
            return False
    return True


def close_distance(settings: VerifySettings, ring: float) -> float:
    """Within this distance (m) of the footprint the robot judges frames of the object viewed
    from ``ring``: the farther of ``verify_distance`` and the ring (plus ``close_ring_gap``),
    plus ``close_margin``."""
    return max(settings.verify_distance, ring + settings.close_ring_gap) + settings.close_margin


def blockers(objects: Iterable[Any], box_min: np.ndarray, box_max: np.ndarray, skip: set[int],
             settings: VerifySettings) -> tuple[np.ndarray, np.ndarray] | None:
    """3D boxes (lo, hi), each (m, 3) world metres, of the memory ``objects`` that may hide the
    object with box ``box_min``/``box_max`` (3,) world from a camera, shrunk by
    ``blocker_shrink`` a side horizontally; None when there are none.

    Never a blocker: the ids in ``skip`` (the object's own node and the target-labelled nodes
    that support it), and an object whose footprint overlaps the object's own grown by
    ``stand_margin``: what the object stands on or hangs from (the line to a laptop's centre
    grazes the top of the desk box under it)."""
    grow = settings.stand_margin
    c_lo, c_hi = np.asarray(box_min)[:2] - grow, np.asarray(box_max)[:2] + grow
    boxes = [(np.asarray(o.box_min, dtype=np.float64), np.asarray(o.box_max, dtype=np.float64))
             for o in objects if int(o.id) not in skip]
    boxes = [b for b in boxes if not (np.all(b[0][:2] <= c_hi) and np.all(b[1][:2] >= c_lo))]
    if not boxes:
        return None
    shrink = np.array([settings.blocker_shrink, settings.blocker_shrink, 0.0])
    lo = np.array([b[0] for b in boxes]) + shrink
    hi = np.array([b[1] for b in boxes]) - shrink
    keep = np.all(hi > lo, axis=1)
    return (lo[keep], hi[keep]) if keep.any() else None


def sight(center: np.ndarray, camera: tuple[float, float] | None,
          hiding: tuple[np.ndarray, np.ndarray] | None) -> tuple[np.ndarray, float, np.ndarray, np.ndarray] | None:
    """``approach_cell``'s ``sight`` argument: (the object's centre (3,) world, the camera
    height m, the blockers' lo and hi (m, 3)), or None (no camera known, or nothing may hide
    the object: any cell sees it)."""
    if camera is None or hiding is None:
        return None
    return np.asarray(center, dtype=np.float64), camera[0], hiding[0], hiding[1]


def seen_from(center: np.ndarray, anchors: Iterable[Any], anchor_ids: set[int], distance: float) -> np.ndarray | None:
    """The point (2,) world ``distance`` from the object's centre (3,) world toward the camera
    of the anchor among ``anchor_ids`` (the anchors that observed it) whose camera stood
    nearest that distance; None when no such anchor is known.

    The line along which an object was detected was clear: a cell on it, nearer, most likely
    sees the object too, where the free cell nearest the robot may stand behind furniture."""
    if not anchor_ids:
        return None
    centre = np.asarray(center, dtype=np.float64)[:2]
    best, best_err = None, math.inf
    for a in anchors:
        if int(a.id) not in anchor_ids:
            continue
        cam = np.asarray(a.T_world_cam, dtype=np.float64)[:2, 3]
        d = float(np.hypot(*(cam - centre)))
        if d > 1e-6 and abs(d - distance) < best_err:
            best, best_err = cam, abs(d - distance)
    if best is None:
        return None
    u = (best - centre) / float(np.hypot(*(best - centre)))
    return centre + u * min(float(np.hypot(*(best - centre))), distance)


def seen_from_node(center: np.ndarray, memory: Any, node: Any, distance: float) -> np.ndarray | None:
    """``seen_from`` for the memory object ``node`` (None: unknown) with the anchors of the
    ``memory`` snapshot (None: none) that observed it (its ``anchor_ids``)."""
    anchors = getattr(memory, "anchors", ()) or ()
    return seen_from(center, anchors, set(int(i) for i in getattr(node, "anchor_ids", ()) or ()), distance)


def may_switch(settings: VerifySettings, switches: int, judging: bool) -> bool:
    """Whether a nearer candidate may replace the one under way: ``switch_margin`` is set, the
    robot is still on its way (``judging``: it is close, or a frame was judged), and fewer than
    ``max_switches`` switches were made (``switches``) in this verification: two candidates the
    way to each of which passes nearer the other must not trade places for ever."""
    return not (settings.switch_margin <= 0.0 or judging or switches >= settings.max_switches)


def nearer_candidate(here: float, others: Iterable[tuple[float, C]], settings: VerifySettings) -> C | None:
    """The candidate to verify instead of the one under way, ``here`` m from the robot: among
    ``others`` ((distance m, candidate) pairs, in the mission's order; the first of equals
    wins), the nearest, when it is ``switch_margin`` or more nearer; else None.

    A candidate is chosen when the robot first sees it, and a nearer one often shows on the
    way: the nearer one is the cheaper to judge, and the other stays a candidate for later."""
    gap, best = min(others, key=lambda dc: dc[0], default=(math.inf, None))
    return best if gap <= here - settings.switch_margin else None


def closer_cell(grid: Any, box_min: np.ndarray, box_max: np.ndarray, robot_xy: np.ndarray, gap: float, close: float,
                settings: VerifySettings, furniture: list[tuple[np.ndarray, np.ndarray]] | None,
                heights: tuple[float, float] | None) -> np.ndarray | None:
    """With no view cell reachable on the map: the reachable free cell (world xy) nearest the
    object's box (past walls where one sees it), ``closer_min_gain`` m nearer it than the robot
    stands (``gap`` m off; frames count within ``close`` m); None when the robot is about as
    near already, or no such cell is known.

    An object seen from afar on a young map has unknown floor around it: walking up to it, as
    a person would, shows that floor, where a deferral sends the robot exploring elsewhere."""
    reach = gap - settings.closer_min_gain
    if reach <= close - settings.close_margin:
        return None
    return approach_cell(grid, box_min, box_max, robot_xy, reach, None, furniture=furniture,
                         box_weight=settings.closer_box_weight, wall_heights=heights)


def through_unknown_cell(grid: Any, box_min: np.ndarray, box_max: np.ndarray, robot_xy: np.ndarray, ring: float,
                         excluded: list[np.ndarray], furniture: list[tuple[np.ndarray, np.ndarray]] | None,
                         view: tuple[np.ndarray, float, np.ndarray, np.ndarray] | None,
                         heights: tuple[float, float] | None) -> np.ndarray | None:
    """A view cell (world xy, free on the map, clear of walls toward the object, ``view``: the
    ``sight`` argument) that a path crossing unknown floor may reach; None when there is none.

    Furniture between the robot and an object can cut the free floor by the object from the
    robot's; the way round, through a room the camera has not yet seen, is what a person
    takes: the navigator replans as the floor shows, and a way that turns out closed fails."""
    return approach_cell(grid, box_min, box_max, robot_xy, ring, excluded, furniture=furniture, strict_walls=True,
                         sight=view, wall_heights=heights, connected=False)


def may_try_unknown(settings: VerifySettings, moves: int, n_obs: int) -> bool:
    """A way through unknown floor is worth trying: fewer than ``unknown_moves`` tried, for an
    object observed ``unknown_min_observations`` times or more (the way is a guess, and a
    one-frame box is not worth one)."""
    return moves < settings.unknown_moves and int(n_obs) >= settings.unknown_min_observations


def fallback_cell(kind: str, settings: VerifySettings, grid: Any, box_min: np.ndarray, box_max: np.ndarray,
                  robot_xy: np.ndarray, *, gap: float, ring: float, excluded: list[np.ndarray], moves: int, n_obs: int,
                  furniture: list[tuple[np.ndarray, np.ndarray]] | None,
                  view: tuple[np.ndarray, float, np.ndarray, np.ndarray] | None,
                  heights: tuple[float, float] | None) -> np.ndarray | None:
    """The cell (world xy) of a ``next_view_move`` fallback ``kind``: "closer" (``closer_cell``,
    fewer than ``closer_moves`` made: ``moves``) or "unknown" (``through_unknown_cell``, while
    ``may_try_unknown``); None when that move is spent or finds no cell. ``gap``: the robot's
    distance (m) to the box; ``ring``: the view ring; ``view``: the ``sight`` argument."""
    if kind == "closer":
        if moves >= settings.closer_moves:
            return None
        return closer_cell(grid, box_min, box_max, robot_xy, gap, close_distance(settings, ring), settings,
                           furniture, heights)
    if kind == "unknown" and may_try_unknown(settings, moves, n_obs):
        return through_unknown_cell(grid, box_min, box_max, robot_xy, ring, excluded, furniture, view, heights)
    return None


@dataclass(frozen=True)
class ViewMove:
    """What a verification in progress does next.

    ``tries``: the moves to try in order until one goes: "view" (a view cell), "closer" (a
    closer cell), "unknown" (a view cell through unknown floor), "glance" (look left or right of
    the object from where the robot stands; always goes) and "remap" (defer until the map
    around the object grows; always goes where a map and a pose are known); empty: carry on.
    ``reason``: set when the verification ends here, deferred with that reason.
    ``exclude_cell``: the view cell the robot went to is tried no more.
    ``reset_unseen``: the frames that could not show the object count afresh (a new cell).
    ``another_cell``: the "view" try is a move to another cell than the one that showed nothing.
    ``stop_closing``: the goal sent next is not a closer cell unless "closer" goes.
    """

    tries: tuple[str, ...] = ()
    reason: str | None = None
    exclude_cell: bool = False
    reset_unseen: bool = False
    another_cell: bool = False
    stop_closing: bool = False


def stall_matters(close: bool, sent: bool, state: str) -> bool:
    """Whether ``next_view_move`` reads the stall clock this tick (``close``: frames are judged;
    ``sent``: a goal was sent; ``state``: its navigation state): on the way, always; close,
    only while a goal is in flight. Reading it restarts it when the robot made progress, so
    it is read only when it decides something."""
    return not close or (sent and state not in DONE)


def next_view_move(settings: VerifySettings, *, close: bool, sent: bool, state: str, unseen: int, excluded: int,
                   has_cell: bool, closing: bool, stalled: bool) -> ViewMove:
    """The next move of a verification: ``close`` (frames are judged), ``sent`` (a goal was
    sent), ``state`` (its navigation state), ``unseen`` (frames since the last view cell that
    could not show the object), ``excluded`` (view cells tried and set aside), ``has_cell`` (a
    cell was sent), ``closing`` (the goal in flight is a closer cell), ``stalled`` (no progress
    toward the goal for ``stall_s``; read only where ``stall_matters``).

    - Close and there at a closer cell (no view cell was on the map when it was sent), after
      ``reposition_after`` frames that could not show the object either: a view cell on the map
      grown since, else a way through unknown floor, else a deferral until the map around the
      object grows (which draws exploration toward it, ``exploration.utility.reach_sigma``);
      glancing at an object behind a wall from the wrong side of it shows nothing.
    - Close and there, after ``reposition_after`` frames that could not show the object: the
      object is hidden from this cell (behind furniture the memory now knows, or out of the
      field of view): another view cell, and after ``view_cells`` cells a deferral ("no view
      cell shows it") instead of glancing at a hidden object until the timeout.
    - Close and there: glance left and right of the object so that new frames arrive.
    - On the way and stalled: whatever blocks the way (a doorway the robot cannot pass) blocks
      the other cells by it too: deferred ("no progress toward a view cell").
    - No goal, or the goal ended or stalled: the view cell it was (not a closer cell) is set
      aside, and a new view cell is tried, then a closer cell, then a way through unknown floor,
      then a deferral until the map around the object grows."""
    there = close and state in DONE
    if there and unseen >= settings.reposition_after:
        if closing and has_cell:
            # a closer cell (no view cell was on the map) that shows nothing either: the object
            # lies behind what the robot now sees; a view cell on the grown map, a way through
            # unknown floor, or a deferral until the map around it grows, not glances at it
            return ViewMove(tries=("view", "unknown", "remap"), exclude_cell=True, reset_unseen=True,
                            stop_closing=True)
        if excluded >= settings.view_cells:
            return ViewMove(reason="no view cell shows it")
        if has_cell:
            return ViewMove(tries=("view", "glance"), exclude_cell=True, reset_unseen=True, another_cell=True)
    if there:
        return ViewMove(tries=("glance",))
    if not close and stalled:
        return ViewMove(reason="no progress toward a view cell")
    if not sent or state in DONE or stalled:
        exclude = sent and has_cell and not closing
        view = ("view",) if excluded + int(exclude) <= settings.view_cells else ()
        return ViewMove(tries=view + ("closer", "unknown", "remap"), exclude_cell=exclude, stop_closing=True)
    return ViewMove()


__all__ = ["DONE", "MIN_HALF_FOV", "MIN_VIEW_RING", "ViewMove", "blockers", "box_distance", "close_distance",
           "closer_cell", "fallback_cell", "may_switch", "may_try_unknown", "nearer_candidate", "nearest_view",
           "next_view_move", "seen_from",
           "seen_from_node", "sight",
           "stall_matters", "through_unknown_cell", "view_ring", "views_from_here"]
