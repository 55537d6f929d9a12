"""Explore: follow the exploration plan's WTRP order of frontiers (the mission's search).

Polls the context's plan and navigation status and posts frontier goals; thresholds come from
``decisions.explore``. Nothing here blocks or talks to an actor.
"""

from __future__ import annotations

import math

import numpy as np

from hiconav.decisions.progress import StallClock
from hiconav.trees.behaviours.base import MissionBehaviour, Status
from hiconav.trees.behaviours.goto import _stalled_toward
from hiconav.trees.registry import register_behaviour
from hiconav.types import Goal, Pose2D, wrap_angle


@register_behaviour()
class Explore(MissionBehaviour):
    """Follow the exploration plan: go to the first frontier of the WTRP order, re-planned as the
    map grows; FAILURE when no frontier is left for ``max_idle_s``. The idle clock is the mission
    context's (``last_frontier_time``), so an Explore retried after the map was explored out fails
    at once instead of idling (and turning) again for every retry.

    The robot goes to a frontier's viewpoint facing the frontier's centroid, so that on arrival
    the camera looks at it. A frontier can still outlive the visit: from its viewpoint the
    camera may not see it (the floor close to the robot is below the field of view, a wall
    nearer than the minimum depth reads nothing). When a plan made ``spent_after_s`` or more
    after reaching a viewpoint still has a frontier viewpoint within ``spent_radius`` of it,
    that spot is spent (``context.spent_viewpoints``): frontiers seen from there are skipped for
    the rest of the mission, instead of being reached, looked at and chosen again, under a new
    frontier id, for hundreds of steps. Before it is skipped, a spent frontier within
    ``push_radius`` of the robot is pushed into once (``push_through``): the robot drives to
    ``push_m`` beyond its centroid through floor the map does not know, as a person steps into
    a doorway to look along the corridor behind it (Gibson Tolstoy/0/2: the passage to the
    toilet opened at the robot's side, below the camera's view, and the mission ended with "no
    frontier left" after 33 of 500 steps).

    A frontier whose goal failed (no path, or no progress for ``stall_s``) is remembered for the
    mission (``context.failed_frontiers``): picking it again is no progress for the idle clock, so
    a retried Explore over unreachable frontiers fails instead of idling anew. With every frontier
    failed, each is tried once more (``squeeze``) as a goal through unknown floor, where the
    navigator falls back to the lethal layer one cell thinner.

    ``start_look_turns`` quarter turns in place come first, once per mission (the count lives in
    the context, so a retried Explore goes on where a preempted one stopped): the camera sees 79
    degrees, so without them the start room is only known in the direction the robot happened to
    face, and a target beside the start stayed unseen while the plan led away (ProcTHOR val/28/0:
    a fridge 1.9 m from the start, never in view in 500 steps). Turning costs steps but no path
    length."""

    SETTINGS = "explore"

    def initialise(self) -> None:
        self._seq: int | None = None
        self._frontier: int | None = None
        self._goal_xy: np.ndarray | None = None
        if self.context.last_frontier_time is None:
            self.context.last_frontier_time = self.context.now()
        self._visited: set[int] = set()
        self._reached: list[tuple[np.ndarray, float]] = []  # viewpoint, clock time: awaiting a newer plan
        self._start_look = False  # the goal in flight is one of the start's quarter turns
        self._push_at: float | None = None  # clock time the push in flight was sent
        self._squeezing = False  # the goal in flight is a squeeze toward a failed frontier
        self._nearest: float | None = None  # the robot's least distance to the goal in flight
        self._stall = StallClock()  # no progress toward the goal in flight

    def _quarter_turn(self, pose: Pose2D) -> None:
        """Turn in place a quarter turn to the left (a "look" goal); no frontier is pursued."""
        self._frontier, self._goal_xy = None, None
        self._seq = self.context.send_goal(Goal(pose.x, pose.y, wrap_angle(pose.yaw + math.pi / 2), 0.5, "look"))

    def _look_around_start(self) -> Status:
        """One quarter turn in place after another until ``start_look_turns`` are done."""
        ctx = self.context
        pose = ctx.pose
        if self._seq is None and pose is not None:
            self._quarter_turn(pose)
            self._start_look = True
        ctx.last_frontier_time = ctx.now()  # looking around is progress
        self.feedback_message = f"looking around the start ({ctx.start_looks}/{self.param('start_look_turns')})"
        return Status.RUNNING

    def _near_any(self, xy: np.ndarray, spots: list[tuple[float, float]]) -> bool:
        """True when ``xy`` lies within ``spent_radius`` of one of ``spots`` (spent viewpoints,
        pushed or squeezed frontier centroids: one visit per spot, whatever id the plan gives it)."""
        r = self.param("spent_radius")
        return any(math.hypot(xy[0] - x, xy[1] - y) <= r for x, y in spots)

    def _spent(self, xy: np.ndarray) -> bool:
        return self._near_any(xy, self.context.spent_viewpoints)

    def _settle_reached(self) -> None:
        """Mark reached viewpoints as spent once a plan made after the visit still shows a
        frontier viewpoint near them."""
        msg = self.context.plan
        if msg is None or not self._reached:
            return
        r = self.param("spent_radius")
        views = np.array([f.viewpoint for f in msg.frontiers], dtype=np.float64).reshape(-1, 2)
        waiting = []
        for xy, t in self._reached:
            if msg.stamp < t + self.param("spent_after_s"):
                waiting.append((xy, t))
            elif len(views) and float(np.min(np.hypot(*(views - xy).T))) <= r:
                self.context.spent_viewpoints.append((float(xy[0]), float(xy[1])))
                self.context.events.append(f"{self.context.now():.2f} frontier viewpoint "
                                           f"({xy[0]:.2f}, {xy[1]:.2f}) spent: reached, not cleared")
        self._reached = waiting

    def _push_goal(self, centroid: np.ndarray) -> tuple[np.ndarray, float] | None:
        """(goal xy, yaw) ``push_m`` beyond a spent frontier's ``centroid``, away from the robot,
        or None: pushing is off, the centroid is beyond ``push_radius`` or was pushed before."""
        pose = self.context.pose
        if not self.param("push_through") or pose is None:
            return None
        robot = np.array([pose.x, pose.y])
        d = centroid - robot
        dist = float(np.hypot(*d))
        if dist > self.param("push_radius") or self._near_any(centroid, self.context.pushed_frontiers):
            return None
        yaw = math.atan2(d[1], d[0]) if dist > 0.1 else pose.yaw
        goal = centroid + self.param("push_m") * np.array([math.cos(yaw), math.sin(yaw)])
        return goal, yaw

    def _nearer(self, by: float) -> bool:
        """True when the robot has come ``by`` m nearer the goal in flight than it has been since
        the goal was sent (``_nearest`` keeps the best distance; reset with each goal)."""
        pose = self.context.pose
        if pose is None or self._goal_xy is None:
            return False
        d = math.hypot(pose.x - self._goal_xy[0], pose.y - self._goal_xy[1])
        if self._nearest is None or d < self._nearest - by:
            first = self._nearest is None
            self._nearest = d
            return not first
        return False

    def _squeeze_pick(self) -> tuple[int, np.ndarray, float | None] | None:
        """(frontier id, viewpoint, yaw) of the first frontier of the plan's order that failed and
        was not squeezed yet (``context.squeezed_frontiers``), or None. Its goal goes through
        unknown floor, where the navigator plans on the lethal layer and then on it one cell
        thinner (``squeeze_mask``): a last resort before "no frontier left", as the map's grid
        phase can close a passage the robot fits (Gibson Onaga/0/1 idled 430 s in front of two
        rooms it could reach)."""
        msg = self.context.plan
        if msg is None or not self.param("squeeze"):
            return None
        frontiers = {f.id: f for f in msg.frontiers}
        for fid in list(getattr(msg.plan, "order", ()) or ()):
            f = frontiers.get(fid)
            if f is None or fid not in self.context.failed_frontiers:
                continue
            centroid = np.asarray(f.centroid, dtype=np.float64)
            if self._near_any(centroid, self.context.squeezed_frontiers):
                continue
            self.context.squeezed_frontiers.append((float(centroid[0]), float(centroid[1])))
            xy = np.asarray(f.viewpoint, dtype=np.float64)
            d = centroid - xy
            return fid, xy, (math.atan2(d[1], d[0]) if float(np.hypot(*d)) > 0.2 else None)
        return None

    def _pick(self) -> tuple[int, np.ndarray, float | None, bool] | None:
        """(frontier id, goal xy, yaw or None, push) for the first frontier of the plan's order
        that is not visited: its viewpoint facing its centroid, or, where that viewpoint is spent,
        a push into it (``_push_goal``); frontiers seen from spent spots that cannot be pushed
        into are skipped."""
        msg = self.context.plan
        if msg is None:
            return None
        frontiers = {f.id: f for f in msg.frontiers}
        order = list(getattr(msg.plan, "order", ()) or ())
        goal = getattr(msg.plan, "goal", None)
        if goal is not None and goal.id not in order:
            order.insert(0, goal.id)
        for fid in order:
            if fid in frontiers and fid not in self._visited:
                xy = np.asarray(frontiers[fid].viewpoint, dtype=np.float64)
                centroid = np.asarray(frontiers[fid].centroid, dtype=np.float64)
                if not self._spent(xy):
                    d = centroid - xy
                    yaw = math.atan2(d[1], d[0]) if float(np.hypot(*d)) > 0.2 else None
                    return fid, xy, yaw, False
                push = self._push_goal(centroid)
                if push is not None:
                    self.context.pushed_frontiers.append((float(centroid[0]), float(centroid[1])))
                    return fid, push[0], push[1], True
        return None

    def update(self) -> Status:
        ctx = self.context
        now = ctx.now()
        state = None if self._seq is None else ctx.nav_state(self._seq)
        if self._push_at is not None and state not in ("reached", "failed") and \
                now - self._push_at > self.param("push_s"):
            state = "failed"  # a push blocked by what the map does not know: rocking on gains nothing
        if self._frontier is not None and state not in ("reached", "failed") and \
                _stalled_toward(self, self._goal_xy, self.param("stall_s"), progress=self.param("progress_m")):
            # no nearer to the frontier's viewpoint in stall_s: a passage the map thinks open that the
            # robot does not fit through (Gibson Tolstoy/0/3 rocked at a corridor's mouth for all 500
            # steps while the passage to the toilet opened beside it); move on to the next frontier
            ctx.log(f"frontier #{self._frontier}: no progress for {self.param('stall_s'):.0f} s, skipped")
            state = "failed"
        if state in ("reached", "failed"):
            self._push_at = None
            if self._frontier is not None:
                self._visited.add(self._frontier)  # reached but still a frontier, or unreachable: move on
                if state == "failed":
                    ctx.failed_frontiers.add(self._frontier)
                if state == "reached" and self._goal_xy is not None:
                    self._reached.append((self._goal_xy, now))
            self._seq = None
        if self._frontier is not None and state not in ("reached", "failed") and self._nearer(self.param("progress_m")):
            ctx.last_frontier_time = now  # 0.25 m nearer a frontier (a re-picked or squeezed one too)
        if state in ("reached", "failed") and self._start_look:
            ctx.start_looks += 1
            self._start_look = False
        if ctx.start_looks < self.param("start_look_turns"):
            return self._look_around_start()
        self._settle_reached()
        if self._push_at is not None and self._seq is not None:
            ctx.last_frontier_time = now
            self.feedback_message = f"pushing into frontier #{self._frontier}"
            return Status.RUNNING  # a push runs to its end: the frontier it enters changes as it goes
        if self._squeezing and self._seq is not None:
            self.feedback_message = f"squeezing toward frontier #{self._frontier}"
            return Status.RUNNING  # progress (0.25 m nearer, above) alone resets the idle clock
        self._squeezing = False
        pick = self._pick()
        if pick is None:
            squeeze = self._squeeze_pick()
            if squeeze is not None:
                fid, xy, yaw = squeeze
                self._seq = ctx.send_goal(Goal(float(xy[0]), float(xy[1]), yaw, self.param("goal_tolerance"),
                                               "frontier", int(fid), through_unknown=True))
                self._frontier, self._goal_xy, self._squeezing = fid, xy, True
                self._stall.reset()
                self._nearest = None
                ctx.log(f"squeezing toward frontier #{fid}: every frontier failed on the map's masks")
                self.feedback_message = f"squeezing toward frontier #{fid}"
                return Status.RUNNING
            if self._frontier is not None and self._seq is not None:
                ctx.send_goal(None)
                self._seq = None
            if now - ctx.last_frontier_time > self.param("max_idle_s"):  # set in initialise
                if ctx.deferred:
                    # explored out: a deferred candidate is all that is left, so try it again now
                    # rather than end the mission (val/1/2: a fridge deferred for a label flip
                    # was still waiting when the small house had no frontier left)
                    ctx.log(f"no frontier left: deferred candidates {sorted(ctx.deferred)} are due now")
                    ctx.deferred.clear()
                    ctx.last_frontier_time = now
                    self.feedback_message = "no frontier left: back to the deferred candidates"
                    return Status.RUNNING
                self.feedback_message = "no frontier left"
                return Status.FAILURE
            pose = ctx.pose
            if pose is not None and (ctx.look_spot is None or
                                     math.hypot(pose.x - ctx.look_spot[0], pose.y - ctx.look_spot[1]) > self.param("look_spot_m")):
                ctx.look_spot, ctx.looks_here = (pose.x, pose.y), 0
            if self._seq is None and pose is not None and ctx.looks_here < self.param("look_turns"):
                # no frontier in view: turn in place (a quarter turn per look) to see around; the
                # count is the mission's, per spot, so a frontier that flickers in and out of the
                # plan cannot make the robot spin for the rest of the episode (val/52/1: 400 turns)
                ctx.looks_here += 1
                self._quarter_turn(pose)
                ctx.last_frontier_time = now  # looking around is progress
            self.feedback_message = "looking around" if self._seq is not None else "waiting for a frontier"
            return Status.RUNNING
        fid, xy, yaw, push = pick
        if fid not in ctx.failed_frontiers or push:
            # a frontier that failed before is no progress: a retried Explore re-picking the
            # unreachable frontiers reset the idle clock each time, and Gibson Onaga/0/1 went on so
            # for 430 s of clock without a step (Retry: 50 failures of 15 s each)
            ctx.last_frontier_time = now
        moved = self._goal_xy is None or float(np.hypot(*(xy - self._goal_xy))) > self.param("switch_distance")
        if self._seq is None or fid != self._frontier or moved or push:
            self._seq = ctx.send_goal(Goal(float(xy[0]), float(xy[1]), yaw, self.param("goal_tolerance"),
                                           "frontier", int(fid), through_unknown=push))
            self._frontier, self._goal_xy = fid, xy
            self._stall.reset()
            self._nearest = None
            if push:
                self._push_at = now
                ctx.log(f"pushing into frontier #{fid}: its viewpoint did not clear it")
        self.feedback_message = f"frontier #{fid}"
        return Status.RUNNING

    def cleanup(self, new_status: Status) -> None:
        if getattr(self, "_seq", None) is not None and self.ctx is not None:
            self.ctx.send_goal(None)
            self._seq = None
