"""The stall clock: has the robot come nearer a goal lately?

A navigator can rock in a doorway, or glance about a cell it cannot quite reach, for hundreds of
steps while a behaviour's timeout (tens of clock seconds) has not run out. The stall clock keeps
the robot's best distance to the goal and the clock time it was reached: coming ``progress`` m
nearer (or being within ``near`` of the goal, where glancing about is the work) restarts it; no
such progress for ``limit_s`` is a stall. Pure: the caller passes distances and clock times.
"""

from __future__ import annotations


class StallClock:
    """Best distance to the goal in flight and when it was reached; ``reset()`` with each goal."""

    def __init__(self) -> None:
        self.best: tuple[float, float] | None = None  # (best distance m, clock time s)

    def reset(self) -> None:
        self.best = None

    def stalled(self, distance: float, now: float, limit_s: float, near: float = 0.35,
                progress: float = 0.25) -> bool:
        """True when the robot, ``distance`` m from the goal at clock time ``now``, has come no
        ``progress`` m nearer than its best for more than ``limit_s`` and is not within ``near``."""
        if self.best is None or distance < self.best[0] - progress or distance <= near:
            self.best = (distance, now)
            return False
        return now - self.best[1] > limit_s


__all__ = ["StallClock"]
