"""Greedy WTRP baseline: from the current node go to the unvisited node with the smallest
cost-to-weight ratio M[cur, j] / W_j (nearest neighbour for unit weights).

A baseline for comparisons and ablations, never the planner's default. Zero-weight nodes go
last (ratio +inf), ordered by travel cost.
"""

from __future__ import annotations

import time

import numpy as np

from hiconav.exploration.wtrp.common import WTRPSolution, check_instance, check_order, wtrp_cost


def solve_greedy(M: np.ndarray, W: np.ndarray) -> WTRPSolution:
    """Nearest weighted-ratio order (see module docstring)."""
    t0 = time.perf_counter()
    M, w = check_instance(M, W)
    n = M.shape[0] - 1
    unvisited = np.ones(n + 1, dtype=bool)
    unvisited[0] = False
    cur = 0
    order: list[int] = []
    for _ in range(n):
        cand = np.flatnonzero(unvisited)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(w[cand] > 0, M[cur, cand] / np.maximum(w[cand], 1e-300), np.inf)
        # lexicographic: ratio, then travel cost (decides among zero-weight nodes)
        k = np.lexsort((M[cur, cand], ratio))[0]
        cur = int(cand[k])
        unvisited[cur] = False
        order.append(cur)
    out = tuple(order)
    check_order(out, n)
    return WTRPSolution(out, wtrp_cost(M, w[1:], out), "greedy", time.perf_counter() - t0)
