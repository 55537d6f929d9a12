"""The paper's failure taxonomy (section "Failure Case Analysis"), computed from episode traces.

Categories (defined in docs/evaluation.md):
- ``success``: stopped within the success distance of a goal instance.
- ``false_positive``: the agent stopped (called STOP) but not near a goal instance.
- ``no_frontier``: the agent ran out of frontiers without finding the target.
- ``stuck``: no progress for ``stuck_window`` steps at the end of the episode (the robot stayed
  within ``progress_radius`` of its final position), whatever ended it.
- ``step_out``: the step limit was reached while the robot was still making progress.
- ``invalid_episode``: bad input (house not loadable, start not navigable, unknown category):
  reported and counted, the navigator is not run.
- ``error``: the runner raised; the message is in the record.

The paper's "different floor" category cannot occur here: every episode stays on one floor.
This module must not run episodes; it only reads trace fields.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from typing import Any

import numpy as np


class Failure(str, enum.Enum):
    SUCCESS = "success"
    FALSE_POSITIVE = "false_positive"
    NO_FRONTIER = "no_frontier"
    STUCK = "stuck"
    STEP_OUT = "step_out"
    INVALID_EPISODE = "invalid_episode"
    ERROR = "error"


#: Display order in tables and plots.
CATEGORIES: tuple[str, ...] = tuple(f.value for f in Failure)

DEFAULT_STUCK_WINDOW = 50
DEFAULT_PROGRESS_RADIUS = 0.5


def last_progress_step(positions: np.ndarray, radius: float = DEFAULT_PROGRESS_RADIUS) -> int:
    """The last step at which the robot was farther than ``radius`` m from its final position.

    positions: (T, 2) world xy of the robot after each step (row 0 = the start). Returns 0
    when the robot never left the disc (it made no progress at all).
    """
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    if len(positions) == 0:
        return 0
    far = np.flatnonzero(np.linalg.norm(positions - positions[-1], axis=1) > radius)
    return int(far[-1]) if len(far) else 0


def classify(trace: Mapping[str, Any], *, stuck_window: int = DEFAULT_STUCK_WINDOW) -> Failure:
    """Failure category of one episode from its trace fields.

    Reads: ``error`` / ``error_kind``, ``success``, ``termination`` ("stop" | "no_frontier" |
    "step_limit" | "stuck" | "error"), ``steps``, ``max_steps``, ``last_progress_step`` (None =
    unknown). Precedence: error > success > false positive > no frontier > stuck > step-out.
    """
    if trace.get("error"):
        return Failure.INVALID_EPISODE if trace.get("error_kind") == "data" else Failure.ERROR
    if trace.get("success"):
        return Failure.SUCCESS
    termination = trace.get("termination")
    if termination == "stop":
        return Failure.FALSE_POSITIVE
    if termination == "no_frontier":
        return Failure.NO_FRONTIER
    steps = int(trace.get("steps", 0))
    last = trace.get("last_progress_step")
    if termination == "stuck" or (last is not None and steps - int(last) >= stuck_window):
        return Failure.STUCK
    if termination == "step_limit" or steps >= int(trace.get("max_steps", steps + 1)):
        return Failure.STEP_OUT
    return Failure.ERROR  # an unknown termination is a runner bug, never a silent step-out
