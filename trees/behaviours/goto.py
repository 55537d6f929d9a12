"""Shared machinery of VerifyTarget and Approach: a free cell near a candidate's footprint, the
goal to it facing the candidate, and the stall clock (no progress toward a goal). Pure polling:
nothing here blocks or talks to an actor.
"""

from __future__ import annotations

import math

import numpy as np

from hiconav.decisions.confirmation import withdrawn
from hiconav.decisions.cells import camera_of, cell_near, furniture_boxes, wall_heights
from hiconav.decisions.progress import StallClock
from hiconav.decisions.geometry import facing as _facing
from hiconav.trees.behaviours.base import MissionBehaviour, Status
from hiconav.trees.context import Candidate
from hiconav.types import Goal


class _GoToObject(MissionBehaviour):
    """Shared machinery: choose a free cell near the candidate's footprint and go there facing it.

    ``_stall`` (``StallClock``) lives as long as the behaviour: a new goal cell resets it, a new
    activation does not."""

    def __init__(self, *args, **kwargs) -> None:  # type: ignore[no-untyped-def]
        super().__init__(*args, **kwargs)
        self._stall = StallClock()

    READS = ("target",)

    def _lost(self, cand: Candidate | None, no_target: str = "no target") -> bool:
        """True (the behaviour fails; feedback ``no_target``) when there is no target, or when the
        reasoning layer has withdrawn ``cand`` (``hiconav.decisions.confirmation.withdrawn``; its
        goal is cancelled, and the candidate list no longer offers it)."""
        ctx = self.context
        if cand is None:
            self.feedback_message = no_target
            return True
        if not withdrawn(cand.source, cand.object_id, ctx.withdrawn):
            return False
        ctx.send_goal(None)
        self.feedback_message = f"{cand.label} #{cand.object_id}: withdrawn by the reasoning layer"
        return True

    def _centre_weight(self) -> float:
        """approach_cell's weight on a cell's distance to the footprint's centre (see Approach)."""
        return 0.0

    def _prefer_weight(self) -> float:
        """approach_cell's weight on a cell's distance to ``_preferred_xy`` (``view_ray_weight``:
        see VerifyTarget; 0 for a behaviour without it)."""
        return float(getattr(self.settings, "view_ray_weight", 0.0))

    def _corner_radius(self) -> float:
        """approach_cell's rounding of the box's corners (see Approach); 0: the box."""
        return 0.0

    def _preferred_xy(self, cand: Candidate, distance: float) -> np.ndarray | None:
        """A point the approach cell should lie near, or None (no preference)."""
        return None

    def _here(self, cand: Candidate, distance: float, rules: dict) -> np.ndarray | None:
        """Where the robot stands (world xy) when that will do for a cell within ``distance`` of
        the candidate under ``rules`` (``_send``'s, as ``cell_near`` takes them; see VerifyTarget),
        else None: a cell is searched."""
        return None

    def _sight(self, cand: Candidate) -> tuple[np.ndarray, float, np.ndarray, np.ndarray] | None:
        """approach_cell's ``sight`` argument, or None: cells need not see the candidate."""
        return None

    def _camera(self) -> tuple[float, float] | None:
        return camera_of(self.context.memory)

    def _furniture(self, cand: Candidate) -> list[tuple[np.ndarray, np.ndarray]]:
        return furniture_boxes(self.context.memory, cand.object_id)

    def _wall_heights(self, cand: Candidate) -> tuple[float, float] | None:
        return wall_heights(self.context.memory, float(np.asarray(cand.box_max)[2]))

    def _send(self, cand: Candidate, distance: float, strict_walls: bool = False, box_weight: float = 0.0) -> bool:
        """Go to a cell within ``distance`` of the candidate's footprint (``cell_near``), facing it."""
        ctx = self.context
        pose = ctx.pose
        if pose is None or ctx.grid is None:
            return False
        rules = {"centre_weight": self._centre_weight(), "prefer_xy": self._preferred_xy(cand, distance),
                 "prefer_weight": self._prefer_weight(), "sight": self._sight(cand),
                 "furniture": self._furniture(cand), "strict_walls": strict_walls, "box_weight": box_weight,
                 "wall_heights": self._wall_heights(cand), "corner_radius": self._corner_radius(),
                 "path_cost": bool(getattr(self.settings, "path_cost", False))}
        here = self._here(cand, distance, rules)
        if here is not None:
            self._go_to_cell(cand, here, 0.2)
            return True
        cell = cell_near(ctx.grid, cand.box_min, cand.box_max, np.array([pose.x, pose.y]), distance, self._excluded,
                         **rules)
        if cell is None:
            return False
        self._go_to_cell(cand, cell, 0.2)
        return True

    def _go_to_cell(self, cand: Candidate, cell: np.ndarray, tolerance: float, through_unknown: bool = False) -> None:
        """Send the goal ``cell`` (world xy) facing the candidate, and restart the stall clock."""
        self._cell = cell
        self._stall.reset()
        self._seq = self.context.send_goal(Goal(float(cell[0]), float(cell[1]), _facing(cell, cand.center),
                                                tolerance, "approach", cand.object_id,
                                                through_unknown=through_unknown))

    def _stall_near(self) -> float:
        """Within this of the goal cell the robot is there (``stall_near``: VerifyTarget glances
        about its view cell; 0 for a behaviour without it)."""
        return float(getattr(self.settings, "stall_near", 0.0))

    def _stalled(self) -> bool:
        """True when the robot has made no progress toward the goal cell for ``stall_s``."""
        pose, cell = self.context.pose, getattr(self, "_cell", None)
        if pose is None or cell is None or getattr(self, "_seq", None) is None:
            return False
        return self._stall.stalled(math.hypot(pose.x - cell[0], pose.y - cell[1]), self.context.now(),
                                   self.param("stall_s"), self._stall_near())

    def cleanup(self, new_status: Status) -> None:
        if getattr(self, "_seq", None) is not None and self.ctx is not None and new_status != Status.SUCCESS:
            self.ctx.send_goal(None)
        self._seq = None
