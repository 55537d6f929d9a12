"""Spatial relations between objects as a person sees them: on, next to, near, under, in a room.

Each object is a ``Thing``: its category, its planar box (centre xy, size along the box's own
axes, yaw) and its vertical extent. The predicates are pure functions of two things (or of a
point and a room polygon) and return a bool or a distance; they hold the thresholds in one place,
so that a text-navigation description written from the ground truth (``hiconav.sim.task_episodes``)
and its grounding on the memory graph read the words the same way.

Frames: world metres, x east, y north, z up; yaw in radians, counter-clockwise from +x.
This module must not read files, know a data set or hold state.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

#: m: "next to" / "beside" holds up to this planar gap between the two boxes
NEXT_TO = 1.0
#: m: "near" / "close to" holds up to this planar gap
NEAR = 2.0
#: m: "on" holds when the upper box's bottom lies within this of the lower box's top
ON_TOLERANCE = 0.10
#: m: "on" holds when the upper box's centre lies over the lower box grown by this
ON_MARGIN = 0.05
#: m: "under" holds when the upper box's bottom is at most this below the lower box's top
UNDER_TOLERANCE = 0.05
#: m: boxes that overlap in plan by less than this along some axis only touch
OVERLAP_MARGIN = 0.01

#: The relations ``holds`` knows, by their canonical names (``decompose.RELATIONS`` spelling).
RELATIONS: tuple[str, ...] = ("on", "next to", "near", "under")


@dataclass(frozen=True)
class Thing:
    """An object for the relation predicates: category, planar box and vertical extent.

    center: (x, y) world m of the box centre; size: (sx, sy) m along the box's own x and y;
    yaw: rad, the box's x axis from world +x; z0, z1: bottom and top heights (m).
    """

    category: str
    center: tuple[float, float]
    size: tuple[float, float]
    yaw: float
    z0: float
    z1: float

    def corners(self) -> np.ndarray:
        """(4, 2) world xy of the box's footprint corners, counter-clockwise."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        hx, hy = self.size[0] / 2.0, self.size[1] / 2.0
        local = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
        return local @ np.array([[c, s], [-s, c]]) + np.asarray(self.center, dtype=np.float64)


def _axes(a: Thing, b: Thing) -> list[np.ndarray]:
    return [np.array([math.cos(t.yaw), math.sin(t.yaw)]) for t in (a, b)] + \
        [np.array([-math.sin(t.yaw), math.cos(t.yaw)]) for t in (a, b)]


def plan_overlap(a: Thing, b: Thing, margin: float = OVERLAP_MARGIN) -> bool:
    """Whether the two footprints overlap in plan by more than ``margin`` m along every
    separating axis (boxes that only touch do not overlap)."""
    pa, pb = a.corners(), b.corners()
    for axis in _axes(a, b):
        ra, rb = pa @ axis, pb @ axis
        if min(ra.max(), rb.max()) - max(ra.min(), rb.min()) <= margin:
            return False
    return True


def _point_segment(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    dx, dy = bx - ax, by - ay
    dd = dx * dx + dy * dy
    t = 0.0 if dd == 0.0 else min(max(((px - ax) * dx + (py - ay) * dy) / dd, 0.0), 1.0)
    return math.hypot(px - ax - t * dx, py - ay - t * dy)


def planar_gap(a: Thing, b: Thing) -> float:
    """Shortest planar distance (m) between the two footprints; 0 where they touch or overlap."""
    if plan_overlap(a, b, margin=0.0):
        return 0.0
    pa, pb = a.corners().tolist(), b.corners().tolist()
    best = math.inf
    # disjoint convex polygons: the shortest distance runs from a corner of one to an edge of the other
    for p, q in ((pa, pb), (pb, pa)):
        for x, y in p:
            for k in range(4):
                (ax, ay), (bx, by) = q[k - 1], q[k]
                best = min(best, _point_segment(x, y, ax, ay, bx, by))
    return best


def gap_lower_bound(a: Thing, b: Thing) -> float:
    """A cheap lower bound of ``planar_gap``: centre distance less both half-diagonals."""
    return math.hypot(a.center[0] - b.center[0], a.center[1] - b.center[1]) \
        - 0.5 * math.hypot(a.size[0], a.size[1]) - 0.5 * math.hypot(b.size[0], b.size[1])


def is_next_to(a: Thing, b: Thing, within: float = NEXT_TO) -> bool:
    """"a next to b" / "a beside b": the footprints lie at most ``within`` m apart."""
    return gap_lower_bound(a, b) <= within and planar_gap(a, b) <= within


def is_near(a: Thing, b: Thing, within: float = NEAR) -> bool:
    """"a near b" / "a close to b": the footprints lie at most ``within`` m apart."""
    return gap_lower_bound(a, b) <= within and planar_gap(a, b) <= within


def is_on(a: Thing, b: Thing) -> bool:
    """"a on b": a's bottom lies at b's top (within ``ON_TOLERANCE``) and a's centre over b's
    footprint (grown by ``ON_MARGIN``)."""
    if abs(a.z0 - b.z1) > ON_TOLERANCE:
        return False
    c, s = math.cos(b.yaw), math.sin(b.yaw)
    dx, dy = a.center[0] - b.center[0], a.center[1] - b.center[1]
    lx, ly = c * dx + s * dy, -s * dx + c * dy
    return abs(lx) <= b.size[0] / 2.0 + ON_MARGIN and abs(ly) <= b.size[1] / 2.0 + ON_MARGIN


def is_under(a: Thing, b: Thing) -> bool:
    """"a under b" / "a below b": b's box lies above a's (b's bottom at least a's top less
    ``UNDER_TOLERANCE``) and the two overlap in plan."""
    return b.z0 >= a.z1 - UNDER_TOLERANCE and plan_overlap(a, b)


def holds(relation: str, a: Thing, b: Thing) -> bool:
    """Whether ``a <relation> b`` holds; ``relation`` is one of ``RELATIONS``."""
    if relation == "on":
        return is_on(a, b)
    if relation == "next to":
        return is_next_to(a, b)
    if relation == "near":
        return is_near(a, b)
    if relation == "under":
        return is_under(a, b)
    raise ValueError(f"unknown relation {relation!r}; known: {', '.join(RELATIONS)}")


def in_polygon(xy: Sequence[float], polygon: np.ndarray) -> bool:
    """Whether the point ``xy`` lies inside ``polygon`` ((N, 2) world xy; even-odd rule). A point
    on the boundary counts as inside the polygon on its +x / +y side (tested 1 um up and right),
    as ``hiconav.sim.house.rasterize_polygon`` assigns cells: two rooms never share a point."""
    x, y = float(xy[0]) + 1e-6, float(xy[1]) + 1e-6
    pts = np.asarray(polygon, dtype=np.float64)
    inside = False
    n = len(pts)
    for i in range(n):
        x0, y0 = pts[i - 1]
        x1, y1 = pts[i]
        if (y0 > y) != (y1 > y):
            xc = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
            if x < xc:
                inside = not inside
    return inside


def polygon_distance(xy: Sequence[float], polygon: np.ndarray) -> float:
    """Planar distance (m) from ``xy`` to ``polygon`` ((N, 2)); 0 inside it."""
    if in_polygon(xy, polygon):
        return 0.0
    p = np.asarray(xy, dtype=np.float64)[:2]
    pts = np.asarray(polygon, dtype=np.float64)
    best = math.inf
    for i in range(len(pts)):
        a, b = pts[i - 1], pts[i]
        d = b - a
        t = 0.0 if not d.any() else float(np.clip((p - a) @ d / (d @ d), 0.0, 1.0))
        best = min(best, float(np.linalg.norm(p - (a + t * d))))
    return best
