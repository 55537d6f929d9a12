"""Frontier extraction and tracking on the occupancy grid.

A frontier cell is a free cell 4-adjacent to an unknown cell. Frontier cells are clustered
(8-connected components, cv2.connectedComponentsWithStats), small clusters are dropped, long
ones split along their principal axis, and each cluster gets a centroid and a viewpoint: the
nearest free, non-inflated cell to the centroid that is connected to the robot through cells
clear of the robot radius (tight passages count; see ``OccupancyGrid.lethal``), or the nearest
such connected cell when none keeps the inflation margin; when no cluster has one, those reachable
on the lethal layer one cell thinner are kept (``squeeze_fallback``). Ids stay stable across
updates (and across grid growth) by matching clusters to the previous ones on shared global
cells, then on centroid distance.

It must not score or order frontiers (that is exploration's job) and must not modify the grid.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from hiconav.mapping.occupancy import GridLike, lethal_mask, squeeze_mask
from hiconav.mapping.config import FrontierConfig
from hiconav.types import Frontier

__all__ = ["FrontierTracker", "frontier_mask", "nearest_reachable_cell", "reachable_mask"]

_CROSS = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], dtype=np.uint8)
_KEY_OFFSET = 1 << 30




def frontier_mask(state: np.ndarray) -> np.ndarray:
    """(H, W) bool: free cells (state 0) 4-adjacent to unknown cells (state -1) or the grid edge."""
    unknown = (state == -1).astype(np.uint8)
    near_unknown = cv2.dilate(unknown, _CROSS, borderType=cv2.BORDER_CONSTANT, borderValue=1)
    return (state == 0) & near_unknown.astype(bool)


def nearest_reachable_cell(
    mask: np.ndarray, rc: tuple[int, int], radius_cells: int
) -> tuple[int, int] | None:
    """The True cell of ``mask`` nearest to ``rc`` within a square window of ``radius_cells``."""
    h, w = mask.shape
    r, c = int(rc[0]), int(rc[1])
    r0, r1 = max(0, r - radius_cells), min(h, r + radius_cells + 1)
    c0, c1 = max(0, c - radius_cells), min(w, c + radius_cells + 1)
    if r0 >= r1 or c0 >= c1:
        return None
    rr, cc = np.nonzero(mask[r0:r1, c0:c1])
    if rr.size == 0:
        return None
    d2 = (rr + r0 - r) ** 2 + (cc + c0 - c) ** 2
    k = int(np.argmin(d2))
    if d2[k] > radius_cells * radius_cells:
        return None
    return int(rr[k] + r0), int(cc[k] + c0)


def reachable_mask(traversable: np.ndarray, start: tuple[int, int] | None) -> np.ndarray:
    """(H, W) bool: traversable cells 8-connected to ``start`` (all traversable if start is None)."""
    if start is None:
        return traversable.copy()
    n, labels = cv2.connectedComponents(traversable.astype(np.uint8), connectivity=8)
    lab = labels[start[0], start[1]]
    if lab == 0:
        return np.zeros_like(traversable)
    return labels == lab


class FrontierTracker:
    """Extracts frontier clusters and keeps their ids stable across updates."""

    def __init__(self, config: FrontierConfig | None = None) -> None:
        self.config = config or FrontierConfig()
        self._next_id = 0
        self._prev_keys = np.zeros(0, dtype=np.int64)  # sorted global cell keys of previous frontiers
        self._prev_key_ids = np.zeros(0, dtype=np.int64)
        self._prev_centroids: dict[int, np.ndarray] = {}
        self.frontiers: list[Frontier] = []
        # diagnostics of the last update: cells reachable from the robot, in the cropped window
        # whose cell (0, 0) is grid cell ``reachable_offset``
        self.reachable: np.ndarray | None = None
        self.reachable_offset = np.zeros(2, dtype=np.int64)
        self.squeezed = False  # the last update's frontiers are reachable only one cell thinner

    @staticmethod
    def _global_keys(cells: np.ndarray, origin_cells: np.ndarray) -> np.ndarray:
        g = cells.astype(np.int64) + origin_cells[None, :]
        return (g[:, 0] + _KEY_OFFSET) * (2 * _KEY_OFFSET) + (g[:, 1] + _KEY_OFFSET)

    def _split(self, cells: np.ndarray) -> list[np.ndarray]:
        """Split a long cluster into chunks of at most max_size cells along its principal axis."""
        n = cells.shape[0]
        k = int(math.ceil(n / self.config.max_size_cells))
        if k <= 1:
            return [cells]
        x = cells.astype(np.float64)
        x -= x.mean(axis=0)
        _, _, vt = np.linalg.svd(x, full_matrices=False)
        order = np.argsort(x @ vt[0], kind="stable")
        return [cells[idx] for idx in np.array_split(order, k)]

    def update(self, grid: GridLike, robot_xy: np.ndarray) -> list[Frontier]:
        """Frontiers of ``grid`` (an OccupancyGrid or GridSnapshot) seen from ``robot_xy`` (2,) world m.

        Returns hiconav.types.Frontier objects sorted by id; ``cells`` are (row, col) in
        ``grid``'s current indexing, centroid/viewpoint are world xy.
        """
        cfg = self.config
        self.squeezed = False
        full_state = grid.state
        res = grid.resolution
        if full_state.size == 0 or not (full_state != -1).any():
            self._assign_ids([], [])
            self.frontiers = []
            return []
        # work on the bounding box of the known cells plus a ring of unknown ones (same result, less work)
        known = full_state != -1
        rows = np.flatnonzero(known.any(axis=1))
        cols = np.flatnonzero(known.any(axis=0))
        H, W = full_state.shape
        r0, r1 = max(0, rows[0] - 1), min(H, rows[-1] + 2)
        c0, c1 = max(0, cols[0] - 1), min(W, cols[-1] + 2)
        off = np.array([r0, c0])
        state = full_state[r0:r1, c0:c1]
        # frontier cells; the grid's own edge counts as unknown, the crop's edge is unknown anyway
        fmask = frontier_mask(state)
        # reachability through tight passages too (robot radius clear, no margin: the navigator
        # plans through them when nothing wider connects); viewpoints prefer cells with the margin
        traversable = (state == 0) & ~lethal_mask(grid)[r0:r1, c0:c1]
        roomy = traversable & ~np.asarray(grid.inflated[r0:r1, c0:c1], dtype=bool)
        rrc = grid.world_to_cell(np.asarray(robot_xy, dtype=np.float64)[:2]) - off
        start = nearest_reachable_cell(
            traversable, (int(rrc[0]), int(rrc[1])), int(math.ceil(cfg.robot_search_m / res))
        )
        reach = reachable_mask(traversable, start) if start is not None else traversable
        self.reachable, self.reachable_offset = reach, off
        # a viewpoint must also see its frontier: same free-space component as the frontier cells
        _, free_labels = cv2.connectedComponents((state == 0).astype(np.uint8), connectivity=8)

        n, labels, stats, _ = cv2.connectedComponentsWithStats(fmask.astype(np.uint8), connectivity=8)
        big = [i for i in range(1, n) if stats[i, cv2.CC_STAT_AREA] >= cfg.min_size_cells]
        origin_cells = np.array([round(grid.origin[1] / res), round(grid.origin[0] / res)], dtype=np.int64)
        search = int(math.ceil(cfg.viewpoint_search_m / res))

        clusters = self._clusters(labels, stats, big, reach & roomy, reach, free_labels, search)
        if not clusters and big and cfg.drop_unreachable and cfg.squeeze_fallback:
            # no frontier has a viewpoint the robot reaches: the map's phase error and depth noise
            # can close a passage the robot fits through by a cell (``squeeze_mask``), which ends
            # the search with floor left unseen beyond it. The frontiers a viewpoint one cell
            # thinner reaches are kept, as a last resort; the navigator squeezes toward them once
            # the normal and tight plans fail.
            squeeze = (state == 0) & ~squeeze_mask(grid)[r0:r1, c0:c1]
            start_sq = nearest_reachable_cell(
                squeeze, (int(rrc[0]), int(rrc[1])), int(math.ceil(cfg.robot_search_m / res))
            )
            if start_sq is not None:
                reach_sq = reachable_mask(squeeze, start_sq)
                clusters = self._clusters(labels, stats, big, reach_sq, reach_sq, free_labels, search)
                self.squeezed = bool(clusters)
        placed: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []  # cells, centroid_xy, viewpoint_xy
        for cells, cen_rc, vp in clusters:
            cells_full = (cells + off).astype(np.int32)
            centroid = grid.cell_to_world(cen_rc + off)
            viewpoint = (
                grid.cell_to_world(np.array(vp, dtype=np.float64) + off)
                if vp is not None
                else np.full(2, np.nan)
            )
            placed.append((cells_full, centroid, viewpoint))

        ids = self._assign_ids(
            [self._global_keys(c[0], origin_cells) for c in placed], [c[1] for c in placed]
        )
        out = [
            Frontier(
                id=fid,
                centroid=np.asarray(cen, dtype=np.float64),
                viewpoint=np.asarray(vp, dtype=np.float64),
                size=int(cells.shape[0]),
                cells=cells,
            )
            for fid, (cells, cen, vp) in zip(ids, placed)
        ]
        out.sort(key=lambda f: f.id)
        self.frontiers = out
        return out

    def _clusters(self, labels: np.ndarray, stats: np.ndarray, big: list[int], preferred: np.ndarray,
                  reach: np.ndarray, free_labels: np.ndarray,
                  search: int) -> list[tuple[np.ndarray, np.ndarray, tuple[int, int] | None]]:
        """(cells, centroid (row, col), viewpoint cell or None) of each kept cluster piece, in the
        crop's indexing: the viewpoint on ``preferred`` cells where one is near, else on ``reach``."""
        cfg = self.config
        clusters: list[tuple[np.ndarray, np.ndarray, tuple[int, int] | None]] = []
        for i in big:
            x, y, w, h = (
                int(stats[i, k])
                for k in (cv2.CC_STAT_LEFT, cv2.CC_STAT_TOP, cv2.CC_STAT_WIDTH, cv2.CC_STAT_HEIGHT)
            )
            rr, cc = np.nonzero(labels[y : y + h, x : x + w] == i)
            cells_all = np.stack([rr + y, cc + x], axis=1).astype(np.int32)
            for cells in self._split(cells_all):
                if cells.shape[0] < cfg.min_size_cells:
                    continue
                cen_rc = cells.mean(axis=0)
                vp = self._viewpoint(preferred, free_labels, cells, cen_rc, search)
                if vp is None:
                    vp = self._viewpoint(reach, free_labels, cells, cen_rc, search)
                if vp is None and cfg.drop_unreachable:
                    continue
                clusters.append((cells, cen_rc, vp))
        return clusters

    @staticmethod
    def _viewpoint(
        reach: np.ndarray, free_labels: np.ndarray, cells: np.ndarray, cen_rc: np.ndarray, search: int
    ) -> tuple[int, int] | None:
        """Nearest reachable cell to the centroid (within ``search`` cells) in its free component."""
        labs = np.unique(free_labels[cells[:, 0], cells[:, 1]])
        r, c = int(round(cen_rc[0])), int(round(cen_rc[1]))
        h, w = reach.shape
        r0, r1 = max(0, r - search), min(h, r + search + 1)
        c0, c1 = max(0, c - search), min(w, c + search + 1)
        fl = free_labels[r0:r1, c0:c1]
        same = fl == labs[0] if labs.size == 1 else np.isin(fl, labs)
        win = reach[r0:r1, c0:c1] & same
        vp = nearest_reachable_cell(win, (r - r0, c - c0), search)
        return None if vp is None else (vp[0] + r0, vp[1] + c0)

    def _assign_ids(self, keys: list[np.ndarray], centroids: list[np.ndarray]) -> list[int]:
        """Greedy matching to the previous frontiers: most shared cells first, then nearest centroid."""
        n = len(keys)
        ids: list[int | None] = [None] * n
        used: set[int] = set()
        pairs: list[tuple[int, int, int]] = []  # (-overlap, new index, prev id)
        if self._prev_keys.size:
            for j, k in enumerate(keys):
                pos = np.searchsorted(self._prev_keys, k)
                pos = np.clip(pos, 0, self._prev_keys.size - 1)
                hit = self._prev_keys[pos] == k
                if hit.any():
                    pid, cnt = np.unique(self._prev_key_ids[pos[hit]], return_counts=True)
                    pairs += [(-int(c), j, int(p)) for p, c in zip(pid, cnt)]
        for _neg, j, pid in sorted(pairs):
            if ids[j] is None and pid not in used:
                ids[j] = pid
                used.add(pid)
        for j in range(n):
            if ids[j] is not None:
                continue
            best, best_d = None, self.config.match_distance_m
            for pid, cen in self._prev_centroids.items():
                if pid in used:
                    continue
                d = float(np.hypot(*(cen - centroids[j])))
                if d <= best_d:
                    best, best_d = pid, d
            if best is None:
                best = self._next_id
                self._next_id += 1
            ids[j] = best
            used.add(best)
        final = [int(i) for i in ids]  # type: ignore[arg-type]
        if n:
            all_keys = np.concatenate(keys)
            all_ids = np.concatenate([np.full(k.size, i, dtype=np.int64) for k, i in zip(keys, final)])
            order = np.argsort(all_keys, kind="stable")
            self._prev_keys, self._prev_key_ids = all_keys[order], all_ids[order]
        else:
            self._prev_keys = np.zeros(0, dtype=np.int64)
            self._prev_key_ids = np.zeros(0, dtype=np.int64)
        self._prev_centroids = {i: np.asarray(c, dtype=np.float64) for i, c in zip(final, centroids)}
        return final
