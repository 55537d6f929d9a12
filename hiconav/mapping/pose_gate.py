"""The pose gate: a frame whose base pose jumped farther than the robot can move is refused.

A localisation glitch (a SLAM relocalisation, a bad MAVLink message, a corrupt recording) can put
the base pose metres or kilometres away from where the robot was a moment ago; integrated, such
a frame paints the map in the wrong place or makes the grid grow without bound. The gate keeps the
pose and stamp of the last accepted frame and refuses (``PoseJumpError``, a ``FrameError``) a
frame that moved more than ``max_speed_mps * elapsed + margin_m`` since then. The bound grows with
the time since the last accepted frame, so a genuine slow move is accepted again once the robot
could have made it. The first frame is always accepted.

It is pure and synchronous: the memory actor asks it before integrating and tells it what it
integrated. It must not modify frames or maps.
"""

from __future__ import annotations

import math

from hiconav.errors import FrameError
from hiconav.mapping.config import PoseGateConfig
from hiconav.types import Frame

__all__ = ["PoseGate", "PoseJumpError"]


class PoseJumpError(FrameError):
    """The frame's base pose moved farther since the last accepted frame than the robot can."""


class PoseGate:
    """Refuses frames whose base pose jumped beyond what ``config.max_speed_mps`` allows.

    Attributes: last ((x, y, stamp) of the last accepted frame, or None), n_rejected.
    """

    def __init__(self, config: PoseGateConfig | None = None) -> None:
        self.config = config or PoseGateConfig()
        self.last: tuple[float, float, float] | None = None
        self.n_rejected = 0

    def allowed_jump(self, elapsed_s: float) -> float:
        """Largest move (m) accepted after ``elapsed_s`` seconds (negative elapsed counts as 0)."""
        c = self.config
        return c.max_speed_mps * max(float(elapsed_s), 0.0) + c.margin_m

    def check(self, frame: Frame) -> None:
        """Raise ``PoseJumpError`` (and count it) when ``frame`` jumped too far; changes nothing else.

        A frame without a base pose passes: its consumers refuse it with their own error.
        """
        bp = frame.base_pose
        if self.last is None or bp is None:
            return
        x, y, stamp = self.last
        moved = math.hypot(bp.x - x, bp.y - y)
        elapsed = float(frame.stamp) - stamp
        allowed = self.allowed_jump(elapsed)
        if not moved <= allowed:  # NaN too
            self.n_rejected += 1
            raise PoseJumpError(
                f"base pose moved {moved:.3g} m in {elapsed:.3g} s since the last accepted frame, more than "
                f"{allowed:.3g} m (mapping.pose_gate: max_speed_mps = {self.config.max_speed_mps:g} m/s "
                f"x elapsed + margin_m = {self.config.margin_m:g} m): a localisation jump, frame dropped",
                field="frame.base_pose",
            )

    def accept(self, frame: Frame) -> None:
        """Remember ``frame``'s pose and stamp as the reference for the next check."""
        bp = frame.base_pose
        if bp is not None:
            self.last = (float(bp.x), float(bp.y), float(frame.stamp))
