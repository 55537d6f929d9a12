"""A* on a 2D occupancy grid (8-connected, no corner cutting) and line-of-sight path smoothing.

The search is compiled with numba (cached on disk after the first call), with an octile
heuristic, so that a query across a 24 m x 24 m, 5 cm grid costs milliseconds. Moves cost 1
(straight) and sqrt(2) (diagonal); a diagonal move needs both adjacent straight cells free, so
the path never squeezes between two blocked corners. The fast layer calls it on a window around
start and goal first and on the whole grid only if the window has no path.

It must not read maps, poses or configs: it takes a (H, W) bool array and cells.
"""

from __future__ import annotations

import heapq
import math

import numba
import numpy as np

__all__ = ["SQRT2", "astar", "line_of_sight", "path_length", "smooth_path"]

SQRT2 = math.sqrt(2.0)

# neighbour offsets: 4 straight, then 4 diagonal
_DR = np.array([-1, 1, 0, 0, -1, -1, 1, 1], dtype=np.int64)
_DC = np.array([0, 0, -1, 1, -1, 1, -1, 1], dtype=np.int64)


@numba.njit(cache=True, nogil=True)
def _astar_kernel(
    blocked: np.ndarray, sr: int, sc: int, gr: int, gc: int, dr: np.ndarray, dc: np.ndarray
) -> np.ndarray:  # pragma: no cover - compiled
    h, w = blocked.shape
    n = h * w
    g = np.full(n, np.inf)
    parent = np.full(n, -1, dtype=np.int64)
    closed = np.zeros(n, dtype=np.bool_)
    start = sr * w + sc
    goal = gr * w + gc
    sqrt2 = math.sqrt(2.0)
    g[start] = 0.0
    dx0 = abs(gr - sr)
    dy0 = abs(gc - sc)
    h0 = (dx0 + dy0) + (sqrt2 - 2.0) * min(dx0, dy0)
    heap = [(h0, 0.0, start)]
    found = False
    while len(heap) > 0:
        f, gcur, cur = heapq.heappop(heap)
        if closed[cur]:
            continue
        closed[cur] = True
        if cur == goal:
            found = True
            break
        r = cur // w
        c = cur - r * w
        for k in range(8):
            nr = r + dr[k]
            nc = c + dc[k]
            if nr < 0 or nr >= h or nc < 0 or nc >= w:
                continue
            if blocked[nr, nc]:
                continue
            if k >= 4:  # diagonal: no corner cutting
                if blocked[r, nc] or blocked[nr, c]:
                    continue
                step = sqrt2
            else:
                step = 1.0
            nb = nr * w + nc
            if closed[nb]:
                continue
            ng = gcur + step
            if ng < g[nb] - 1e-12:
                g[nb] = ng
                parent[nb] = cur
                ddr = abs(gr - nr)
                ddc = abs(gc - nc)
                hh = (ddr + ddc) + (sqrt2 - 2.0) * min(ddr, ddc)
                heapq.heappush(heap, (ng + hh, ng, nb))
    if not found:
        return np.zeros((0, 2), dtype=np.int64)
    # walk back
    count = 1
    cur = goal
    while cur != start:
        cur = parent[cur]
        count += 1
    out = np.empty((count, 2), dtype=np.int64)
    cur = goal
    i = count - 1
    while True:
        out[i, 0] = cur // w
        out[i, 1] = cur % w
        if cur == start:
            break
        cur = parent[cur]
        i -= 1
    return out


def astar(blocked: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> np.ndarray | None:
    """Shortest 8-connected path from ``start`` to ``goal`` (cells (row, col)) avoiding ``blocked``.

    blocked: (H, W) bool, True = not traversable (the start cell itself is allowed even when
    blocked, so that a robot inside the inflation zone can leave it). Returns (N, 2) int64 cells
    from start to goal inclusive, or None when the goal is blocked, outside the grid or
    unreachable. Path length (``path_length``) is optimal for costs 1 / sqrt(2).
    """
    blocked = np.ascontiguousarray(blocked, dtype=np.bool_)
    if blocked.ndim != 2:
        raise ValueError(f"blocked must be (H, W), got {blocked.shape}")
    h, w = blocked.shape
    sr, sc = int(start[0]), int(start[1])
    gr, gc = int(goal[0]), int(goal[1])
    for name, (r, c) in (("start", (sr, sc)), ("goal", (gr, gc))):
        if not (0 <= r < h and 0 <= c < w):
            if name == "start":
                raise ValueError(f"start {start} is outside the grid {blocked.shape}")
            return None
    if blocked[gr, gc]:
        return None
    if (sr, sc) == (gr, gc):
        return np.array([[sr, sc]], dtype=np.int64)
    if blocked[sr, sc]:
        blocked = blocked.copy()
        blocked[sr, sc] = False
    path = _astar_kernel(blocked, sr, sc, gr, gc, _DR, _DC)
    return path if path.shape[0] else None


def path_length(cells: np.ndarray) -> float:
    """Length of a cell path (N, 2) in cells (sum of Euclidean steps)."""
    cells = np.asarray(cells, dtype=np.float64)
    if cells.shape[0] < 2:
        return 0.0
    return float(np.hypot(*np.diff(cells, axis=0).T).sum())


@numba.njit(cache=True, nogil=True)
def _los_kernel(blocked: np.ndarray, r0: int, c0: int, r1: int, c1: int) -> bool:  # pragma: no cover
    # supercover-style check: sample the segment at 1/3-cell steps and test every touched cell
    h, w = blocked.shape
    dr = r1 - r0
    dc = c1 - c0
    n = int(max(abs(dr), abs(dc)) * 3) + 1
    for i in range(n + 1):
        t = i / n
        r = int(math.floor(r0 + 0.5 + dr * t))
        c = int(math.floor(c0 + 0.5 + dc * t))
        if r < 0 or r >= h or c < 0 or c >= w or blocked[r, c]:
            return False
    return True


def line_of_sight(blocked: np.ndarray, a: tuple[int, int], b: tuple[int, int]) -> bool:
    """True if the straight segment between the centres of cells ``a`` and ``b`` crosses no blocked cell."""
    return bool(
        _los_kernel(np.ascontiguousarray(blocked, dtype=np.bool_), int(a[0]), int(a[1]), int(b[0]), int(b[1]))
    )


@numba.njit(cache=True, nogil=True)
def _smooth_kernel(blocked: np.ndarray, path: np.ndarray) -> np.ndarray:  # pragma: no cover
    n = path.shape[0]
    keep = np.zeros(n, dtype=np.bool_)
    keep[0] = True
    i = 0
    while i < n - 1:
        j = n - 1
        while j > i + 1:
            if _los_kernel(blocked, path[i, 0], path[i, 1], path[j, 0], path[j, 1]):
                break
            j -= 1
        keep[j] = True
        i = j
    return path[keep]


def smooth_path(blocked: np.ndarray, path: np.ndarray) -> np.ndarray:
    """Line-of-sight shortcutting: the fewest waypoints (greedy farthest visible) along ``path``.

    path: (N, 2) int cells from ``astar``; returns (M, 2) int64 waypoints, first and last kept.
    The start cell is treated as free (the robot may stand in the inflation zone).
    """
    path = np.ascontiguousarray(path, dtype=np.int64)
    if path.shape[0] <= 2:
        return path.copy()
    blocked = np.array(blocked, dtype=np.bool_, copy=True)
    blocked[path[0, 0], path[0, 1]] = False
    return _smooth_kernel(blocked, path)
