"""Exact WTRP by dynamic programming over subsets (Held-Karp style), for small n.

The weighted latency is rewritten edge by edge: the edge into the j-th visited node is paid
once by every node visited at or after j, so sum_i W_pi(i) C_i = sum_j M[pi(j-1), pi(j)] *
(W_total - W(visited before j)). The remaining weight depends only on the visited set, so
f[S, last] = min cost of visiting set S ending at ``last`` is a Bellman recursion: O(n^2 2^n)
time, O(n 2^n) memory. Must not be used beyond ``MAX_EXACT_N`` nodes (memory grows as 2^n).
"""

from __future__ import annotations

import time

import numba
import numpy as np

from hiconav.exploration.wtrp.common import WTRPError, WTRPSolution, check_instance, check_order, wtrp_cost

MAX_EXACT_N = 18  # 2^18 * 18 float64 = 38 MB; auto uses exact up to 12 only


@numba.njit(cache=True, nogil=True)
def _dp(M: np.ndarray, w: np.ndarray) -> np.ndarray:  # pragma: no cover - numba
    n = M.shape[0] - 1
    full = 1 << n
    wsub = np.zeros(full, dtype=np.float64)
    for S in range(1, full):
        low = S & (-S)
        j = 0
        while (1 << j) != low:
            j += 1
        wsub[S] = wsub[S ^ low] + w[j + 1]
    total = wsub[full - 1]
    f = np.full((full, n), np.inf)
    parent = np.full((full, n), -1, dtype=np.int32)
    for j in range(n):
        f[1 << j, j] = M[0, j + 1] * total
    for S in range(1, full):
        rem = total - wsub[S]
        for last in range(n):
            if not (S >> last) & 1:
                continue
            v = f[S, last]
            if v == np.inf:
                continue
            for nxt in range(n):
                if (S >> nxt) & 1:
                    continue
                c = v + M[last + 1, nxt + 1] * rem
                S2 = S | (1 << nxt)
                if c < f[S2, nxt]:
                    f[S2, nxt] = c
                    parent[S2, nxt] = last
    order = np.empty(n, dtype=np.int64)
    S = full - 1
    last = 0
    for j in range(1, n):
        if f[S, j] < f[S, last]:
            last = j
    for k in range(n - 1, -1, -1):
        order[k] = last + 1
        p = parent[S, last]
        S ^= 1 << last
        last = p
    return order


def solve_exact(M: np.ndarray, W: np.ndarray) -> WTRPSolution:
    """Optimal WTRP order for n <= MAX_EXACT_N nodes (see module docstring)."""
    t0 = time.perf_counter()
    M, w = check_instance(M, W)
    n = M.shape[0] - 1
    if n > MAX_EXACT_N:
        raise WTRPError(f"exact WTRP supports n <= {MAX_EXACT_N} nodes, got n = {n}; use 'ils'",
                        field="method")
    if n == 0:
        return WTRPSolution((), 0.0, "exact", time.perf_counter() - t0)
    order = tuple(int(v) for v in _dp(M, w))
    check_order(order, n)
    return WTRPSolution(order, wtrp_cost(M, w[1:], order), "exact", time.perf_counter() - t0)
