"""Context-aware frontier exploration (paper "Context-Aware Frontier Exploration" and "Goal
Selection and Planning"): frontier utility (S_struct, S_vis), utility-induced weights, motion
cost, WTRP ordering and the planner with goal hysteresis.

Public API: ``ExplorationPlanner``, ``ExplorationPlan``, ``ExplorationConfig``, ``solve_wtrp``,
``WTRPSolution``, ``wtrp_cost``, ``frontier_utility``, ``utility_weights``, ``cost_matrix``.
Heavy solver backends (numba kernels, OR-Tools) load on first use.
"""

from hiconav.exploration.config import CostConfig, ExplorationConfig, OrderingConfig, UtilityConfig
from hiconav.exploration.cost import CostMatrix, cost_matrix, geodesic_distances, openness
from hiconav.exploration.planner import ExplorationPlan, ExplorationPlanner
from hiconav.exploration.utility import frontier_utility, utility_weights
from hiconav.exploration.wtrp import WTRP_SOLVERS, WTRPError, WTRPSolution, solve_wtrp, wtrp_cost

__all__ = [
    "WTRP_SOLVERS",
    "CostConfig",
    "CostMatrix",
    "ExplorationConfig",
    "ExplorationPlan",
    "ExplorationPlanner",
    "OrderingConfig",
    "UtilityConfig",
    "WTRPError",
    "WTRPSolution",
    "cost_matrix",
    "frontier_utility",
    "geodesic_distances",
    "openness",
    "solve_wtrp",
    "utility_weights",
    "wtrp_cost",
]
