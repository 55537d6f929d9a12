"""Mapping: the occupancy grid built from depth (free / occupied / unknown, inflation) and frontiers."""

from hiconav.mapping.config import FrontierConfig, MappingConfig, OccupancyConfig, PoseGateConfig
from hiconav.mapping.frontiers import FrontierTracker, frontier_mask
from hiconav.mapping.occupancy import FREE, OCCUPIED, UNKNOWN, GridSnapshot, IntegrationStats, OccupancyGrid
from hiconav.mapping.pose_gate import PoseGate, PoseJumpError

__all__ = [
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "FrontierConfig",
    "FrontierTracker",
    "GridSnapshot",
    "IntegrationStats",
    "MappingConfig",
    "OccupancyConfig",
    "OccupancyGrid",
    "PoseGate",
    "PoseGateConfig",
    "PoseJumpError",
    "frontier_mask",
]
