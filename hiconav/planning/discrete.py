"""Converter from a path to Habitat-style discrete actions: turn to within a tolerance, then forward.

Pure functions; it must not plan (the path comes from A*).
"""

from __future__ import annotations

import math

import numpy as np

from hiconav.types import DiscreteAction, Pose2D, wrap_angle

__all__ = ["heading_action", "to_discrete"]


def heading_action(pose: Pose2D, yaw: float, tolerance_deg: float = 15.0) -> DiscreteAction | None:
    """TURN_LEFT / TURN_RIGHT toward ``yaw`` (rad), or None when already within the tolerance."""
    err = wrap_angle(yaw - pose.yaw)
    if abs(err) <= math.radians(tolerance_deg):
        return None
    return DiscreteAction.TURN_LEFT if err > 0 else DiscreteAction.TURN_RIGHT


def to_discrete(pose: Pose2D, target_xy: np.ndarray, tolerance_deg: float = 15.0) -> DiscreteAction:
    """Turn toward ``target_xy`` (2,) world m until within ``tolerance_deg``, then MOVE_FORWARD."""
    d = np.asarray(target_xy, dtype=np.float64) - pose.xy
    turn = heading_action(pose, math.atan2(d[1], d[0]), tolerance_deg)
    return turn if turn is not None else DiscreteAction.MOVE_FORWARD
