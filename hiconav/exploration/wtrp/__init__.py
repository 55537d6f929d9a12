"""WTRP ordering of frontiers (paper section "Goal Selection and Planning", eq. 15):
minimise sum_i W_pi(i) * C_i(pi) over open paths from the robot (node 0).

One entry point, ``solve_wtrp``, and a registry of solvers by name (``WTRP_SOLVERS``):
"exact" (DP over subsets, n <= 18), "ils" (GILS-RVND with O(1) move evaluation, numba),
"ortools" (routing with a soft-bounded time dimension; a comparison, weak here), "greedy"
(nearest cost/weight ratio; the baseline). "auto" = exact for n <= 12, else ils.
"""

from __future__ import annotations

import numpy as np

from hiconav.exploration.wtrp.common import WTRPError, WTRPSolution, check_instance, wtrp_cost
from hiconav.registry import Registry

WTRP_SOLVERS: Registry = Registry("WTRP solver")
AUTO_EXACT_MAX_N = 12


def _exact(M, W, time_limit, seed):
    from hiconav.exploration.wtrp.exact import solve_exact
    return solve_exact(M, W)


def _ils(M, W, time_limit, seed):
    from hiconav.exploration.wtrp.ils import solve_ils
    return solve_ils(M, W, time_limit=time_limit, seed=seed)


def _ortools(M, W, time_limit, seed):
    from hiconav.exploration.wtrp.ortools_solver import solve_ortools
    return solve_ortools(M, W, time_limit=1.0 if time_limit is None else time_limit)


def _greedy(M, W, time_limit, seed):
    from hiconav.exploration.wtrp.greedy import solve_greedy
    return solve_greedy(M, W)


WTRP_SOLVERS.add("exact", _exact)
WTRP_SOLVERS.add("ils", _ils)
WTRP_SOLVERS.add("ortools", _ortools)
WTRP_SOLVERS.add("greedy", _greedy)


def solve_wtrp(M: np.ndarray, W: np.ndarray, method: str = "auto", time_limit: float | None = 1.0,
               seed: int = 0) -> WTRPSolution:
    """Order nodes 1..n of the (n+1, n+1) cost matrix ``M`` (node 0 = robot, open path) to
    minimise the weighted latency with weights ``W`` (n,).

    method: "auto" | "exact" | "ils" | "ortools" | "greedy" (or a registered/import-path name
    of a callable (M, W, time_limit, seed) -> WTRPSolution). time_limit: seconds for the
    metaheuristics (None: ils runs its full deterministic schedule). Returns WTRPSolution
    (order of node indices 1..n, cost, method, seconds).
    """
    M, w = check_instance(M, W)
    n = M.shape[0] - 1
    if method == "auto":
        method = "exact" if n <= AUTO_EXACT_MAX_N else "ils"
    solver = WTRP_SOLVERS.get(method, field="method")
    return solver(M, w[1:], time_limit, seed)


__all__ = ["WTRP_SOLVERS", "WTRPError", "WTRPSolution", "solve_wtrp", "wtrp_cost"]
