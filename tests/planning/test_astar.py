"""hiconav.planning.astar: optimal 8-connected paths (checked against scipy), smoothing, line of sight."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import shortest_path

from hiconav.planning import astar, line_of_sight, path_length, smooth_path


def grid_graph(blocked: np.ndarray):
    """The same 8-connected graph as astar (no corner cutting) as a sparse matrix for scipy."""
    h, w = blocked.shape
    free = ~blocked
    idx = np.arange(h * w).reshape(h, w)
    rows, cols, costs = [], [], []
    for dr, dc in [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1)]:
        r0, r1 = max(0, -dr), min(h, h - dr)
        c0, c1 = max(0, -dc), min(w, w - dc)
        ok = free[r0:r1, c0:c1] & free[r0 + dr : r1 + dr, c0 + dc : c1 + dc]
        if dr and dc:  # no corner cutting
            ok &= free[r0 + dr : r1 + dr, c0:c1] & free[r0:r1, c0 + dc : c1 + dc]
        a = idx[r0:r1, c0:c1][ok]
        b = idx[r0 + dr : r1 + dr, c0 + dc : c1 + dc][ok]
        rows.append(a)
        cols.append(b)
        costs.append(np.full(a.size, math.sqrt(2.0) if dr and dc else 1.0))
    return coo_matrix(
        (np.concatenate(costs), (np.concatenate(rows), np.concatenate(cols))), shape=(h * w, h * w)
    ).tocsr()


@pytest.mark.parametrize("seed", range(8))
def test_astar_length_equals_scipy_shortest_path(seed):
    rng = np.random.default_rng(seed)
    h, w = rng.integers(20, 60, size=2)
    blocked = rng.random((h, w)) < rng.uniform(0.1, 0.35)
    free = np.argwhere(~blocked)
    dist = shortest_path(
        grid_graph(blocked), method="D", directed=True, indices=[int(free[0, 0] * w + free[0, 1])]
    )[0]
    start = tuple(free[0])
    for k in rng.choice(len(free), size=15, replace=False):
        goal = tuple(free[k])
        ref = dist[goal[0] * w + goal[1]]
        path = astar(blocked, start, goal)
        if np.isinf(ref):
            assert path is None
            continue
        assert path is not None
        assert tuple(path[0]) == start and tuple(path[-1]) == goal
        assert not blocked[path[:, 0], path[:, 1]].any()
        if len(path) > 1:
            steps = np.abs(np.diff(path, axis=0))
            assert steps.max() <= 1 and steps.sum(axis=1).min() >= 1
        assert path_length(path) == pytest.approx(ref, abs=1e-9)


def test_no_corner_cutting():
    blocked = np.zeros((3, 3), bool)
    blocked[0, 1] = blocked[1, 0] = True
    path = astar(blocked, (1, 1), (0, 0))
    assert path is None  # the only way is diagonal between two blocked corners


def test_unreachable_blocked_or_outside_goals_give_none():
    blocked = np.zeros((10, 10), bool)
    blocked[:, 5] = True
    assert astar(blocked, (0, 0), (0, 9)) is None
    assert astar(blocked, (0, 0), (0, 5)) is None
    assert astar(blocked, (0, 0), (20, 20)) is None


def test_blocked_start_may_be_left():
    blocked = np.zeros((10, 10), bool)
    blocked[2, 2] = True
    path = astar(blocked, (2, 2), (8, 8))
    assert path is not None and path_length(path) == pytest.approx(6 * math.sqrt(2))


def test_smoothing_keeps_line_of_sight_and_shortens():
    blocked = np.zeros((60, 60), bool)
    blocked[10:50, 30] = True
    path = astar(blocked, (30, 5), (30, 55))
    way = smooth_path(blocked, path)
    assert len(way) < len(path) and tuple(way[0]) == (30, 5) and tuple(way[-1]) == (30, 55)
    for a, b in zip(way[:-1], way[1:]):
        assert line_of_sight(blocked, tuple(a), tuple(b))
    assert path_length(way) <= path_length(path) + 1e-9
    assert not line_of_sight(blocked, (30, 5), (30, 55))
