"""Where to stand to view or reach an object: approach cells on the robot's map, the 2D line
of sight past walls, and whether a memory anchor's camera could show a point.

Pure geometry on grid snapshots, memory boxes and anchors, used by the mission behaviours
(``VerifyTarget``, ``Approach``); nothing here ticks, sends goals or reads the context.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from hiconav.geometry import rounded_box_distance
from hiconav.mapping.occupancy import lethal_mask


def approach_cell(grid: Any, box_min: np.ndarray, box_max: np.ndarray, robot_xy: np.ndarray,
                  max_distance: float, exclude: list[np.ndarray] | None = None,
                  tight: bool = False, centre_weight: float = 0.0, prefer_xy: np.ndarray | None = None,
                  prefer_weight: float = 0.0, sight: tuple[np.ndarray, float, np.ndarray, np.ndarray] | None = None,
                  furniture: list[tuple[np.ndarray, np.ndarray]] | None = None,
                  strict_walls: bool = False, box_weight: float = 0.0,
                  wall_heights: tuple[float, float] | None = None, connected: bool = True,
                  prefer_roomy: bool = True, corner_radius: float = 0.0,
                  path_cost: bool = False) -> np.ndarray | None:
    """A free, non-inflated grid cell connected to the robot within ``max_distance`` of a footprint.

    grid: snapshot with ``state`` (H, W) int8 (0 free), ``inflated`` (H, W) bool, ``origin`` (2,),
    ``resolution``; box_min / box_max: (3,) world metres (only x, y used); robot_xy: (2,) world.
    ``tight``: the robot may reach the cell through passages only the robot radius clears (see
    ``OccupancyGrid.lethal``), and such cells count when no cell keeps the inflation margin.
    Returns the (2,) world xy of the chosen cell centre, or None: the cell with the least
    distance to the robot plus ``centre_weight`` times its distance to the footprint's centre.
    With a weight, the cell lies in front of the object's middle rather than off one of its
    ends: from a cell near the end of a painting 0.9 m long the robot sees it at a grazing
    angle past its wall, and such a cell is no view point of it.
    ``prefer_xy`` adds ``prefer_weight`` times the cell's distance to that point (a place the
    object was seen from; see ``VerifyTarget``). ``sight`` = (point (3,), camera height, lo,
    hi (m, 3)): when some candidate cells see the point over the boxes (``segments_blocked``
    from the camera above the cell), only those are kept. ``furniture`` (memory objects' (lo,
    hi) boxes): when some candidate cells see the footprint's centre on the 2D map past every
    occupied cell that no memory object (nor the target) explains, that is past walls
    (``wall_clear``), only those are kept; with ``strict_walls`` the others never are (None
    when every cell is behind a wall). ``wall_heights`` = (camera height, the target's top): an
    occupied cell hides the footprint only where it stands as high as the line of sight there
    (``wall_clear``'s ``heights``), as the camera judges it; without them every occupied cell
    is a wall, and low unlabelled furniture beside the object rules out the cells next to it.
    ``box_weight`` adds that many times the cell's distance to
    the footprint: for a ring wider than the success distance the nearest cell to the robot lies
    on the ring's edge, 1 m out, where the object's box error decides success (Gibson stopped
    0.96-1.06 m from five targets' boxes while free cells 0.1-0.2 m nearer were known).
    ``connected=False`` drops the first condition: any free cell will do, for a goal the robot
    is to reach through unknown floor (``VerifyTarget._send_through_unknown``). With ``tight``,
    ``prefer_roomy=False`` weighs cells only the robot radius clears as the others (for a robot
    that already stands in such a passage). Distances to the footprint are to the box with its
    corners rounded by ``corner_radius`` (``rounded_box_distance``; 0: the box).
    ``path_cost`` (with ``connected``): a cell's distance to the robot is the length of the path
    to it on the robot's map (``path_lengths``), not the straight line: across a bed or a table
    the cell nearest in a line is a walk round the furniture, and one on the robot's side of it
    is as good a view.
    """
    from scipy import ndimage

    state = np.asarray(grid.state)
    roomy = (state == 0) & ~np.asarray(grid.inflated, dtype=bool)
    free = (state == 0) & ~lethal_mask(grid) if tight else roomy
    res = float(grid.resolution)
    ox, oy = float(grid.origin[0]), float(grid.origin[1])
    h, w = free.shape
    r0 = max(int((box_min[1] - max_distance - oy) / res) - 1, 0)
    r1 = min(int((box_max[1] + max_distance - oy) / res) + 2, h)
    c0 = max(int((box_min[0] - max_distance - ox) / res) - 1, 0)
    c1 = min(int((box_max[0] + max_distance - ox) / res) + 2, w)
    if r0 >= r1 or c0 >= c1:
        return None
    labels, _ = ndimage.label(free)
    rr = int(np.clip((robot_xy[1] - oy) / res, 0, h - 1))
    rc = int(np.clip((robot_xy[0] - ox) / res, 0, w - 1))
    robot_label = labels[rr, rc]
    if robot_label == 0:  # robot cell itself inflated/unknown: use the nearest free component
        near = labels[max(rr - 6, 0):rr + 7, max(rc - 6, 0):rc + 7]
        robot_label = int(np.bincount(near[near > 0]).argmax()) if np.any(near > 0) else 0
    rows, cols = np.mgrid[r0:r1, c0:c1]
    x = ox + (cols + 0.5) * res
    y = oy + (rows + 0.5) * res
    to_box = rounded_box_distance(x, y, box_min, box_max, corner_radius)
    ok = (to_box <= max_distance) & free[r0:r1, c0:c1]
    if robot_label and connected:
        ok &= labels[r0:r1, c0:c1] == robot_label
    for ex in exclude or []:
        ok &= np.hypot(x - ex[0], y - ex[1]) > 0.3
    if not np.any(ok):
        return None
    if tight and prefer_roomy and np.any(ok & roomy[r0:r1, c0:c1]):
        ok &= roomy[r0:r1, c0:c1]
    centre = 0.5 * (np.asarray(box_min, dtype=np.float64)[:2] + np.asarray(box_max, dtype=np.float64)[:2])
    if furniture is not None:
        idx = np.flatnonzero(ok)
        clear = wall_clear(grid, np.stack([x.flat[idx], y.flat[idx]], axis=1), centre,
                           [(box_min, box_max), *furniture], heights=wall_heights)
        if clear.any() or strict_walls:
            ok = _only(ok, idx[clear])
        if not ok.any():
            return None
    if sight is not None:
        point, height, lo, hi = sight
        idx = np.flatnonzero(ok)
        starts = np.stack([x.flat[idx], y.flat[idx], np.full(idx.size, float(height))], axis=1)
        clear = ~segments_blocked(starts, point, lo, hi)
        if clear.any():
            ok = _only(ok, idx[clear])
    cost = np.hypot(x - robot_xy[0], y - robot_xy[1])
    if path_cost and connected:
        path = path_lengths(grid, robot_xy, (r0, r1, c0, c1))
        # a cell no path inside the window reaches keeps its straight line, after every reached one
        cost = np.where(np.isfinite(path), path, cost + PATH_UNREACHED_M)
    if box_weight > 0.0:
        cost = cost + box_weight * to_box
    if centre_weight > 0.0:
        cost = cost + centre_weight * np.hypot(x - centre[0], y - centre[1])
    if prefer_xy is not None and prefer_weight > 0.0:
        cost = cost + prefer_weight * np.hypot(x - prefer_xy[0], y - prefer_xy[1])
    cost = np.where(ok, cost, np.inf)
    i = int(np.argmin(cost))
    return np.array([x.flat[i], y.flat[i]])


#: m: added to the straight-line distance of a cell that no path inside the window reaches
PATH_UNREACHED_M = 100.0
#: m: the window path_lengths marches in reaches this far past the robot and the cells' box
PATH_WINDOW_MARGIN_M = 3.0


def path_lengths(grid: Any, robot_xy: np.ndarray, cells: tuple[int, int, int, int],
                 margin_m: float = PATH_WINDOW_MARGIN_M) -> np.ndarray:
    """(r1 - r0, c1 - c0) metres: the length of the shortest path from the robot to each grid cell
    of ``cells`` = (r0, r1, c0, c1) over known free cells clear of the robot radius (the
    navigator's lethal layer, ``lethal_mask``: where it plans), by
    fast marching (any-angle, ``hiconav.sim.fmm``); inf where no path inside the window reaches.

    The march runs in the box around the robot and the cells grown by ``margin_m``, not on the
    whole map: a path that leaves it is a detour the view cells should not take anyway, and a
    map of a large house is 800 x 800 cells (0.3 s a march) against ~200 x 200 here (1-3 ms a
    march, measured on train episodes).
    The robot's own cell and its neighbours within 0.1 m are the sources, as the robot may stand
    in the inflation margin."""
    from hiconav.sim.fmm import fmm_distance

    r0, r1, c0, c1 = cells
    state = np.asarray(grid.state)
    h, w = state.shape
    res = float(grid.resolution)
    ox, oy = float(grid.origin[0]), float(grid.origin[1])
    rr = int(np.clip((robot_xy[1] - oy) / res, 0, h - 1))
    rc = int(np.clip((robot_xy[0] - ox) / res, 0, w - 1))
    m = int(math.ceil(margin_m / res))
    wr0, wr1 = max(min(r0, rr) - m, 0), min(max(r1, rr + 1) + m, h)
    wc0, wc1 = max(min(c0, rc) - m, 0), min(max(c1, rc + 1) + m, w)
    trav = (state[wr0:wr1, wc0:wc1] == 0) & ~lethal_mask(grid)[wr0:wr1, wc0:wc1]
    src = np.zeros_like(trav)
    k = max(int(round(0.1 / res)), 1)
    src[max(rr - wr0 - k, 0):rr - wr0 + k + 1, max(rc - wc0 - k, 0):rc - wc0 + k + 1] = True
    dist = fmm_distance(trav, src, res)
    return dist[r0 - wr0:r1 - wr0, c0 - wc0:c1 - wc0]


def _only(mask: np.ndarray, flat_idx: np.ndarray) -> np.ndarray:
    """A mask of ``mask``'s shape that is True at the flat indices ``flat_idx`` alone."""
    out = np.zeros_like(mask)
    out.flat[flat_idx] = True
    return out


def facing(xy: np.ndarray, center: np.ndarray) -> float:
    """Heading (rad) from ``xy`` toward ``center``."""
    return math.atan2(center[1] - xy[1], center[0] - xy[0])


def wall_clear(grid: Any, cells_xy: np.ndarray, target_xy: np.ndarray,
               explained: list[tuple[np.ndarray, np.ndarray]], margin: float = 0.1,
               heights: tuple[np.ndarray | float, float] | None = None, clearance: float = 0.05) -> np.ndarray:
    """(n,) bool: the straight line on the grid from each of ``cells_xy`` (n, 2) to ``target_xy``
    crosses no occupied cell outside the ``explained`` boxes ((lo, hi), xy used, grown by
    ``margin``), i.e. no wall.

    On a 2D map a table is as opaque as a wall, so a plain line-of-sight test lost every cell by
    objects on tables (an earlier attempt, reverted); furniture the memory knows is see-through
    here and what stays opaque is what no object explains: walls (a cell on the far side of a
    wall is close to the object on the map and far from it on foot).

    ``heights`` = (start heights (n,) or one, end height) above the floor, with a grid that
    keeps obstacle heights (``top``): an occupied cell blocks only where its highest point comes
    within ``clearance`` of the line's height there, so a camera sees a sofa over an unlabelled
    low table. A cell with no recorded height blocks."""
    state = np.asarray(grid.state)
    res, ox, oy = float(grid.resolution), float(grid.origin[0]), float(grid.origin[1])
    h, w = state.shape
    cells_xy = np.asarray(cells_xy, dtype=np.float64).reshape(-1, 2)
    if len(cells_xy) == 0:
        return np.zeros(0, dtype=bool)
    d = np.asarray(target_xy, dtype=np.float64)[None, :] - cells_xy
    n_samples = max(2, int(math.ceil(float(np.max(np.hypot(d[:, 0], d[:, 1]))) / (0.5 * res))) + 1)
    t = np.linspace(0.0, 1.0, n_samples)[None, :, None]
    pts = cells_xy[:, None, :] + t * d[:, None, :]  # (n, s, 2)
    cols = np.floor((pts[..., 0] - ox) / res).astype(np.int64)
    rows = np.floor((pts[..., 1] - oy) / res).astype(np.int64)
    inside = (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)
    occ = np.zeros(rows.shape, dtype=bool)
    occ[inside] = state[rows[inside], cols[inside]] == 1
    top = getattr(grid, "top", None)
    if heights is not None and top is not None:
        start = np.broadcast_to(np.asarray(heights[0], dtype=np.float64), (len(cells_xy),))
        line_z = start[:, None] + t[..., 0] * (float(heights[1]) - start[:, None])  # (n, s)
        cell_top = np.zeros(rows.shape, dtype=np.float64)
        cell_top[inside] = np.asarray(top)[rows[inside], cols[inside]]
        occ &= (cell_top <= 0.0) | (cell_top + clearance >= line_z)
    for lo, hi in explained:
        lo, hi = np.asarray(lo, dtype=np.float64)[:2] - margin, np.asarray(hi, dtype=np.float64)[:2] + margin
        occ &= ~((pts[..., 0] >= lo[0]) & (pts[..., 0] <= hi[0]) & (pts[..., 1] >= lo[1]) & (pts[..., 1] <= hi[1]))
    return ~occ.any(axis=1)


def segments_blocked(starts: np.ndarray, end: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(n,) bool: the segment from each of ``starts`` (n, 3) to ``end`` (3,) passes through one
    of the axis-aligned boxes ``lo`` / ``hi`` (m, 3) (slab test; a box containing either end
    does not count, so the object itself and furniture the robot stands by never block)."""
    starts = np.asarray(starts, dtype=np.float64).reshape(-1, 3)
    lo = np.asarray(lo, dtype=np.float64).reshape(-1, 3)
    hi = np.asarray(hi, dtype=np.float64).reshape(-1, 3)
    if len(starts) == 0 or len(lo) == 0:
        return np.zeros(len(starts), dtype=bool)
    end = np.asarray(end, dtype=np.float64)
    d = end[None, :] - starts  # (n, 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / np.where(np.abs(d) < 1e-12, 1e-12, d)
        t0 = (lo[None, :, :] - starts[:, None, :]) * inv[:, None, :]  # (n, m, 3)
        t1 = (hi[None, :, :] - starts[:, None, :]) * inv[:, None, :]
    t_in = np.minimum(t0, t1).max(axis=2)
    t_out = np.maximum(t0, t1).min(axis=2)
    hit = (t_in <= t_out) & (t_in > 0.0) & (t_out < 1.0)  # entered and left strictly between the ends
    return hit.any(axis=1)


def anchor_sees(anchor: Any, point: np.ndarray, blockers: tuple[np.ndarray, np.ndarray] | None = None,
                margin: float = 0.05) -> bool:
    """True when ``point`` (3,) world projects inside the anchor's image (both fields of view,
    ``margin`` of the size in from its edges) and, with ``blockers`` (lo, hi) boxes (m, 3), the
    line from the camera to it passes through none of them.

    A frame whose camera could not show the point says nothing about the object there: a tv
    hung above the vertical field of view of a camera 1.2 m away, or a vase behind a chair,
    must not count as a frame that missed it (a test on bearings alone rejected real objects
    as 'detected in 0 of 8 frames')."""
    T = np.asarray(anchor.T_world_cam, dtype=np.float64)
    pc = T[:3, :3].T @ (np.asarray(point, dtype=np.float64)[:3] - T[:3, 3])
    if pc[2] <= 1e-6:
        return False
    K = anchor.intrinsics
    u = (K.fx * pc[0] / pc[2] + K.cx) / K.width
    v = (K.fy * pc[1] / pc[2] + K.cy) / K.height
    if not (margin <= u <= 1.0 - margin and margin <= v <= 1.0 - margin):
        return False
    if blockers is None:
        return True
    return not bool(segments_blocked(T[None, :3, 3], point, *blockers)[0])


__all__ = ["anchor_sees", "approach_cell", "facing", "segments_blocked", "wall_clear"]
