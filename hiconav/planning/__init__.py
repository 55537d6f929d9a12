"""Planning: A* on the inflated grid, path smoothing, pure-pursuit local planner, discrete actions,
and the Navigator that ties them together with re-planning and recovery."""

from hiconav.planning.astar import astar, line_of_sight, path_length, smooth_path
from hiconav.planning.config import DiscreteConfig, LocalPlannerConfig, NavigatorConfig
from hiconav.planning.discrete import heading_action, to_discrete
from hiconav.planning.local_planner import PurePursuit, lookahead_point
from hiconav.planning.navigator import Navigator, blocked_cells, plan_path

__all__ = [
    "DiscreteConfig",
    "LocalPlannerConfig",
    "Navigator",
    "NavigatorConfig",
    "PurePursuit",
    "astar",
    "blocked_cells",
    "heading_action",
    "line_of_sight",
    "lookahead_point",
    "path_length",
    "plan_path",
    "smooth_path",
    "to_discrete",
]
