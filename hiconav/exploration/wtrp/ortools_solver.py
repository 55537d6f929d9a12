"""WTRP with OR-Tools routing: a comparison, not the planner's solver.

Model: one vehicle from node 0 to a dummy end node n+1 (every arc into it costs 0: an open
path); a time dimension with the (scaled, integer) transit costs; the cumul at node i carries
a soft upper bound 0 with coefficient W_i (scaled to integers), so the penalty sum is the
weighted latency sum_i W_i C_i. Arc costs are the transit times too (GLS needs arc costs to
penalise); with weights scaled by ``weight_scale`` the latency dominates. Guided local search
within ``time_limit``. The returned cost is re-evaluated exactly in floating point.
This module must not be imported by code that does not use OR-Tools (it is loaded lazily).
"""

from __future__ import annotations

import math
import time

import numpy as np

from hiconav.exploration.wtrp.common import WTRPSolution, check_instance, check_order, wtrp_cost


def solve_ortools(M: np.ndarray, W: np.ndarray, *, time_limit: float = 1.0, cost_scale: float | None = None,
                  weight_scale: float = 1000.0) -> WTRPSolution:
    """OR-Tools routing for the WTRP (see module docstring). M (n+1, n+1), W (n,)."""
    from ortools.constraint_solver import pywrapcp, routing_enums_pb2

    t0 = time.perf_counter()
    M, w = check_instance(M, W)
    n = M.shape[0] - 1
    if n <= 1:
        order = tuple(range(1, n + 1))
        return WTRPSolution(order, wtrp_cost(M, w[1:], order), "ortools", time.perf_counter() - t0)
    if cost_scale is None:  # integers stay exact; otherwise ~1e4 levels over the range
        integral = np.allclose(M, np.round(M))
        cost_scale = 1.0 if integral else 1e4 / max(float(M.max()), 1e-12)
    Mi = np.zeros((n + 2, n + 2), dtype=np.int64)
    Mi[: n + 1, : n + 1] = np.round(M * cost_scale).astype(np.int64)
    Mi[:, 0] = 0
    Mi[:, n + 1] = 0  # to the dummy end: free (open path)
    Wi = np.round(w * weight_scale / max(float(w.max()), 1e-12)).astype(np.int64)
    horizon = int(Mi.max(axis=1).sum()) + 1

    manager = pywrapcp.RoutingIndexManager(n + 2, 1, [0], [n + 1])
    routing = pywrapcp.RoutingModel(manager)
    rows = Mi.tolist()

    def transit(i: int, j: int) -> int:
        return rows[manager.IndexToNode(i)][manager.IndexToNode(j)]

    cb = routing.RegisterTransitCallback(transit)
    routing.SetArcCostEvaluatorOfAllVehicles(cb)
    routing.AddDimension(cb, 0, horizon, True, "time")
    dim = routing.GetDimensionOrDie("time")
    for i in range(1, n + 1):
        dim.SetCumulVarSoftUpperBound(manager.NodeToIndex(i), 0, int(max(Wi[i], 0)))
    params = pywrapcp.DefaultRoutingSearchParameters()
    params.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC
    params.local_search_metaheuristic = routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    remaining = max(0.05, time_limit - (time.perf_counter() - t0))
    params.time_limit.FromMilliseconds(math.ceil(remaining * 1000))
    sol = routing.SolveWithParameters(params)
    if sol is None:  # fallback, clearly labelled: OR-Tools found nothing in time
        order = tuple(int(i) for i in np.argsort(M[0, 1:], kind="stable") + 1)
        return WTRPSolution(order, wtrp_cost(M, w[1:], order), "ortools-failed-nearest",
                            time.perf_counter() - t0)
    order_l: list[int] = []
    idx = routing.Start(0)
    while not routing.IsEnd(idx):
        node = manager.IndexToNode(idx)
        if 1 <= node <= n:
            order_l.append(node)
        idx = sol.Value(routing.NextVar(idx))
    order = tuple(order_l)
    check_order(order, n)
    return WTRPSolution(order, wtrp_cost(M, w[1:], order), "ortools", time.perf_counter() - t0)
