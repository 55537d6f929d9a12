"""Local planner: pure-pursuit velocity commands along a world-frame path, with limits.

Pure and stateless apart from the last commanded speed (for the acceleration limit). It must
not plan around obstacles: the path it follows comes from A* on the inflated grid.
"""

from __future__ import annotations

import math

import numpy as np

from hiconav.planning.config import LocalPlannerConfig
from hiconav.types import Pose2D, VelocityCommand, wrap_angle

__all__ = ["PurePursuit", "lookahead_point", "segment_target"]


def lookahead_point(path_xy: np.ndarray, xy: np.ndarray, lookahead: float) -> tuple[np.ndarray, int]:
    """The point ``lookahead`` m ahead along ``path_xy`` (N, 2) from its point nearest to ``xy``.

    Returns (point (2,), index of the segment it lies on). The path end is returned when the
    remaining path is shorter than the lookahead.
    """
    path_xy = np.asarray(path_xy, dtype=np.float64)
    if path_xy.shape[0] == 1:
        return path_xy[0].copy(), 0
    a, b = path_xy[:-1], path_xy[1:]
    ab = b - a
    L2 = np.maximum((ab**2).sum(axis=1), 1e-12)
    t = np.clip(((xy - a) * ab).sum(axis=1) / L2, 0.0, 1.0)
    proj = a + t[:, None] * ab
    d = np.hypot(*(proj - xy).T)
    k = int(np.argmin(d))
    seg_len = np.sqrt(L2)
    remaining = lookahead
    pos_t = t[k]
    for i in range(k, len(ab)):
        left = seg_len[i] * (1.0 - pos_t)
        if left >= remaining:
            return a[i] + ab[i] * (pos_t + remaining / seg_len[i]), i
        remaining -= left
        pos_t = 0.0
    return path_xy[-1].copy(), len(ab) - 1


def segment_target(path_xy: np.ndarray, xy: np.ndarray, lookahead: float, switch: float) -> np.ndarray:
    """Lookahead point that never cuts a corner of the path (N, 2).

    The point ``lookahead`` m ahead along the path, but no farther than the end of the segment the
    robot is on; once that corner is within ``switch`` m, the next segment is used. Straight
    segments between waypoints are collision-free by construction (line-of-sight smoothing), so
    steering at their points keeps the robot off the inflated obstacles.
    """
    path_xy = np.asarray(path_xy, dtype=np.float64)
    if len(path_xy) == 1:
        return path_xy[0].copy()
    _, seg = lookahead_point(path_xy, xy, 0.0)  # the segment the robot is on
    corner = path_xy[seg + 1]
    if np.hypot(*(corner - xy)) > switch or seg + 2 >= len(path_xy):
        target, target_seg = lookahead_point(path_xy, xy, lookahead)
        return corner.copy() if target_seg > seg else target
    # at the corner: steer along the next segment
    nxt = path_xy[seg + 2]
    length = float(np.hypot(*(nxt - corner)))
    return corner + (nxt - corner) * min(1.0, lookahead / length) if length > 1e-9 else nxt.copy()


class PurePursuit:
    """Velocity commands that follow a path: curvature 2 sin(alpha) / L_d, speed and rate limits."""

    def __init__(self, config: LocalPlannerConfig | None = None) -> None:
        self.config = config or LocalPlannerConfig()
        self._v = 0.0

    def reset(self) -> None:
        self._v = 0.0

    def command(self, pose: Pose2D, path_xy: np.ndarray, dt: float, stamp: float = 0.0) -> VelocityCommand:
        """Velocity toward the lookahead point of ``path_xy`` (N, 2) world m; zero at the path end."""
        c = self.config
        xy = pose.xy
        goal = np.asarray(path_xy[-1], dtype=np.float64)
        dist_goal = float(np.hypot(*(goal - xy)))
        target = segment_target(path_xy, xy, c.lookahead_m, switch=0.1)
        d = target - xy
        ld = float(np.hypot(*d))
        if ld < 1e-6:
            self._v = 0.0
            return VelocityCommand.zero(stamp)
        alpha = wrap_angle(math.atan2(d[1], d[0]) - pose.yaw)
        if abs(alpha) > math.radians(c.rotate_in_place_deg):
            self._v = 0.0
            omega = float(np.clip(c.heading_gain * alpha, -c.omega_max, c.omega_max))
            return VelocityCommand(0.0, omega, stamp)
        v_des = c.v_max * max(0.0, math.cos(alpha))
        if c.slow_down_m > 0:
            v_des *= min(1.0, max(0.2, dist_goal / c.slow_down_m))
        v = min(v_des, self._v + c.accel_max * max(dt, 0.0))
        omega = 2.0 * v * math.sin(alpha) / max(ld, 1e-3)  # pure pursuit curvature * v
        if abs(omega) > c.omega_max:  # keep the curvature: scale v down with omega
            scale = c.omega_max / abs(omega)
            v *= scale
            omega *= scale
        self._v = v
        return VelocityCommand(float(v), float(omega), stamp)
