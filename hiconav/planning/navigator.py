"""The Navigator: A* to the current goal on the inflated grid, path following, re-planning, recovery.

One call per control tick: ``step`` returns a Habitat-style DiscreteAction, ``step_velocity`` a
VelocityCommand. It plans locally and cheaply (A* in a window around start and goal first, the
whole grid only when the window has no path), re-plans when the path becomes blocked, when the
robot strays from it, or every ``replan_every`` ticks, and recovers when stuck (a virtual
obstacle where the robot could not move, then rotate toward the more open side, and in
velocity mode back off first).

It must not choose goals (exploration and the mission do) and must not modify the grid it is
given; STOP from ``step`` means "nothing to do": check ``reached`` and ``status``.
"""

from __future__ import annotations

import logging
import math

import cv2
import numpy as np

from hiconav.mapping.occupancy import GridLike, lethal_mask, squeeze_mask
from hiconav.geometry import ray_cast_grid
from hiconav.mapping.frontiers import nearest_reachable_cell
from hiconav.planning.astar import astar, smooth_path
from hiconav.planning.config import NavigatorConfig
from hiconav.planning.discrete import heading_action, to_discrete
from hiconav.planning.local_planner import PurePursuit, segment_target
from hiconav.types import DiscreteAction, Goal, Pose2D, VelocityCommand, wrap_angle

__all__ = ["Navigator", "blocked_cells", "plan_path", "squeeze_mask"]

log = logging.getLogger(__name__)




def _finite_pose(pose: Pose2D) -> bool:
    try:
        return all(math.isfinite(float(v)) for v in (pose.x, pose.y, pose.yaw))
    except (AttributeError, TypeError, ValueError):
        return False


def blocked_cells(grid: GridLike, *, through_unknown: bool = False, tight: bool = False,
                  squeeze: bool = False) -> np.ndarray:
    """(H, W) bool cells the robot centre must not enter: inflated obstacles (+ unknown cells);
    ``tight``: the lethal layer instead (obstacles grown by the robot radius, no margin;
    ``lethal_mask``), for passages the inflation margin closes; ``squeeze``: the lethal layer one
    cell thinner (``squeeze_mask``), the last resort of a goal through unknown floor."""
    if squeeze:
        blocked = squeeze_mask(grid)
    else:
        blocked = np.array(lethal_mask(grid) if tight else grid.inflated, dtype=bool, copy=True)
    if not through_unknown:
        blocked |= grid.state == -1
    return blocked


def _disk(blocked: np.ndarray, rc: np.ndarray, radius_cells: float) -> tuple[slice, slice, np.ndarray]:
    h, w = blocked.shape
    r = int(math.ceil(radius_cells))
    r0, r1 = max(0, rc[0] - r), min(h, rc[0] + r + 1)
    c0, c1 = max(0, rc[1] - r), min(w, rc[1] + r + 1)
    yy, xx = np.mgrid[r0:r1, c0:c1]
    m = (yy - rc[0]) ** 2 + (xx - rc[1]) ** 2 <= radius_cells**2
    return slice(r0, r1), slice(c0, c1), m


def plan_path(
    blocked: np.ndarray, start: tuple[int, int], goal: tuple[int, int], margin_cells: int
) -> np.ndarray | None:
    """A* in the start-goal bounding box grown by ``margin_cells``; the full grid if that fails.

    Returns (N, 2) int64 cells in ``blocked``'s indexing, or None.
    """
    h, w = blocked.shape
    r0 = max(0, min(start[0], goal[0]) - margin_cells)
    r1 = min(h, max(start[0], goal[0]) + margin_cells + 1)
    c0 = max(0, min(start[1], goal[1]) - margin_cells)
    c1 = min(w, max(start[1], goal[1]) + margin_cells + 1)
    if (r1 - r0) * (c1 - c0) < h * w:
        sub = astar(blocked[r0:r1, c0:c1], (start[0] - r0, start[1] - c0), (goal[0] - r0, goal[1] - c0))
        if sub is not None:
            return sub + np.array([r0, c0])
    return astar(blocked, start, goal)


class Navigator:
    """Follows A* paths to a Goal on an occupancy grid (OccupancyGrid or GridSnapshot).

    Attributes: goal (Goal | None), reached (bool), status ("idle", "following", "reached",
    "no_path", "recovering", "stuck": ``max_recoveries`` recoveries for the goal in one spot,
    "bad_pose": the last pose given was not finite, no motion commanded),
    path_xy ((N, 2) world waypoints of the smoothed path or None),
    n_plans, n_recoveries.
    """

    def __init__(self, config: NavigatorConfig | None = None) -> None:
        self.config = config or NavigatorConfig()
        self.local = PurePursuit(self.config.local)
        self.goal: Goal | None = None
        self.reached = False
        self.status = "idle"
        self.path_xy: np.ndarray | None = None
        self._dense_xy: np.ndarray | None = None  # A* cell centres (world), for blockage checks
        self._ticks_since_plan = 0
        self._virtual: list[tuple[float, float, float]] = []  # (x, y, radius) where the robot got stuck
        self._last_pose: Pose2D | None = None
        self._last_action: DiscreteAction | None = None
        # world xy where the robot centre has been, a point every TRAIL_STEP_M: traversable
        self._trail: list[tuple[float, float]] = []
        # _trail_cells' last answer and what it was computed for (trail length, grid frame): the
        # path check asks every step, the trail changes every few
        self._trail_cache: tuple[tuple, tuple[np.ndarray, np.ndarray]] | None = None
        self._stuck = 0
        self._settle: tuple[float, int] | None = None  # (least distance to the goal or path end, steps since)
        self._straight_from: float | None = None
        self._recovery: list[DiscreteAction] = []
        self._vel_recovery: list[tuple[float, float, float]] = []  # (v, omega, seconds)
        self._progress_ref: tuple[float, float, float] | None = None  # (x, y, elapsed)
        self._recoveries_at: list[tuple[float, float]] = []  # where each recovery for this goal began
        self._elapsed = 0.0
        self.n_plans = 0
        self.n_recoveries = 0
        self.tight = False  # the current path uses a tight passage (robot radius clear, no margin)
        self.squeeze = False  # ... one cell tighter still (``squeeze_mask``; implies ``tight``)

    # ------------------------------------------------------------------ goal
    def set_goal(self, goal: Goal | None) -> None:
        """Start navigating to ``goal`` (None: stop). Keeps learned virtual obstacles.

        Setting the goal already being followed (an equal Goal) changes nothing, so callers may
        re-send it every tick without interrupting a recovery or resetting ``reached``.
        """
        if goal is not None and goal == self.goal:
            return
        self.goal = goal
        self.reached = False
        self.status = "idle" if goal is None else "following"
        self.path_xy = None
        self._dense_xy = None
        self._recovery.clear()
        self._vel_recovery.clear()
        self._stuck = 0
        self._progress_ref = None
        self._recoveries_at = []
        self._settle: tuple[float, int] | None = None
        self._straight_from: float | None = None  # a straight goal's distance before its last step
        self.local.reset()

    def clear_virtual_obstacles(self) -> None:
        self._virtual.clear()

    # trail points are kept this far apart; consecutive points farther apart than TRAIL_GAP_M
    # (a pose jump: relocalisation, a new episode) are not joined
    TRAIL_STEP_M = 0.05
    TRAIL_GAP_M = 0.6

    def _record_trail(self, pose: Pose2D) -> None:
        if not self._trail or math.hypot(pose.x - self._trail[-1][0], pose.y - self._trail[-1][1]) >= self.TRAIL_STEP_M:
            self._trail.append((float(pose.x), float(pose.y)))

    def _trail_cells(self, grid: GridLike) -> tuple[np.ndarray, np.ndarray]:
        """(rows, cols) of the cells on the robot's trail (segments between consecutive points)."""
        key = (len(self._trail), tuple(np.asarray(grid.origin, dtype=np.float64)), grid.state.shape,
               float(grid.resolution))
        if self._trail_cache is not None and self._trail_cache[0] == key:
            return self._trail_cache[1]
        pts = np.asarray(self._trail, dtype=np.float64).reshape(-1, 2)
        if len(pts) == 1:
            segs = pts
        else:
            a, b = pts[:-1], pts[1:]
            keep = np.hypot(*(b - a).T) <= self.TRAIL_GAP_M
            t = np.linspace(0.0, 1.0, int(math.ceil(self.TRAIL_GAP_M / (0.5 * grid.resolution))) + 1)
            segs = (a[keep, None, :] + t[None, :, None] * (b - a)[keep, None, :]).reshape(-1, 2)
            segs = np.concatenate([segs, pts[-1:]])
        rc = grid.world_to_cell(segs)
        h, w = grid.state.shape
        ok = (rc[:, 0] >= 0) & (rc[:, 0] < h) & (rc[:, 1] >= 0) & (rc[:, 1] < w)
        cells = (rc[ok, 0], rc[ok, 1])
        self._trail_cache = (key, cells)
        return cells

    # ------------------------------------------------------------------ planning
    def _blocked(self, grid: GridLike, start_rc: np.ndarray, tight: bool = False,
                 squeeze: bool = False) -> np.ndarray:
        cfg = self.config
        through_unknown = cfg.plan_through_unknown or (self.goal is not None and self.goal.through_unknown)
        blocked = blocked_cells(grid, through_unknown=through_unknown, tight=tight, squeeze=squeeze)
        res = grid.resolution
        if cfg.trail_free and self._trail:
            # where the robot centre has been it fits (the world is static to this map): a gap between
            # furniture that the map's inflation closes behind the robot is no trap (a robot whose
            # own cell is lethal on the map has no way out on it and rocks in place between two
            # obstacles); an obstacle seen there since still blocks
            rows, cols = self._trail_cells(grid)
            blocked[rows, cols] &= grid.state[rows, cols] == 1
        for x, y, r in self._virtual:
            rc = grid.world_to_cell(np.array([x, y]))
            rs, cs, m = _disk(blocked, rc, r / res)
            blocked[rs, cs] |= m
        # the robot may stand inside the inflation zone: let it leave it, but only through cells
        # farther from the obstacles than the robot itself (never along or toward a wall)
        h, w = blocked.shape
        sr, sc = int(start_rc[0]), int(start_rc[1])
        if 0 <= sr < h and 0 <= sc < w and blocked[sr, sc]:
            rs, cs, m = _disk(blocked, start_rc, 0.3 / res)
            free = (grid.state[rs, cs] != 1).astype(np.uint8)
            clearance = cv2.distanceTransform(free, cv2.DIST_L2, 5)
            here = clearance[sr - rs.start, sc - cs.start]
            sub = blocked[rs, cs]
            sub[m & (clearance > here + 0.5) & (free > 0)] = False  # strictly away from obstacles
        return blocked

    def plan(self, grid: GridLike, pose: Pose2D) -> bool:
        """Plan from ``pose`` to the goal; sets ``path_xy``. False (status "no_path") if none.

        The path keeps the inflation margin from obstacles when it can; when no such path exists
        (a doorway or a gap between furniture narrower than the robot plus twice the margin) and
        ``tight_fallback`` is on, it plans again on the lethal layer (``tight``)."""
        self._ticks_since_plan = 0
        self.n_plans += 1
        if self.goal is None:
            return False
        h, w = grid.state.shape
        start = grid.world_to_cell(pose.xy)
        goal = grid.world_to_cell(self.goal.xy)
        if not (0 <= start[0] < h and 0 <= start[1] < w) or not (0 <= goal[0] < h and 0 <= goal[1] < w):
            self.path_xy, self._dense_xy, self.status = None, None, "no_path"
            return False
        found = self._search(grid, start, goal)
        if found is None and self._virtual:
            # the virtual obstacles left by stuck steps may have walled the robot in (in a corner
            # they can hold it until the step limit): clear them, as a costmap-clearing recovery
            # does, and plan once more on what the sensors saw
            log.info("navigator: no path with %d virtual obstacles; cleared them", len(self._virtual))
            self._virtual.clear()
            found = self._search(grid, start, goal)
        if found is None:
            self.path_xy, self._dense_xy, self.status = None, None, "no_path"
            return False
        blocked, cells = found
        way = smooth_path(blocked, cells)
        path = grid.cell_to_world(way)
        path[0] = pose.xy
        self.path_xy = path
        self._dense_xy = grid.cell_to_world(cells[1:]) if len(cells) > 1 else grid.cell_to_world(cells)
        self.status = "following"
        return True

    def _search(self, grid: GridLike, start: np.ndarray, goal: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """(blocked mask, A* cells) on the normal mask, then the tight one; sets ``tight``.

        A goal through unknown floor (the last short creep toward an object, a push into a
        frontier) plans on the tight mask alone: on the normal one a goal inside the inflation
        margin snaps back to the nearest roomy cell, which the robot had already reached, and the
        creep ends just outside a 1 m success region that the robot could have stood inside of.
        With ``squeeze_fallback``, such a goal that no path reaches on the tight
        mask plans once more on ``squeeze_mask``."""
        modes = [(False, False), (True, False)] if self.config.tight_fallback else [(False, False)]
        if self.config.tight_fallback and self.goal is not None and self.goal.through_unknown:
            modes = [(True, False)] + ([(True, True)] if self.config.squeeze_fallback else [])
        for tight, squeeze in modes:
            found = self._plan_on(grid, start, goal, tight, squeeze)
            if found is not None:
                self.tight, self.squeeze = tight, squeeze
                return found
        return None

    def _plan_on(self, grid: GridLike, start: np.ndarray, goal: np.ndarray,
                 tight: bool, squeeze: bool = False) -> tuple[np.ndarray, np.ndarray] | None:
        """(blocked mask, A* cells) of a path on the normal, ``tight`` or ``squeeze`` mask, or None."""
        res = grid.resolution
        blocked = self._blocked(grid, start, tight, squeeze)
        g = (int(goal[0]), int(goal[1]))
        if blocked[g]:
            snapped = nearest_reachable_cell(~blocked, g, int(math.ceil(self.config.goal_snap_m / res)))
            if snapped is None:
                return None
            g = snapped
        cells = plan_path(
            blocked, (int(start[0]), int(start[1])), g, int(math.ceil(self.config.window_margin_m / res))
        )
        return None if cells is None else (blocked, cells)

    def _path_blocked(self, grid: GridLike, pose: Pose2D) -> bool:
        """True if a remaining cell of the current path is now blocked (escape rule included)."""
        if self._dense_xy is None:
            return True
        rc = grid.world_to_cell(self._dense_xy)
        h, w = grid.state.shape
        ok = (rc[:, 0] >= 0) & (rc[:, 0] < h) & (rc[:, 1] >= 0) & (rc[:, 1] < w)
        if not ok.all():
            return True
        # only the part of the path still ahead of the robot
        k = int(np.argmin(np.hypot(*(self._dense_xy - pose.xy).T)))
        rc = rc[k:]
        blocked = self._blocked(grid, grid.world_to_cell(pose.xy), self.tight, self.squeeze)
        return bool(blocked[rc[:, 0], rc[:, 1]].any())

    def _need_replan(self, grid: GridLike, pose: Pose2D) -> bool:
        if self.path_xy is None or self._ticks_since_plan >= self.config.replan_every:
            return True
        if self._path_blocked(grid, pose):
            return True
        d = self._dense_xy if self._dense_xy is not None and len(self._dense_xy) else self.path_xy
        return float(np.min(np.hypot(*(d - pose.xy).T))) > self.config.deviation_m

    def _goal_reached(self, pose: Pose2D, settle: bool = False) -> bool:
        """Within the goal's tolerance, at the end of a path snapped off a blocked goal or, with
        ``settle`` (discrete steps), settled near it (``_settled``)."""
        assert self.goal is not None
        d = pose.distance_to(Pose2D(self.goal.x, self.goal.y, 0.0))
        if d <= self.goal.tolerance:
            return True
        # the goal itself may be blocked: reaching the end of the snapped path counts
        if self.path_xy is not None and len(self.path_xy) >= 1:
            end = self.path_xy[-1]
            if np.hypot(*(end - self.goal.xy)) <= self.config.goal_snap_m:
                d_end = float(np.hypot(*(end - pose.xy)))
                if d_end <= 0.5 * self.config.discrete.forward_step_m + 1e-6:
                    return True
                d = min(d, d_end)
        return settle and self._settled(d)

    def _settled(self, d: float) -> bool:
        """True once the robot, within ``settle_m`` of the goal (or the snapped path's end; ``d``),
        has come no 2 cm nearer for ``settle_steps`` steps: a discrete step longer than twice the
        reach carries the robot back and forth across a path end it cannot land within the reach
        of, for as long as the step limit allows (the behaviour above sees it within 0.35 m)."""
        cfg = self.config
        if self._settle is None or d < self._settle[0] - 0.02:
            self._settle = (d, 0)
            return False
        self._settle = (self._settle[0], self._settle[1] + 1)
        if d <= cfg.settle_m and self._settle[1] >= cfg.settle_steps:
            log.info("navigator: %.2f m from the goal, no nearer in %d steps: reached", d, self._settle[1])
            return True
        return False

    def _open_side(self, grid: GridLike, pose: Pose2D) -> int:
        """+1 if the left (CCW) side is more open than the right, else -1 (ray casting to the
        occupied cells: a stuck robot often stands inside the inflation, where rays on the
        inflated mask end at once on both sides and the tie turned it toward the nearer wall, so
        that it rocked between two obstacles, nearer the one it turned to each time)."""
        blocked = np.asarray(grid.state) == 1
        rc = grid.world_to_cell(pose.xy) + 0.5
        angles = pose.yaw + np.array([math.pi / 2, math.pi / 3, -math.pi / 2, -math.pi / 3])
        d = ray_cast_grid(blocked, (float(rc[0]), float(rc[1])), angles, 2.0 / grid.resolution)
        return 1 if d[:2].sum() >= d[2:].sum() else -1

    def _give_up(self, pose: Pose2D) -> bool:
        """Record a recovery about to start at ``pose``; True (status "stuck") when ``max_recoveries``
        recoveries for this goal, this one included, began within ``give_up_m`` of it.

        A recovery turns away and steps; the robot that comes back to the same blocked step
        recovers again, and only the mission's stall clock ended it: the robot turned between two
        headings in one spot for the whole stall budget of every frontier it tried. Failing
        the goal hands the choice back to the mission, which tries the next frontier or cell."""
        cfg = self.config
        if cfg.max_recoveries <= 0:
            return False
        self._recoveries_at.append((pose.x, pose.y))
        near = sum(1 for x, y in self._recoveries_at if math.hypot(pose.x - x, pose.y - y) <= cfg.give_up_m)
        if near < cfg.max_recoveries:
            return False
        self.status = "stuck"  # both callers ask only with no recovery under way
        log.info("navigator: %d recoveries at (%.2f, %.2f) for this goal: giving it up", near, pose.x, pose.y)
        return True

    def _add_virtual_obstacle(self, pose: Pose2D) -> None:
        r = self.config.virtual_obstacle_m
        if r <= 0:
            return
        ahead = 0.18 + r
        self._virtual.append((pose.x + ahead * math.cos(pose.yaw), pose.y + ahead * math.sin(pose.yaw), r))

    # ------------------------------------------------------------------ discrete control
    def step(self, grid: GridLike, pose: Pose2D) -> DiscreteAction:
        """The next discrete action toward the goal (STOP when reached or when there is no path).

        A non-finite pose gives STOP (status "bad_pose") and changes nothing: no motion from a pose
        the robot does not know."""
        if not _finite_pose(pose):
            self.status = "bad_pose"
            return DiscreteAction.STOP
        cfg = self.config
        self._ticks_since_plan += 1
        self._record_trail(pose)
        if self.goal is None:
            self.status = "idle"
            return self._act(DiscreteAction.STOP, pose)
        if self.goal.straight:
            return self._step_straight(grid, pose)
        # stuck detection: a forward step that did not move the robot
        if self._last_action == DiscreteAction.MOVE_FORWARD and self._last_pose is not None:
            if self._forward_blocked(pose):
                self._stuck += 1
                self._add_virtual_obstacle(pose)
                self.path_xy = None  # force a re-plan around the new obstacle
                if self._stuck >= cfg.stuck_limit and not self._recovery:
                    if self._give_up(pose):
                        return self._act(DiscreteAction.STOP, pose)
                    side = self._open_side(grid, pose)
                    turn = DiscreteAction.TURN_LEFT if side > 0 else DiscreteAction.TURN_RIGHT
                    self._recovery = [turn] * cfg.recovery_turns + [DiscreteAction.MOVE_FORWARD]
                    self.n_recoveries += 1
                    self._stuck = 0
                    log.info("navigator stuck at (%.2f, %.2f): recovery %s", pose.x, pose.y, turn.value)
            else:
                self._stuck = 0
        if self._recovery:
            self.status = "recovering"
            action = self._recovery.pop(0)
            if not self._recovery:
                self.path_xy = None
            return self._act(action, pose)
        if self._goal_reached(pose, settle=True):
            if self.goal.yaw is not None:
                turn = heading_action(pose, self.goal.yaw, cfg.discrete.turn_tolerance_deg)
                if turn is not None:
                    return self._act(turn, pose)
            self.reached = True
            self.status = "reached"
            return self._act(DiscreteAction.STOP, pose)
        if self._need_replan(grid, pose) and not self.plan(grid, pose):
            return self._act(DiscreteAction.STOP, pose)
        assert self.path_xy is not None
        target = segment_target(
            self.path_xy, pose.xy, cfg.discrete.lookahead_m, switch=0.5 * cfg.discrete.forward_step_m
        )
        if np.hypot(*(target - pose.xy)) < 1e-6:
            target = self.path_xy[-1]
        return self._act(self._discrete_action(grid, pose, target), pose)

    def _forward_blocked(self, pose: Pose2D) -> bool:
        """True when the last action was a forward step that moved the robot less than
        ``forward_blocked_m`` (to ``pose``): something the map may not know is in the way. A blocked
        step slides along the obstacle (Habitat-Sim's default): the robot moves a few centimetres
        sideways, and a slide counted as a step taken turned it back and forth at a gap its map
        showed open, sliding to and fro, for the rest of the episode."""
        return self._last_action == DiscreteAction.MOVE_FORWARD and self._last_pose is not None \
            and self._last_pose.distance_to(pose) < self.config.forward_blocked_m

    def _step_straight(self, grid: GridLike, pose: Pose2D) -> DiscreteAction:
        """A ``Goal.straight`` step: face the goal and step forward, no plan; done (facing the
        goal's yaw) within its tolerance, within half a step of it, when a forward step was blocked
        (moved the robot, or brought it nearer the goal, by less than ``forward_blocked_m``) or the
        point half a step ahead is a cell the map knows occupied.

        The planner keeps the robot centre a robot radius from every occupied cell, and the cells'
        5 cm and their padding cost a few centimetres more, enough for a creep toward an object
        to end just outside a 1 m success region where the robot fitted a decimetre nearer."""
        cfg = self.config
        goal = self.goal
        assert goal is not None
        step = cfg.discrete.forward_step_m
        d = float(np.hypot(*(goal.xy - pose.xy)))
        # blocked: a forward step that moved the robot little, or that brought it no nearer the
        # goal: sliding along an object's side it moves 0.05-0.08 m per step, first one way then
        # the other as its heading to the goal swings, and drives on without coming nearer
        blocked = self._forward_blocked(pose) or (
            self._last_action == DiscreteAction.MOVE_FORWARD and self._straight_from is not None
            and self._straight_from - d < cfg.forward_blocked_m)
        self._straight_from = None
        heading = math.atan2(goal.y - pose.y, goal.x - pose.x)
        done = self.reached or blocked or d <= max(goal.tolerance, 0.5 * step)
        if not done and abs(wrap_angle(heading - pose.yaw)) <= math.radians(cfg.discrete.turn_tolerance_deg):
            # half a step ahead must be clear: a step the obstacle cuts short still gains that much
            end = grid.world_to_cell(pose.xy + 0.5 * step * np.array([math.cos(pose.yaw), math.sin(pose.yaw)]))
            h, w = grid.state.shape
            done = not (0 <= end[0] < h and 0 <= end[1] < w) or int(grid.state[end[0], end[1]]) == 1
        if done:
            self.reached = True
            if goal.yaw is not None:
                turn = heading_action(pose, goal.yaw, cfg.discrete.turn_tolerance_deg)
                if turn is not None:
                    return self._act(turn, pose)
            self.status = "reached"
            return self._act(DiscreteAction.STOP, pose)
        self.status = "following"
        turn = heading_action(pose, heading, cfg.discrete.turn_tolerance_deg)
        if turn is None:
            self._straight_from = d  # this goal's distance before the step
        return self._act(turn if turn is not None else DiscreteAction.MOVE_FORWARD, pose)

    def _discrete_action(self, grid: GridLike, pose: Pose2D, target: np.ndarray) -> DiscreteAction:
        """Turn toward ``target`` until within the turn tolerance, then go forward; keep going
        forward up to ``forward_tolerance_deg`` off while the step is clear (known free, outside the
        inflation) and ends near the path. A 30-degree turn costs a whole step, so turning as soon as
        the error passed 15 degrees made the robot zig-zag, one turn per forward step."""
        dc = self.config.discrete
        d = np.asarray(target, dtype=np.float64) - pose.xy
        err = abs(wrap_angle(math.atan2(d[1], d[0]) - pose.yaw))
        if err <= math.radians(dc.turn_tolerance_deg) or (
                not self.tight and self._stuck == 0 and err <= math.radians(dc.forward_tolerance_deg)
                and self._forward_clear(grid, pose)):
            return DiscreteAction.MOVE_FORWARD
        return to_discrete(pose, target, dc.turn_tolerance_deg)

    def _forward_clear(self, grid: GridLike, pose: Pose2D) -> bool:
        step = self.config.discrete.forward_step_m
        heading = np.array([math.cos(pose.yaw), math.sin(pose.yaw)])
        pts = pose.xy[None, :] + np.array([[0.5], [1.0], [1.5]]) * step * heading[None, :]
        rc = grid.world_to_cell(pts)
        h, w = grid.state.shape
        if not ((rc[:, 0] >= 0) & (rc[:, 0] < h) & (rc[:, 1] >= 0) & (rc[:, 1] < w)).all():
            return False
        if (np.asarray(grid.inflated)[rc[:, 0], rc[:, 1]] | (np.asarray(grid.state)[rc[:, 0], rc[:, 1]] != 0)).any():
            return False
        for x, y, r in self._virtual:  # where the robot got stuck before (glass, unmapped clutter)
            if (np.hypot(pts[:, 0] - x, pts[:, 1] - y) <= r + 0.5 * step).any():
                return False
        path = self._dense_xy if self._dense_xy is not None and len(self._dense_xy) else self.path_xy
        if path is None:
            return False
        end = pose.xy + step * heading
        return float(np.min(np.hypot(*(path - end).T))) <= 0.3

    def _act(self, action: DiscreteAction, pose: Pose2D) -> DiscreteAction:
        self._last_action = action
        self._last_pose = pose
        return action

    # ------------------------------------------------------------------ velocity control
    def step_velocity(
        self, grid: GridLike, pose: Pose2D, dt: float = 0.1, stamp: float = 0.0
    ) -> VelocityCommand:
        """The next velocity command toward the goal (zero when reached or when there is no path).

        A non-finite pose gives the zero command (status "bad_pose") and changes nothing."""
        if not _finite_pose(pose):
            self.status = "bad_pose"
            return VelocityCommand.zero(stamp)
        cfg = self.config
        self._ticks_since_plan += 1
        self._elapsed += dt
        self._record_trail(pose)
        if self.goal is None:
            self.status = "idle"
            return VelocityCommand.zero(stamp)
        if self._vel_recovery:
            self.status = "recovering"
            v, om, left = self._vel_recovery[0]
            left -= dt
            if left <= 0:
                self._vel_recovery.pop(0)
                if not self._vel_recovery:
                    self.path_xy = None
                    self._progress_ref = None
            else:
                self._vel_recovery[0] = (v, om, left)
            return VelocityCommand(v, om, stamp)
        if self._goal_reached(pose):
            if self.goal.yaw is not None:
                err = wrap_angle(self.goal.yaw - pose.yaw)
                if abs(err) > math.radians(cfg.discrete.turn_tolerance_deg):
                    om = float(
                        np.clip(cfg.local.heading_gain * err, -cfg.local.omega_max, cfg.local.omega_max)
                    )
                    return VelocityCommand(0.0, om, stamp)
            self.reached = True
            self.status = "reached"
            self.local.reset()
            return VelocityCommand.zero(stamp)
        # stuck detection: no progress over stuck_time_s while trying to move
        if self._progress_ref is None:
            self._progress_ref = (pose.x, pose.y, self._elapsed)
        elif self._elapsed - self._progress_ref[2] >= cfg.stuck_time_s:
            moved = math.hypot(pose.x - self._progress_ref[0], pose.y - self._progress_ref[1])
            if moved < cfg.stuck_progress_m * 2:
                if self._give_up(pose):
                    self.local.reset()
                    return VelocityCommand.zero(stamp)
                self._add_virtual_obstacle(pose)
                side = self._open_side(grid, pose)
                self._vel_recovery = [
                    (-cfg.back_off_speed, 0.0, cfg.back_off_s),
                    (0.0, side * cfg.local.omega_max, (math.pi / 2) / cfg.local.omega_max),
                ]
                self.n_recoveries += 1
                self.local.reset()
                log.info("navigator stuck at (%.2f, %.2f): backing off and rotating", pose.x, pose.y)
                return self.step_velocity(grid, pose, 0.0, stamp)
            self._progress_ref = (pose.x, pose.y, self._elapsed)
        if self._need_replan(grid, pose) and not self.plan(grid, pose):
            self.local.reset()
            return VelocityCommand.zero(stamp)
        assert self.path_xy is not None
        cmd = self.local.command(pose, self.path_xy, dt, stamp)
        if cmd.v < 0.05:  # turning on the spot is not being stuck
            self._progress_ref = None
        return cmd
