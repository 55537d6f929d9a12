"""Geodesic distances on the navigable grid: where the robot's centre may stand, the distance to a
goal, the success region and the distance to it, per data set.

Where the centre may stand (``centre_free``): for ProcTHOR the navigable grid is the floor free of
walls and objects, and the centre may occupy a cell when the cell's clearance (distance from its
centre to the nearest non-navigable cell, minus half a cell) is at least the robot radius. For
Gibson the data set gives the centre's free space itself: channel 0 of the SemExp maps is
Habitat's navmesh projected to the floor, already shrunk by Habitat's agent radius, so it is used
as it is (shrinking it by the radius again closed doorways and corridors: 2 of Habitat's 25
reference paths stayed traversable).

Distances to the success region (SPL's shortest path, DTS) are any-angle: fast marching
(``hiconav.sim.fmm``), as SemExp and L3MVN measure them; an 8-connected cell path is up to 8%
longer than Habitat's navmesh path.

Two success rules (``House.success_rule``):

* ``"semexp"`` (the Gibson maps, SemExp's ``objectgoal_env``): the traversable map is the
  centre's free space dilated by a 2-cell disk; the success region is the goal category's cells
  dilated by the success distance (a disk of ``round(d / res)`` cells); an episode succeeds when
  the robot stops in that region (its fast-marching distance to it is 0). No line of sight.
  ``GoalDistance.field`` is the Euclidean distance to the goal cells inside the region and
  ``VIEW_RADIUS`` + the fast-marching distance to the region outside it, so ``field <= 1.0``
  exactly on the region.
* ``"view_points"`` (ProcTHOR, whose houses have walls and furniture we can see past or not):
  the distance to a goal object is one multi-source Dijkstra run: every traversable cell within
  ``VIEW_RADIUS`` (1.0 m, Euclidean) of the object's footprint that sees the object is a *view
  point* (as Habitat's ObjectNav goal view points, which are kept only where the object is
  visible) and a source whose initial value is its Euclidean distance to the nearest footprint
  cell. *Sees* means a straight line from the cell to one of the footprint cells crosses no
  ``House.sight_walls`` cell: without it, a robot shut in the next room counted as having found
  an object on the other side of the wall. If no traversable cell is that close the reach grows
  by 1.5x up to 3 m (a labelled fallback for objects in cluttered corners); the offsets of such
  far view points are scaled by ``VIEW_RADIUS / reach``, so that the nearest of them lie within
  the success distance. The success region is the cells whose field is at most the success
  distance; the distance to it is again fast marching.

Paths on the cell graph (``GridGraph``: 8-connected, no corner cutting) remain for the view-point
field and for the walk-through tools. This module computes distances only; it must not move the
robot or render.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from hiconav.errors import DataError
from hiconav.sim.fmm import disk, fmm_distance
from hiconav.sim.house import House, NavGrid

if TYPE_CHECKING:
    from hiconav.sim.episodes import Episode

SQRT2 = math.sqrt(2.0)
VIEW_RADIUS = 1.0  # m: traversable cells this close to a goal footprint are its view points
SEMEXP_DILATION_CELLS = 2  # SemExp's planner map: the navmesh dilated by skimage disk(2)
_SOURCE_EPS = 1e-9  # m: keeps zero-offset source edges in the sparse graph; removed from results


def clearance(nav: NavGrid) -> np.ndarray:
    """(H, W) float64 metres from each cell centre to the nearest blocked cell's edge.

    Cells outside the grid count as blocked. Non-navigable cells have clearance <= 0.
    """
    padded = np.pad(nav.navigable, 1, constant_values=False)
    edt = ndimage.distance_transform_edt(padded)[1:-1, 1:-1]
    return edt * nav.resolution - nav.resolution / 2.0


def traversable(nav: NavGrid, radius: float) -> np.ndarray:
    """(H, W) bool: cells where a robot disc of ``radius`` m centred in the cell fits."""
    return clearance(nav) >= radius - 1e-9


class GridGraph:
    """8-connected graph over a (H, W) bool mask; node k is the k-th True cell (row-major)."""

    def __init__(self, mask: np.ndarray, resolution: float) -> None:
        self.mask = np.asarray(mask, dtype=bool)
        self.resolution = float(resolution)
        h, w = self.mask.shape
        self.index = np.full((h, w), -1, dtype=np.int64)
        rr, cc = np.nonzero(self.mask)
        self.cells = np.stack([rr, cc], axis=1)
        self.n = len(rr)
        self.index[rr, cc] = np.arange(self.n)
        rows, cols, wts = [], [], []
        m = self.mask
        for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
            a = np.zeros_like(m)
            # a[r, c] True when (r, c) and (r + dr, c + dc) are both traversable.
            r0, r1 = 0, h - dr
            c0, c1 = max(0, -dc), w - max(0, dc)
            a[r0:r1, c0:c1] = m[r0:r1, c0:c1] & m[r0 + dr:r1 + dr, c0 + dc:c1 + dc]
            if dr and dc:  # no corner cutting
                a[r0:r1, c0:c1] &= m[r0 + dr:r1 + dr, c0:c1] & m[r0:r1, c0 + dc:c1 + dc]
            ar, ac = np.nonzero(a)
            rows.append(self.index[ar, ac])
            cols.append(self.index[ar + dr, ac + dc])
            wts.append(np.full(len(ar), (SQRT2 if dr and dc else 1.0) * self.resolution))
        self.rows = np.concatenate(rows)
        self.cols = np.concatenate(cols)
        self.wts = np.concatenate(wts)

    def multi_source(self, cells: np.ndarray, offsets: np.ndarray) -> np.ndarray:
        """(H, W) float64 min over sources s of offsets[s] + path length(s, cell); inf if none.

        cells: (K, 2) traversable (row, col) sources; offsets: (K,) metres >= 0.
        """
        h, w = self.mask.shape
        out = np.full((h, w), np.inf)
        if len(cells) == 0 or self.n == 0:
            return out
        src = self.index[cells[:, 0], cells[:, 1]]
        if np.any(src < 0):
            raise ValueError("every source cell must be traversable")
        super_node = self.n
        # Zero weights would be dropped by the sparse matrix: the super node's edges carry a
        # negligible epsilon, taken off again below (left in, a robot exactly at the success
        # distance read 1.000000001 m and failed).
        rows = np.concatenate([self.rows, self.cols, np.full(len(src), super_node)])
        cols = np.concatenate([self.cols, self.rows, src])
        wts = np.concatenate([self.wts, self.wts,
                              np.asarray(offsets, dtype=np.float64) + _SOURCE_EPS])
        graph = coo_matrix((wts, (rows, cols)), shape=(self.n + 1, self.n + 1)).tocsr()
        dist = dijkstra(graph, directed=True, indices=super_node)
        out[self.cells[:, 0], self.cells[:, 1]] = np.maximum(dist[: self.n] - _SOURCE_EPS, 0.0)
        return out


def centre_free(house: House, radius: float) -> np.ndarray:
    """(H, W) bool cells where the robot's centre may stand: the data set's own mask where it
    gives one (``House.centre_free``, Gibson), else the cells with clearance >= ``radius``."""
    if house.centre_free is not None:
        return np.asarray(house.centre_free, dtype=bool)
    key = ("centre_free", round(radius, 6))
    mask = house._cache.get(key)
    if mask is None:
        mask = traversable(house.nav, radius)
        mask.flags.writeable = False
        house._cache[key] = mask
    return mask


def distance_mask(house: House, radius: float) -> np.ndarray:
    """(H, W) bool cells that distances are measured through: the centre's free space, dilated by
    SemExp's 2-cell disk under the "semexp" rule (its ground-truth planner's traversable map)."""
    free = centre_free(house, radius)
    if house.success_rule != "semexp":
        return free
    key = ("distance_mask", round(radius, 6))
    mask = house._cache.get(key)
    if mask is None:
        mask = ndimage.binary_dilation(free, structure=disk(SEMEXP_DILATION_CELLS))
        mask.flags.writeable = False
        house._cache[key] = mask
    return mask


def driving_pieces(free: np.ndarray) -> np.ndarray:
    """(H, W) int labels of the 8-connected pieces of the robot-centre cells ``free`` (0 elsewhere).

    The simulator's sub-steps and slides pass a diagonal link of two cells, so a robot moves
    within one such piece and never leaves it."""
    labels, _ = ndimage.label(np.asarray(free, dtype=bool), structure=np.ones((3, 3), dtype=bool))
    return labels


def reaching_pieces(pieces: np.ndarray, region: np.ndarray) -> np.ndarray:
    """(H, W) bool: the cells of those ``pieces`` (``driving_pieces``) that hold a cell of
    ``region`` ((H, W) bool): where a robot placed can drive into the region.

    Distances measured on a looser mask (SemExp's 2-cell dilation of the navmesh) bridge gaps the
    robot cannot drive through, so a finite distance alone does not say the goal is reachable."""
    ids = np.unique(pieces[np.asarray(region, dtype=bool)])
    ids = ids[ids > 0]
    return np.isin(pieces, ids) if ids.size else np.zeros(pieces.shape, dtype=bool)


def house_graph(house: House, radius: float) -> GridGraph:
    """The graph of the robot-centre cells of a house for a robot radius (cached on the house)."""
    key = ("graph", round(radius, 6))
    graph = house._cache.get(key)
    if graph is None:
        graph = GridGraph(centre_free(house, radius), house.nav.resolution)
        house._cache[key] = graph
    return graph


SIGHT_BLOCK = 2  # cells: a view point looks at one footprint boundary cell per 2 x 2 block


def sees_footprint(cells: np.ndarray, foot: np.ndarray, walls: np.ndarray,
                   reach_cells: float) -> np.ndarray:
    """(N,) bool: whether a straight line from each of ``cells`` (N, 2) to some cell of the
    footprint ``foot`` ((H, W) bool) no farther than ``reach_cells`` crosses no ``walls`` cell.

    Only the footprint's boundary cells are looked at (a line to an inner cell crosses the
    boundary first), one per ``SIGHT_BLOCK`` block. Lines are sampled every quarter cell. Corner
    gaps are closed first (a free cell with wall cells on two orthogonal sides blocks), so a
    line cannot slip between two wall cells that touch only at a corner; footprint cells never
    block their own object (a painting's cell may lie in its wall).
    """
    walls = walls & ~foot
    # close the corner gaps of staircase walls: a cell with wall cells on two orthogonal sides
    # blocks too (straight walls do not grow: the cell next to a wall has a wall on one side)
    pad = np.pad(walls, 1)
    up, down = pad[:-2, 1:-1], pad[2:, 1:-1]
    left, right = pad[1:-1, :-2], pad[1:-1, 2:]
    blocked = walls | ((up | down) & (left | right) & ~foot)
    edge = foot & ~ndimage.binary_erosion(foot)
    targets = np.argwhere(edge)
    _, first = np.unique(targets // SIGHT_BLOCK, axis=0, return_index=True)
    targets = targets[np.sort(first)].astype(np.float64)
    src = cells.astype(np.float64)
    seen = np.zeros(len(cells), dtype=bool)
    n = int(np.ceil(4.0 * (reach_cells + 1.5))) + 1
    frac = np.linspace(0.0, 1.0, n)[1:-1]  # strictly between the two cell centres
    for t in targets:
        delta = t - src
        todo = np.flatnonzero(~seen & (np.abs(delta).max(axis=1) <= reach_cells + 1.5))
        if not len(todo):
            continue
        d = delta[todo]
        rr = np.rint(src[todo, 0, None] + d[:, 0, None] * frac).astype(np.int64)
        cc = np.rint(src[todo, 1, None] + d[:, 1, None] * frac).astype(np.int64)
        seen[todo] = ~blocked[rr, cc].any(axis=1)
    return seen


def goal_sources(graph: GridGraph, footprint: np.ndarray, resolution: float, radius: float,
                 walls: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Traversable source cells near a footprint ((N, 2) cells) and their offsets (m); with
    ``walls`` ((H, W) bool), only cells that see the footprint past them."""
    h, w = graph.mask.shape
    foot = np.zeros((h, w), dtype=bool)
    if len(footprint):
        foot[footprint[:, 0], footprint[:, 1]] = True
    if not foot.any():
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0)
    dist = ndimage.distance_transform_edt(~foot) * resolution
    reach = max(VIEW_RADIUS, radius + 1.5 * resolution)
    while reach <= 3.0 + 1e-9:
        sel = graph.mask & (dist <= reach)
        if sel.any():
            rr, cc = np.nonzero(sel)
            cells = np.stack([rr, cc], axis=1)
            if walls is not None:
                keep = sees_footprint(cells, foot, walls, reach / resolution)
                cells = cells[keep]
            if len(cells):
                offsets = dist[cells[:, 0], cells[:, 1]]
                if reach > VIEW_RADIUS:  # the labelled fallback: far view points, scaled
                    offsets = offsets * (VIEW_RADIUS / reach)
                return cells, offsets
        reach *= 1.5
    return np.zeros((0, 2), dtype=np.int64), np.zeros(0)


class GoalDistance:
    """Geodesic distance (m) from any robot position to the nearest goal instance footprint.

    ``GoalDistance(house, episode)`` uses ``episode.goal_instance_ids``; alternatively pass
    ``instance_ids=...``. ``field``: (H, W) float64 metres, inf where unreachable.
    """

    def __init__(self, house: House, episode: Episode | None = None, *,
                 instance_ids: Iterable[int] | None = None, radius: float = 0.18) -> None:
        ids = tuple(instance_ids) if instance_ids is not None else \
            tuple(episode.goal_instance_ids) if episode is not None else ()
        if not ids:
            raise DataError("GoalDistance needs at least one goal instance id",
                            field="goal_instance_ids")
        for i in ids:
            if not 0 <= i < len(house.objects):
                raise DataError(f"goal instance {i} is not an object of {house.name} "
                                f"(0..{len(house.objects) - 1})", field="goal_instance_ids")
        self.house = house
        self.instance_ids = ids
        self.radius = float(radius)
        key = ("goal", ids, round(self.radius, 6))
        cached = house._cache.get(key)
        if cached is None:
            if house.success_rule == "semexp":
                region = self.success_region(VIEW_RADIUS)
                cached = fmm_distance(distance_mask(house, self.radius), region, house.nav.resolution)
                cached = np.where(region, self._goal_edt() * house.nav.resolution, cached + VIEW_RADIUS)
            else:
                graph = house_graph(house, self.radius)
                foot = np.concatenate([house.footprint(i) for i in ids])
                cells, offsets = goal_sources(graph, foot, house.nav.resolution, self.radius,
                                              house.sight_walls)
                cached = graph.multi_source(cells, offsets)
            cached.flags.writeable = False
            house._cache[key] = cached
        self.field: np.ndarray = cached

    def _goal_edt(self) -> np.ndarray:
        """(H, W) float64 Euclidean distance in cells from each cell centre to the nearest goal
        footprint cell (cached)."""
        key = ("goal_edt", self.instance_ids)
        edt = self.house._cache.get(key)
        if edt is None:
            foot = np.zeros(self.house.nav.shape, dtype=bool)
            cells = np.concatenate([self.house.footprint(i) for i in self.instance_ids])
            if len(cells):
                foot[cells[:, 0], cells[:, 1]] = True
            edt = ndimage.distance_transform_edt(~foot) if foot.any() else np.full(foot.shape, np.inf)
            edt.flags.writeable = False
            self.house._cache[key] = edt
        return edt

    def success_region(self, success_distance: float) -> np.ndarray:
        """(H, W) bool: the cells where a stop succeeds (see the module's two rules)."""
        if self.house.success_rule == "semexp":
            return self._goal_edt() <= round(float(success_distance) / self.house.nav.resolution)
        return self.field <= float(success_distance)

    def distance(self, xy: np.ndarray) -> float:
        """Geodesic metres from world ``xy`` (2,) to the nearest goal footprint (inf if none).

        A position whose cell is not traversable (e.g. a start pressed against a wall) uses the
        nearest reachable cell within 0.5 m plus the straight distance to it.
        """
        return self._lookup(self.field, xy)

    def success_field(self, success_distance: float) -> np.ndarray:
        """(H, W) geodesic metres from each cell to the nearest cell of the success region (the
        ``success_region``; 0 inside it, inf if unreachable), by fast marching."""
        key = ("success", self.instance_ids, round(self.radius, 6), round(float(success_distance), 9))
        cached = self.house._cache.get(key)
        if cached is None:
            cached = fmm_distance(distance_mask(self.house, self.radius),
                                  self.success_region(success_distance), self.house.nav.resolution)
            cached.flags.writeable = False
            self.house._cache[key] = cached
        return cached

    def to_success(self, xy: np.ndarray, success_distance: float) -> float:
        """Geodesic metres from world ``xy`` to the success region: the shortest path an agent
        must travel to succeed, the l of SPL (Habitat ObjectNav measures it to the goal's view
        points). ``distance(xy) - success_distance`` is only a lower bound of it: the nearest
        point of the region may lie along another route than the nearest footprint cell."""
        return self._lookup(self.success_field(success_distance), xy)

    def _lookup(self, field: np.ndarray, xy: np.ndarray) -> float:
        """``field`` at world ``xy``; off the traversable cells, the nearest finite cell within
        0.5 m plus the straight distance to it (inf if none)."""
        nav = self.house.nav
        rc = nav.world_to_cell(np.asarray(xy, dtype=np.float64)[:2])
        if nav.in_bounds(rc) and np.isfinite(field[rc[0], rc[1]]):
            return float(field[rc[0], rc[1]])
        r = math.ceil(0.5 / nav.resolution)
        h, w = nav.shape
        r0, r1 = max(rc[0] - r, 0), min(rc[0] + r + 1, h)
        c0, c1 = max(rc[1] - r, 0), min(rc[1] + r + 1, w)
        if r1 <= r0 or c1 <= c0:
            return math.inf
        win = field[r0:r1, c0:c1]
        rr, cc = np.nonzero(np.isfinite(win))
        if len(rr) == 0:
            return math.inf
        centres = nav.cell_to_world(np.stack([rr + r0, cc + c0], axis=1))
        d = np.linalg.norm(centres - np.asarray(xy)[:2], axis=1) + win[rr, cc]
        return float(d.min())

    def next_cell(self, rc: np.ndarray) -> np.ndarray | None:
        """The 8-neighbour of cell ``rc`` with the smallest distance (descent step), or None."""
        h, w = self.field.shape
        best, best_d = None, self.field[rc[0], rc[1]]
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                r, c = rc[0] + dr, rc[1] + dc
                if (dr or dc) and 0 <= r < h and 0 <= c < w and self.field[r, c] < best_d:
                    best, best_d = np.array([r, c]), self.field[r, c]
        return best

    def path(self, xy: np.ndarray, max_cells: int = 100000) -> np.ndarray:
        """(N, 2) world xy cell centres of a shortest path from ``xy`` to the goal region."""
        nav = self.house.nav
        rc = nav.world_to_cell(np.asarray(xy)[:2])
        if not nav.in_bounds(rc) or not np.isfinite(self.field[rc[0], rc[1]]):
            return np.zeros((0, 2))
        cells = [rc]
        for _ in range(max_cells):
            nxt = self.next_cell(cells[-1])
            if nxt is None:
                break
            cells.append(nxt)
        return nav.cell_to_world(np.array(cells))


def point_distance_field(house: House, xy: np.ndarray, radius: float = 0.18) -> np.ndarray:
    """(H, W) any-angle geodesic metres (fast marching through ``distance_mask``) from a world
    point ``xy``; inf everywhere when its cell is not traversable."""
    mask = distance_mask(house, radius)
    rc = house.nav.world_to_cell(np.asarray(xy)[:2])
    src = np.zeros(mask.shape, dtype=bool)
    if house.nav.in_bounds(rc) and mask[rc[0], rc[1]]:
        src[rc[0], rc[1]] = True
    return fmm_distance(mask, src, house.nav.resolution)
