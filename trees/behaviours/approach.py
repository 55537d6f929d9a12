"""Approach: reach a free cell within the final distance of the target, facing it.

A thin poller of the approach planner (``hiconav.decisions.approach``): it reads the context's
grid, memory and navigation status, asks the planner, and posts the goals it names (a ring cell,
the straight way in or a creep, a turn to face the target); thresholds come from
``decisions.approach``. Nothing here blocks, talks to an actor or decides geometry itself.
"""

from __future__ import annotations

import math

import numpy as np

from hiconav.decisions import approach as plan
from hiconav.decisions import last_resort as resort
from hiconav.trees.behaviours.base import Status
from hiconav.trees.behaviours.goto import _GoToObject
from hiconav.trees.context import Candidate
from hiconav.trees.registry import register_behaviour


@register_behaviour()
class Approach(_GoToObject):
    """Reach a free cell within ``distance`` of the target's footprint (in front of its middle:
    ``centre_weight``), facing it. With no cell reachable or time run out, the target is deferred
    (``defer_s``) before FAILURE, so that a Retry above explores on instead of picking it again.
    A last resort (``hiconav.decisions.last_resort``) tries rings out to ``last_resort_m``, then
    stops where it stands, facing the target."""

    SETTINGS = "approach"

    def _centre_weight(self) -> float:
        return self.param("centre_weight")

    def _corner_radius(self) -> float:
        return self.param("corner_radius")

    def initialise(self) -> None:
        self._start, self._seq, self._cell, self._attempts = self.context.now(), None, None, 0
        self._excluded: list[np.ndarray] = []  # approach cells that failed (world xy)
        self._ring = 0.0  # the approach ring the current goal came from (m)
        self._turned = self._crept = self._straight = False  # _straight: the creep is the straight way in

    def update(self) -> Status:
        ctx, s = self.context, self.settings
        cand: Candidate | None = self.read("target")
        if self._lost(cand):
            return Status.FAILURE
        pose = ctx.pose
        if pose is not None and not (self._crept and not self._turned) and plan.done(
                np.array([pose.x, pose.y]), pose.yaw, self._gap(cand)[0], self._ring, self._cell, self._turned,
                cand.center, s):
            if plan.settled_beyond(self._ring, s) and not self._crept and self._creep(cand):
                return self._running(f"creeping toward {cand.label} #{cand.object_id}")
            self.feedback_message = f"at {cand.label} #{cand.object_id}"
            return Status.SUCCESS
        if ctx.now() - self._start > s.timeout_s:
            return self._give_up(cand, "timed out")
        state = "pending" if self._seq is None else ctx.nav_state(self._seq)
        if self._seq is None and self._attempts == 0 and not self._crept and self._straight_in(cand):
            return self._running(f"stepping in toward {cand.label} #{cand.object_id}")
        if self._crept and not self._turned and (state in ("failed", "reached")
                                                 or ctx.now() - self._crept_at > s.creep_s):
            if not (self._straight and self._gap(cand)[0] > s.distance):
                self._face(cand)  # the creep ended: face the object; done judges it on the ring settled for
                return Status.RUNNING
            ctx.send_goal(None)  # the straight way in ended short (the map did not know): the ring cells
            self._straight = self._crept = False
            self._seq, state = None, "pending"
        if state == "reached" and self._cell is not None and not self._crept and plan.creeps_on(self._ring, s) \
                and self._creep(cand):
            return self._running(f"creeping toward {cand.label} #{cand.object_id}")
        if (self._seq is None or state in ("failed", "reached") or self._stalled()) and not self._next_goal(cand):
            return self._give_up(cand, "no reachable approach cell")
        return self._running(f"approaching {cand.label} #{cand.object_id}")

    def _running(self, feedback: str) -> Status:
        self.feedback_message = feedback
        return Status.RUNNING

    def _next_goal(self, cand: Candidate) -> bool:
        """The next ring cell (``plan.ring_order``), or a turn when close; False: none on a known map."""
        ctx, s = self.context, self.settings
        if self._seq is not None and self._cell is not None:
            self._excluded.append(self._cell)
        self._attempts += 1
        wide = cand.source == resort.SOURCE
        for t in plan.ring_order(s, wide) if self._attempts <= s.max_attempts else []:
            if self._send(cand, t.ring, strict_walls=t.strict, box_weight=t.box_weight):
                self._ring = t.ring
                return True
        move = None if ctx.pose is None else plan.without_cell(self._gap(cand)[0], wide, self._turned, self._crept, s)
        if move is not None:
            self._ring = math.inf if wide else self._ring  # a last resort is done wherever it stops
            if not (move == "creep" and self._creep(cand)):
                self._face(cand)
            return True
        return ctx.grid is None or ctx.pose is None

    def _gap(self, cand: Candidate) -> plan.Gap:
        """(planar distance m, the object's nearest point xy) from the robot (``plan.gap``)."""
        pose, s = self.context.pose, self.settings
        points = getattr(self.context.object(cand.object_id), "points", None) if s.measure == "points" else None
        return plan.gap(np.array([pose.x, pose.y]), cand.box_min, cand.box_max, points, s)

    def _straight_in(self, cand: Candidate) -> bool:
        """Creep straight in when the planner finds the way clear (``plan.straight_way_in``); True when sent."""
        ctx, s = self.context, self.settings
        if s.straight_within <= 0.0 or ctx.pose is None or ctx.grid is None:
            return False
        measured = self._gap(cand)
        if not plan.straight_way_in(ctx.grid, np.array([ctx.pose.x, ctx.pose.y]), cand.box_min, cand.box_max,
                                    measured, s, self._furniture(cand), self._wall_heights(cand)):
            return False
        self._straight = self._creep(cand, measured)  # beyond the distance, so it always sends (True)
        ctx.log(f"#{cand.object_id} {measured[0]:.2f} m off, the way in clear: stepping straight in")
        return True

    def _face(self, cand: Candidate) -> None:
        """Turn in place toward the target (done then needs no approach cell)."""
        pose, self._turned, self._cell = self.context.pose, True, None
        self._seq = self.context.send_goal(plan.face_goal(pose.x, pose.y, cand.center, cand.object_id,
                                                          self.settings))

    def _creep(self, cand: Candidate, measured: plan.Gap | None = None) -> bool:
        """A straight goal to ``plan.creep_goal`` through unknown floor; False when already close."""
        measured = self._gap(cand) if measured is None else measured
        goal = plan.creep_goal(measured, cand.object_id, self.settings)
        if goal is None:
            return False
        self._crept, self._crept_at, self._cell = True, self.context.now(), measured.near
        self._seq = self.context.send_goal(goal)
        return True

    def _give_up(self, cand: Candidate, why: str) -> Status:
        # no approach cell on this map: due again once the map around it has grown (as VerifyTarget)
        unreachable = why == "no reachable approach cell"
        self.context.reject(cand.object_id, f"approach: {why}", permanent=False, defer_s=self.param("defer_s"),
                            remap=unreachable, out_of_reach=unreachable)
        self.feedback_message = why
        return Status.FAILURE
