"""Frontier following: which frontier of the exploration plan's WTRP order the robot goes to next,
and when the map is explored out.

The exploration layer plans frontiers and their WTRP order; this module decides what the robot
does with them, tick by tick: go to the first frontier of the order not yet visited (its
viewpoint, facing its centroid), skip frontiers seen from viewpoints that did not clear them
(spent), push once into a spent frontier beside the robot, squeeze toward failed frontiers
through unknown floor when nothing else is left (and push through spent frontiers never pushed
into, from wherever the robot stands), turn in place to look around at the start and where no
frontier is known, and keep the mission's idle clock (no frontier for ``max_idle_s``:
exploration fails). A robot standing idle judges its reached viewpoints on the plan of its
newest frame: a robot whose frames come only with its actions gets no newer one.

Inputs are plain: the plan's frontiers and order (``PlanView``), the robot's pose, the clock
time, the ``decisions.explore`` settings and the mission-wide ledger of exploration
(``ExploreLedger``: the idle clock, the look counts, the spent / pushed / failed / squeezed
spots). Outputs are a frozen ``ExploreStep``: the goal to send (``FrontierGoal``) or to cancel,
what to log, the status. Nothing here ticks a tree, sends a goal, reads the mission context or
talks to an actor; the ``Explore`` behaviour polls this module and posts what it decides.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np

from hiconav.decisions.config import ExploreSettings
from hiconav.decisions.progress import StallClock
from hiconav.decisions.viewing import DONE
from hiconav.types import Pose2D, wrap_angle

# a viewpoint this near its frontier's centroid has no direction to face: the goal leaves the
# yaw free (m; a degenerate case, not a tunable)
FACE_MIN_M = 0.2
# a spent frontier's centroid this near the robot has no direction to push along: the push keeps
# the robot's heading (m; a degenerate case, not a tunable)
PUSH_HEADING_MIN_M = 0.1
# a look is a turn in place at the robot's own position: any tolerance above the pose's drift
# reaches it (m)
LOOK_TOLERANCE_M = 0.5

Spot = tuple[float, float]


@dataclass(frozen=True)
class PlanView:
    """What frontier following reads of an exploration plan message.

    ``frontiers``: objects with ``id``, ``viewpoint`` and ``centroid`` ((2,) world metres);
    ``order``: the WTRP order of frontier ids; ``goal_id``: the plan's goal frontier (None: none);
    ``stamp``: the clock time the plan was made (s); ``dropped``: ids of frontiers the planner
    left out of ``order``: no path to them on the map's lethal layer, or beyond its
    ``max_frontiers``; ``newest``: the plan was made from the newest world snapshot the mission
    holds (no frame has come since).
    """

    frontiers: tuple[Any, ...]
    order: tuple[int, ...]
    goal_id: int | None
    stamp: float
    dropped: tuple[int, ...] = ()
    newest: bool = False

    @staticmethod
    def of(msg: Any, world_seq: int | None = None) -> PlanView | None:
        """The view of a ``PlanMsg`` (None: no plan yet); a plan without an order has none.
        ``world_seq``: the seq of the newest world snapshot the mission holds (None: unknown)."""
        if msg is None:
            return None
        goal = getattr(msg.plan, "goal", None)
        newest = world_seq is not None and int(getattr(msg, "snapshot_seq", -1)) >= int(world_seq)
        return PlanView(tuple(msg.frontiers), tuple(getattr(msg.plan, "order", ()) or ()),
                        None if goal is None else goal.id, msg.stamp,
                        tuple(getattr(msg.plan, "dropped", ()) or ()), newest)


@dataclass
class ExploreLedger:
    """The mission-wide record of exploration, kept across Explore's activations and retries.

    ``last_frontier_time``: the idle clock, the clock time of the last progress (s);
    ``start_looks``: quarter turns done at the start; ``look_spot`` / ``looks_here``: where the
    robot last looked around for want of a frontier (world xy m) and the turns made there. The
    lists are the mission's own and are appended to in place: ``spent_viewpoints``, reached
    viewpoints that did not clear their frontier; ``pushed_frontiers`` and
    ``squeezed_frontiers``, centroids pushed or squeezed into (world xy m); ``failed_frontiers``,
    ids of frontiers whose goal failed; ``unresolved_asks_left``: how many more times an
    explored-out search may ask the reasoning layer for its best unresolved candidate (0: never,
    as for a task without a described instance); ``last_resort_left``: how many more times an
    explored-out search may take back a candidate set aside only as out of reach
    (``hiconav.decisions.last_resort``; 0: none is left, or it was taken).
    """

    last_frontier_time: float
    start_looks: int
    look_spot: Spot | None
    looks_here: int
    spent_viewpoints: list[Spot] = field(default_factory=list)
    pushed_frontiers: list[Spot] = field(default_factory=list)
    failed_frontiers: set[int] = field(default_factory=set)
    squeezed_frontiers: list[Spot] = field(default_factory=list)
    unresolved_asks_left: int = 0
    last_resort_left: int = 0


@dataclass(frozen=True)
class FrontierGoal:
    """A goal of frontier following: world (x, y) m, the yaw to face (None: free), its tolerance.

    ``kind``: "frontier" (a viewpoint facing the centroid), "push" (beyond a spent frontier's
    centroid), "squeeze" (the viewpoint of a failed frontier, or of one the planner found no path
    to, tried again) or "look" (a quarter turn in place); ``frontier``: the frontier id (None for
    a look); ``through_unknown``: the path may cross floor the map does not know.
    """

    kind: Literal["frontier", "push", "squeeze", "look"]
    x: float
    y: float
    yaw: float | None
    tolerance: float
    frontier: int | None = None
    through_unknown: bool = False


@dataclass(frozen=True)
class ExploreStep:
    """One tick's decision: the status, a feedback line, the goal to send (None: none), whether
    to cancel the goal in flight first, the lines to log in order, whether the deferred
    candidates are due now (explored out: they are all that is left), whether to ask the
    reasoning layer for its best unresolved candidate (explored out, nothing deferred), and
    whether to take back the best candidate set aside as out of reach (``last_resort``: explored
    out, nothing deferred, nothing left to ask)."""

    status: Literal["running", "failure"]
    feedback: str
    goal: FrontierGoal | None = None
    cancel: bool = False
    log: tuple[str, ...] = ()
    release_deferred: bool = False
    ask_unresolved: bool = False
    last_resort: bool = False
    ended: bool = False  # the goal in flight ended (reached, failed or given up): forget it


def near_any(xy: np.ndarray, spots: Sequence[Spot], radius: float) -> bool:
    """True when ``xy`` ((2,) world m) lies within ``radius`` of one of ``spots``: one visit per
    spot, whatever id the plan gives the frontier there."""
    return any(math.hypot(xy[0] - x, xy[1] - y) <= radius for x, y in spots)


def facing_yaw(viewpoint: np.ndarray, centroid: np.ndarray) -> float | None:
    """The yaw from a frontier's ``viewpoint`` to its ``centroid`` ((2,) world m), so that on
    arrival the camera looks at the frontier; None when they are ``FACE_MIN_M`` or nearer."""
    d = centroid - viewpoint
    return math.atan2(d[1], d[0]) if float(np.hypot(*d)) > FACE_MIN_M else None


def push_goal(centroid: np.ndarray, pose: Pose2D | None, pushed: Sequence[Spot],
              s: ExploreSettings, radius: float | None = None) -> tuple[np.ndarray, float] | None:
    """(goal xy, yaw) ``push_m`` beyond a spent frontier's ``centroid`` ((2,) world m), away from
    the robot, or None: pushing is off, there is no pose, the centroid is beyond ``push_radius``
    (``radius`` where given) or was pushed into before (within ``spent_radius`` of one of ``pushed``).

    A frontier can outlive the visit to its viewpoint: the floor close to the robot is below the
    camera's field of view, a wall nearer than the minimum depth reads nothing. Driving into it
    once, through floor the map does not know, shows what lies behind, as a person steps into a
    doorway to look along the corridor behind it."""
    if not s.push_through or pose is None:
        return None
    robot = np.array([pose.x, pose.y])
    d = centroid - robot
    dist = float(np.hypot(*d))
    if dist > (s.push_radius if radius is None else radius) or near_any(centroid, pushed, s.spent_radius):
        return None
    yaw = math.atan2(d[1], d[0]) if dist > PUSH_HEADING_MIN_M else pose.yaw
    goal = centroid + s.push_m * np.array([math.cos(yaw), math.sin(yaw)])
    return goal, yaw


def look_goal(pose: Pose2D) -> FrontierGoal:
    """A quarter turn to the left in place: the camera sees 79 degrees, so four of them show the
    room all round."""
    return FrontierGoal("look", pose.x, pose.y, wrap_angle(pose.yaw + math.pi / 2), LOOK_TOLERANCE_M)


def start_look_step(state: str | None, pose: Pose2D | None, looks: int, s: ExploreSettings
                    ) -> tuple[int, FrontierGoal | None, bool]:
    """The start look as a step of its own (``LookAround``): with the quarter turn in flight in
    navigation ``state`` (None: none sent) and ``looks`` quarter turns done, the quarter turns
    done now, the next one to send (None: one is in flight, or no pose yet) and whether the
    look is done (``start_look_turns``; Explore skips the look then, as it counts the same
    turns)."""
    looks += int(state in DONE)
    if looks >= s.start_look_turns:
        return looks, None, True
    if (state is None or state in DONE) and pose is not None:
        return looks, look_goal(pose), False
    return looks, None, False


def settle_reached(reached: list[tuple[np.ndarray, float]], plan: PlanView | None, spent: list[Spot],
                   s: ExploreSettings, now: float | None = None,
                   idle: bool = False) -> tuple[list[tuple[np.ndarray, float]], list[Spot]]:
    """Judge reached viewpoints ((viewpoint (2,) world m, clock time reached)) on ``plan``: a
    viewpoint is spent when a plan made ``spent_after_s`` or more after the visit still has a
    frontier viewpoint within ``spent_radius`` of it (the visit did not clear the frontier).
    Returns (still waiting for a newer plan, newly spent spots); appends the spent ones to
    ``spent``. A viewpoint that a later plan shows cleared is dropped.

    While the robot stands ``idle`` (no goal in flight), a plan made from the newest frame
    (``plan.newest``) is as new as any will be until the robot acts: a robot whose camera frames
    come only with its actions (a lockstep simulator, a driver that publishes on motion) would
    otherwise wait for ever on a plan that its own waiting keeps from coming. Such a plan judges
    a viewpoint once ``spent_after_s`` have passed since the visit (clock ``now``)."""
    if plan is None or not reached:
        return reached, []
    views = np.array([f.viewpoint for f in plan.frontiers], dtype=np.float64).reshape(-1, 2)
    waiting, settled = [], []
    for xy, t in reached:
        none_newer = idle and plan.newest and now is not None and now >= t + s.spent_after_s
        if plan.stamp < t + s.spent_after_s and not none_newer:
            waiting.append((xy, t))
        elif len(views) and float(np.min(np.hypot(*(views - xy).T))) <= s.spent_radius:
            spot = (float(xy[0]), float(xy[1]))
            spent.append(spot)
            settled.append(spot)
    return waiting, settled


def pick_frontier(plan: PlanView | None, visited: Collection[int], pose: Pose2D | None,
                  ledger: ExploreLedger, s: ExploreSettings) -> tuple[Any, np.ndarray, float | None, bool] | None:
    """(frontier id, goal xy, yaw or None, push) for the first frontier of the plan's order (its
    goal frontier first) that is not ``visited``: its viewpoint facing its centroid, or, where that
    viewpoint is spent, a push into it (``push_goal``; the centroid joins
    ``ledger.pushed_frontiers``). Frontiers seen from spent spots that cannot be pushed into are
    skipped: reaching, looking at and choosing them again, under a new id, clears nothing."""
    if plan is None:
        return None
    frontiers = {f.id: f for f in plan.frontiers}
    order = list(plan.order)
    if plan.goal_id is not None and plan.goal_id not in order:
        order.insert(0, plan.goal_id)
    for fid in order:
        if fid in frontiers and fid not in visited:
            xy = np.asarray(frontiers[fid].viewpoint, dtype=np.float64)
            centroid = np.asarray(frontiers[fid].centroid, dtype=np.float64)
            if not near_any(xy, ledger.spent_viewpoints, s.spent_radius):
                return fid, xy, facing_yaw(xy, centroid), False
            push = push_goal(centroid, pose, ledger.pushed_frontiers, s)
            if push is not None:
                ledger.pushed_frontiers.append((float(centroid[0]), float(centroid[1])))
                return fid, push[0], push[1], True
    return None


def pick_squeeze(plan: PlanView | None, ledger: ExploreLedger, s: ExploreSettings,
                 pose: Pose2D | None = None) -> tuple[Any, np.ndarray, float | None] | None:
    """(frontier id, goal xy, yaw) of the first frontier of the plan's order that failed, else of
    the first the planner left out of its order (``plan.dropped``), that was not squeezed yet (its
    centroid then joins ``ledger.squeezed_frontiers``), else a push into the first spent frontier
    never pushed into (``push_goal`` from wherever the robot stands; the centroid joins
    ``ledger.pushed_frontiers`` too), or None.

    The map's grid can close a passage the robot fits: a goal through unknown floor lets the
    navigator plan on the lethal layer and then on it one cell thinner, a last resort before
    "no frontier left". A doorway first seen from across the room is such a passage: the floor
    seen through it is a narrow wedge, tight at the doorway, and the frontiers along the wedge have
    no path on the lethal layer, so the planner leaves them out of its order; they are squeezed
    toward too, after the failed ones. A doorway whose viewpoint the robot reached without
    clearing it (spent) is pushed into only while the robot stands within ``push_radius`` of it;
    a robot that went on elsewhere first and then ran out of frontiers goes back and pushes
    through it (its goal beyond the centroid, through unknown floor), rather than ending the
    search beside a door it never tried."""
    if plan is None or not s.squeeze:
        return None
    frontiers = {f.id: f for f in plan.frontiers}
    failed = [fid for fid in plan.order if fid in ledger.failed_frontiers]
    for fid in failed + list(plan.dropped):  # the plan's dropped ids are not in its order
        f = frontiers.get(fid)
        if f is None:
            continue
        centroid = np.asarray(f.centroid, dtype=np.float64)
        xy = np.asarray(f.viewpoint, dtype=np.float64)
        if not np.all(np.isfinite(xy)) or near_any(centroid, ledger.squeezed_frontiers, s.spent_radius):
            continue
        ledger.squeezed_frontiers.append((float(centroid[0]), float(centroid[1])))
        return fid, xy, facing_yaw(xy, centroid)
    if not s.push_through or pose is None:
        return None
    for fid in plan.order:
        f = frontiers.get(fid)
        if f is None or not near_any(np.asarray(f.viewpoint, dtype=np.float64), ledger.spent_viewpoints,
                                     s.spent_radius):
            continue
        centroid = np.asarray(f.centroid, dtype=np.float64)
        if near_any(centroid, ledger.squeezed_frontiers, s.spent_radius):
            continue
        push = push_goal(centroid, pose, ledger.pushed_frontiers, s, radius=math.inf)
        if push is None:
            continue
        spot = (float(centroid[0]), float(centroid[1]))
        ledger.squeezed_frontiers.append(spot)
        ledger.pushed_frontiers.append(spot)
        return fid, push[0], push[1]
    return None


class FrontierFollower:
    """One activation of frontier following: the frontier goal in flight and what this
    activation has visited; the mission-wide record lives in the ``ExploreLedger`` passed in.

    ``step`` is called once per tick with the state of the goal in flight ("reached", "failed",
    or anything else while it runs; None: no goal in flight) and returns what to do."""

    def __init__(self) -> None:
        self.frontier: Any = None  # the frontier id of the goal in flight (or last sent)
        self.goal_xy: np.ndarray | None = None
        self.visited: set[Any] = set()  # reached but still a frontier, or unreachable: move on
        self.reached: list[tuple[np.ndarray, float]] = []  # viewpoint, clock time: awaiting a newer plan
        self.start_look = False  # the goal in flight is one of the start's quarter turns
        self.push_at: float | None = None  # clock time the push in flight was sent
        self.squeezing = False  # the goal in flight is a squeeze toward a failed frontier
        self.nearest: float | None = None  # the robot's least distance to the goal in flight
        self.stall = StallClock()  # no progress toward the goal in flight

    def _stalled(self, pose: Pose2D | None, now: float, in_flight: bool, s: ExploreSettings) -> bool:
        """No ``progress_m`` nearer the goal in flight for ``stall_s``: a passage the map shows
        open that the robot does not fit through; moving on beats rocking at its mouth."""
        if pose is None or self.goal_xy is None or not in_flight:
            return False
        return self.stall.stalled(math.hypot(pose.x - self.goal_xy[0], pose.y - self.goal_xy[1]), now, s.stall_s,
                                  s.stall_near, s.progress_m)

    def _nearer(self, pose: Pose2D | None, by: float) -> bool:
        """True when the robot has come ``by`` m nearer the goal in flight than it has been since
        the goal was sent (``nearest`` keeps the best distance; reset with each goal)."""
        if pose is None or self.goal_xy is None:
            return False
        d = math.hypot(pose.x - self.goal_xy[0], pose.y - self.goal_xy[1])
        if self.nearest is None or d < self.nearest - by:
            first = self.nearest is None
            self.nearest = d
            return not first
        return False

    def _turn(self, pose: Pose2D) -> FrontierGoal:
        """A quarter turn in place; no frontier is pursued."""
        self.frontier, self.goal_xy = None, None
        return look_goal(pose)

    def _aim(self, fid: Any, xy: np.ndarray) -> None:
        """A new goal toward frontier ``fid`` at ``xy``: restart the stall and progress clocks."""
        self.frontier, self.goal_xy = fid, xy
        self.stall.reset()
        self.nearest = None

    def step(self, state: str | None, pose: Pose2D | None, now: float, plan: PlanView | None,
             ledger: ExploreLedger, deferred: Collection[int], s: ExploreSettings) -> ExploreStep:
        """One tick: ``state`` of the goal in flight (None: none), the robot's ``pose``, the clock
        time ``now`` (s), the latest ``plan``, the mission's ``ledger`` (updated in place), the
        ids of deferred candidates and the settings."""
        log: list[str] = []
        state = self._judge(state, pose, now, ledger, s, log)
        out = self._choose(state, pose, now, plan, ledger, deferred, s, log)
        return replace(out, ended=state in DONE)

    def _judge(self, state: str | None, pose: Pose2D | None, now: float, ledger: ExploreLedger,
               s: ExploreSettings, log: list[str]) -> str | None:
        """The state of the goal in flight, "failed" when it is given up (a push past ``push_s``,
        a stall); an ended goal's frontier is visited, and remembered as reached or failed."""
        in_flight = state is not None
        if self.push_at is not None and state not in DONE and now - self.push_at > s.push_s:
            state = "failed"  # a push blocked by what the map does not know: rocking on gains nothing
        if self.frontier is not None and state not in DONE and self._stalled(pose, now, in_flight, s):
            log.append(f"frontier #{self.frontier}: no progress for {s.stall_s:.0f} s, skipped")
            state = "failed"
        if state in DONE:
            self.push_at = None
            if self.frontier is not None:
                self.visited.add(self.frontier)
                if state == "failed":
                    # remembered for the mission: picking it again is no progress for the idle clock
                    ledger.failed_frontiers.add(self.frontier)
                if state == "reached" and self.goal_xy is not None:
                    self.reached.append((self.goal_xy, now))
        return state

    def _choose(self, state: str | None, pose: Pose2D | None, now: float, plan: PlanView | None,
                ledger: ExploreLedger, deferred: Collection[int], s: ExploreSettings,
                log: list[str]) -> ExploreStep:
        """What to do with the goal in flight judged (``state``): look around at the start, keep
        a push or a squeeze going, go to the frontier picked, or what is left without one."""
        in_flight = state is not None and state not in DONE
        if self.frontier is not None and state not in DONE and self._nearer(pose, s.progress_m):
            ledger.last_frontier_time = now  # nearer a frontier (a re-picked or squeezed one too)
        if state in DONE and self.start_look:
            ledger.start_looks += 1
            self.start_look = False
        if ledger.start_looks < s.start_look_turns:
            return self._look_around_start(in_flight, pose, now, ledger, s, log)
        self.reached, spent = settle_reached(self.reached, plan, ledger.spent_viewpoints, s, now, idle=not in_flight)
        log += [f"frontier viewpoint ({x:.2f}, {y:.2f}) spent: reached, not cleared" for x, y in spent]
        if self.push_at is not None and in_flight:
            ledger.last_frontier_time = now
            # a push runs to its end: the frontier it enters changes as it goes
            return ExploreStep("running", f"pushing into frontier #{self.frontier}", log=tuple(log))
        if self.squeezing and in_flight:
            # progress (progress_m nearer, above) alone resets the idle clock
            return ExploreStep("running", f"squeezing toward frontier #{self.frontier}", log=tuple(log))
        self.squeezing = False
        pick = pick_frontier(plan, self.visited, pose, ledger, s)
        if pick is None:
            return self._nothing_to_pick(in_flight, pose, now, plan, ledger, deferred, s, log)
        fid, xy, yaw, push = pick
        if fid not in ledger.failed_frontiers or push:
            # a frontier that failed before is no progress: a retried Explore re-picking the
            # unreachable frontiers must not reset the idle clock each time
            ledger.last_frontier_time = now
        moved = self.goal_xy is None or float(np.hypot(*(xy - self.goal_xy))) > s.switch_distance
        goal = None
        if not in_flight or fid != self.frontier or moved or push:
            goal = FrontierGoal("push" if push else "frontier", float(xy[0]), float(xy[1]), yaw, s.goal_tolerance,
                                int(fid), through_unknown=push)
            self._aim(fid, xy)
            if push:
                self.push_at = now
                log.append(f"pushing into frontier #{fid}: its viewpoint did not clear it")
        return ExploreStep("running", f"frontier #{fid}", goal, log=tuple(log))

    def _look_around_start(self, in_flight: bool, pose: Pose2D | None, now: float, ledger: ExploreLedger,
                           s: ExploreSettings, log: list[str]) -> ExploreStep:
        """One quarter turn in place after another until ``start_look_turns`` are done: without
        them the start room is only known in the direction the robot happened to face."""
        goal = None
        if not in_flight and pose is not None:
            goal = self._turn(pose)
            self.start_look = True
        ledger.last_frontier_time = now  # looking around is progress
        return ExploreStep("running", f"looking around the start ({ledger.start_looks}/{s.start_look_turns})", goal,
                           log=tuple(log))

    def _nothing_to_pick(self, in_flight: bool, pose: Pose2D | None, now: float, plan: PlanView | None,
                         ledger: ExploreLedger, deferred: Collection[int], s: ExploreSettings,
                         log: list[str]) -> ExploreStep:
        """No frontier to go to: squeeze toward a failed one, or cancel the goal in flight and,
        idle for ``max_idle_s``, release the deferred candidates or fail; else look around."""
        squeeze = pick_squeeze(plan, ledger, s, pose)
        if squeeze is not None:
            fid, xy, yaw = squeeze
            goal = FrontierGoal("squeeze", float(xy[0]), float(xy[1]), yaw, s.goal_tolerance, int(fid),
                                through_unknown=True)
            self._aim(fid, xy)
            self.squeezing = True
            log.append(f"squeezing toward frontier #{fid}: every frontier failed on the map's masks")
            return ExploreStep("running", f"squeezing toward frontier #{fid}", goal, log=tuple(log))
        cancel = self.frontier is not None and in_flight
        if cancel:
            in_flight = False
        if now - ledger.last_frontier_time > s.max_idle_s:
            if deferred:
                # explored out: a deferred candidate is all that is left, so it is tried again now
                # rather than the mission ended
                log.append(f"no frontier left: deferred candidates {sorted(deferred)} are due now")
                ledger.last_frontier_time = now
                return ExploreStep("running", "no frontier left: back to the deferred candidates", cancel=cancel,
                                   log=tuple(log), release_deferred=True)
            if ledger.unresolved_asks_left > 0:
                # explored out in search of a described instance: the instances seen whose
                # relations could not be confirmed are all that is left, and the reasoning layer
                # ranks them (``hiconav.reasoning.unresolved``); wait one more idle period for it
                ledger.unresolved_asks_left -= 1
                ledger.last_frontier_time = now
                log.append("no frontier left: asking the reasoning layer for its best unresolved candidate")
                return ExploreStep("running", "no frontier left: asking for the best unresolved candidate",
                                   cancel=cancel, log=tuple(log), ask_unresolved=True)
            if ledger.last_resort_left > 0 and s.last_resort:
                # explored out, and a candidate was set aside only because no view point or approach
                # cell could be reached: ending fails for certain, stopping as near it as the map
                # allows may not (``hiconav.decisions.last_resort``)
                ledger.last_resort_left -= 1
                ledger.last_frontier_time = now
                log.append("no frontier left: taking back the best candidate set aside as out of reach")
                return ExploreStep("running", "no frontier left: the last resort", cancel=cancel, log=tuple(log),
                                   last_resort=True)
            return ExploreStep("failure", "no frontier left", cancel=cancel, log=tuple(log))
        if pose is not None and (ledger.look_spot is None or
                                 math.hypot(pose.x - ledger.look_spot[0], pose.y - ledger.look_spot[1]) > s.look_spot_m):
            ledger.look_spot, ledger.looks_here = (pose.x, pose.y), 0
        goal = None
        if not in_flight and pose is not None and ledger.looks_here < s.look_turns:
            # no frontier in view: turn in place to see around; the count is the mission's, per
            # spot, so a frontier that flickers in and out of the plan cannot keep the robot spinning
            ledger.looks_here += 1
            goal = self._turn(pose)
            in_flight = True
            ledger.last_frontier_time = now  # looking around is progress
        return ExploreStep("running", "looking around" if in_flight else "waiting for a frontier", goal,
                           cancel=cancel, log=tuple(log))


__all__ = ["ExploreLedger", "ExploreStep", "FrontierFollower", "FrontierGoal", "PlanView", "facing_yaw",
           "look_goal", "near_any", "pick_frontier", "pick_squeeze", "push_goal", "settle_reached", "start_look_step"]
