"""Local planner, discrete converter and Navigator behaviour on hand-made grids (no simulator)."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from hiconav.mapping import GridSnapshot
from hiconav.mapping.occupancy import disk_kernel
from hiconav.planning import Navigator, PurePursuit, heading_action, lookahead_point, to_discrete
from hiconav.planning.config import NavigatorConfig
from hiconav.planning.local_planner import segment_target
from hiconav.planning.navigator import squeeze_mask
from hiconav.types import DiscreteAction, Goal, Pose2D, VelocityCommand

RES = 0.05


def snapshot(state: np.ndarray) -> GridSnapshot:
    occ = (state == 1).astype(np.uint8)
    inflated = cv2.dilate(occ, disk_kernel(5.0)).astype(bool)
    return GridSnapshot(
        state=state.astype(np.int8),
        inflated=inflated,
        explored=state != -1,
        origin=np.zeros(2),
        resolution=RES,
        version=1,
        stamp=0.0,
    )


def open_room(n: int = 100) -> np.ndarray:
    s = np.zeros((n, n), np.int8)
    s[0, :] = s[-1, :] = s[:, 0] = s[:, -1] = 1
    return s


def test_to_discrete_turns_to_within_15_deg_then_goes_forward():
    p = Pose2D(0, 0, 0)
    assert to_discrete(p, np.array([1.0, 0.1])) == DiscreteAction.MOVE_FORWARD  # 5.7 deg
    assert to_discrete(p, np.array([1.0, 0.5])) == DiscreteAction.TURN_LEFT  # 26.6 deg
    assert to_discrete(p, np.array([1.0, -0.5])) == DiscreteAction.TURN_RIGHT
    assert to_discrete(p, np.array([-1.0, -0.01])) == DiscreteAction.TURN_RIGHT  # shortest way round
    assert heading_action(Pose2D(0, 0, math.radians(170)), math.radians(-175)) is None  # wraps


def test_lookahead_point_walks_along_the_path():
    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    pt, seg = lookahead_point(path, np.array([0.5, 0.1]), 0.7)
    np.testing.assert_allclose(pt, [1.0, 0.2], atol=1e-9)
    assert seg == 1
    pt, _ = lookahead_point(path, np.array([0.9, 0.9]), 5.0)
    np.testing.assert_allclose(pt, [1.0, 1.0])
    # never past the first corner ahead while it is farther than the switch distance
    np.testing.assert_allclose(segment_target(path, np.array([0.5, 0.0]), 0.7, 0.1), [1.0, 0.0])


def test_pure_pursuit_respects_limits_and_turns_in_place_for_large_errors():
    pp = PurePursuit()
    c = pp.config
    path = np.array([[0.0, 0.0], [3.0, 0.0]])
    cmd = pp.command(Pose2D(0, 0, 0), path, dt=0.1)
    assert 0 < cmd.v <= c.accel_max * 0.1 + 1e-9  # acceleration limit from standstill
    for _ in range(30):
        cmd = pp.command(Pose2D(0, 0, 0), path, dt=0.1)
    assert cmd.v == pytest.approx(c.v_max) and abs(cmd.omega) < 1e-9
    cmd = pp.command(Pose2D(0, 0, math.pi), path, dt=0.1)  # facing away: rotate on the spot
    assert cmd.v == 0.0 and abs(cmd.omega) == pytest.approx(c.omega_max)
    cmd = pp.command(Pose2D(0, 0.0, 0.3), path, dt=0.1)
    assert cmd.omega < 0 and abs(cmd.omega) <= c.omega_max + 1e-9


def simulate_discrete(
    nav: Navigator, grid: GridSnapshot, pose: Pose2D, true_blocked: np.ndarray | None = None, steps: int = 200
) -> tuple[Pose2D, list[DiscreteAction]]:
    """Kinematic stand-in for the simulator: forward 0.25 m unless the end cell is truly blocked."""
    actions = []
    for _ in range(steps):
        a = nav.step(grid, pose)
        actions.append(a)
        if a == DiscreteAction.STOP:
            break
        if a == DiscreteAction.TURN_LEFT:
            pose = Pose2D(pose.x, pose.y, pose.yaw + math.radians(30))
        elif a == DiscreteAction.TURN_RIGHT:
            pose = Pose2D(pose.x, pose.y, pose.yaw - math.radians(30))
        elif a == DiscreteAction.MOVE_FORWARD:
            nxt = Pose2D(pose.x + 0.25 * math.cos(pose.yaw), pose.y + 0.25 * math.sin(pose.yaw), pose.yaw)
            rc = grid.world_to_cell(nxt.xy)
            if true_blocked is None or not true_blocked[rc[0], rc[1]]:
                pose = nxt
    return pose, actions


def test_navigator_reaches_a_goal_around_a_wall():
    s = open_room()
    s[20:100, 50] = 1  # wall with a gap at the bottom (rows 1..19)
    grid = snapshot(s)
    nav = Navigator()
    nav.set_goal(Goal(4.0, 4.0, tolerance=0.25))
    pose, actions = simulate_discrete(nav, grid, Pose2D(1.0, 4.0, 0.0))
    assert nav.reached and actions[-1] == DiscreteAction.STOP
    assert np.hypot(pose.x - 4.0, pose.y - 4.0) <= 0.25
    assert nav.path_xy is not None and nav.n_plans >= 1


def test_goal_yaw_is_reached_after_position():
    grid = snapshot(open_room())
    nav = Navigator()
    nav.set_goal(Goal(2.5, 2.5, yaw=-math.pi / 2, tolerance=0.3))
    pose, _ = simulate_discrete(nav, grid, Pose2D(1.0, 1.0, 0.0))
    assert nav.reached and abs((pose.yaw + math.pi / 2 + math.pi) % (2 * math.pi) - math.pi) <= math.radians(
        15
    )


def test_unreachable_goal_stops_with_no_path():
    s = open_room()
    s[:, 50] = 1
    nav = Navigator()
    nav.set_goal(Goal(4.0, 2.5))
    assert nav.step(snapshot(s), Pose2D(1.0, 2.5, 0.0)) == DiscreteAction.STOP
    assert not nav.reached and nav.status == "no_path"
    nav.set_goal(None)
    assert nav.step(snapshot(s), Pose2D(1.0, 2.5, 0.0)) == DiscreteAction.STOP and nav.status == "idle"


def test_a_goal_may_ask_for_a_path_through_unknown_cells():
    """Approach's last creep toward an object crosses floor the camera never saw; other goals do not."""
    s = open_room()
    s[:, 45:55] = -1  # a band never seen
    plain = Navigator()
    plain.set_goal(Goal(4.0, 2.5))
    assert plain.step(snapshot(s), Pose2D(1.0, 2.5, 0.0)) == DiscreteAction.STOP and plain.status == "no_path"
    creep = Navigator()
    creep.set_goal(Goal(4.0, 2.5, through_unknown=True))
    assert creep.step(snapshot(s), Pose2D(1.0, 2.5, 0.0)) == DiscreteAction.MOVE_FORWARD


def test_replans_when_the_path_becomes_blocked():
    grid = snapshot(open_room())
    nav = Navigator()
    nav.set_goal(Goal(4.0, 2.5))
    nav.step(grid, Pose2D(1.0, 2.5, 0.0))
    assert nav.path_xy is not None and len(nav.path_xy) == 2  # straight line
    s = open_room()
    s[30:70, 50] = 1  # a new obstacle across the straight line
    blocked_grid = snapshot(s)
    plans = nav.n_plans
    nav.step(blocked_grid, Pose2D(1.0, 2.5, 0.0))
    assert nav.n_plans == plans + 1 and len(nav.path_xy) > 2


def test_recovers_when_stuck_on_an_unmapped_obstacle():
    grid = snapshot(open_room())
    truth = np.zeros((100, 100), bool)
    truth[30:70, 40:44] = True  # invisible to the map: a glass wall
    nav = Navigator()
    nav.set_goal(Goal(4.0, 2.5, tolerance=0.25))
    pose, actions = simulate_discrete(nav, grid, Pose2D(1.0, 2.5, 0.0), true_blocked=truth, steps=300)
    assert nav.n_recoveries >= 1 or len(nav._virtual) >= 1
    assert nav.reached, nav.status
    assert np.hypot(pose.x - 4.0, pose.y - 2.5) <= 0.25


def test_a_forward_step_that_slid_along_an_obstacle_counts_as_blocked():
    # a blocked step slides along the obstacle (Habitat-Sim's default, and the simulator's): the
    # robot moves a few centimetres sideways, not the step's 0.25 m; counted as a step taken, it
    # turned back and forth at a gap its map showed open, sliding to and fro, until the step limit
    grid = snapshot(open_room())
    nav = Navigator()
    nav.set_goal(Goal(4.0, 2.5, tolerance=0.25))
    assert nav.step(grid, Pose2D(1.0, 2.5, 0.0)) == DiscreteAction.MOVE_FORWARD
    nav.step(grid, Pose2D(1.0, 2.57, 0.0))  # 7 cm along the obstacle
    assert len(nav._virtual) == 1
    nav2 = Navigator()
    nav2.set_goal(Goal(4.0, 2.5, tolerance=0.25))
    nav2.step(grid, Pose2D(1.0, 2.5, 0.0))
    nav2.step(grid, Pose2D(1.19, 2.5, 0.0))  # most of a step, slowed by the slide's last sub-step
    assert not nav2._virtual


def test_velocity_mode_backs_off_when_stuck():
    grid = snapshot(open_room())
    nav = Navigator()
    nav.set_goal(Goal(4.0, 2.5))
    pose = Pose2D(1.0, 2.5, 0.0)
    cmds = [nav.step_velocity(grid, pose, dt=0.1) for _ in range(40)]  # the robot never moves
    assert any(c.v < 0 for c in cmds), "no back-off"
    assert nav.n_recoveries >= 1
    assert all(isinstance(c, VelocityCommand) for c in cmds)


def test_a_goal_fails_after_max_recoveries_in_one_spot():
    """Gibson Lindenwood/0/0: blocked by what the map did not know, the robot recovered (turned
    away and stepped) and came back to the same blocked step for 16 s of clock, until the
    mission's stall clock gave up. The navigator gives the goal up itself ("stuck", a STOP the
    control actor reports as failed) after max_recoveries recoveries within give_up_m; with 0 it
    never does."""
    grid = snapshot(open_room())
    for limit, gives_up in ((3, True), (0, False)):
        nav = Navigator(NavigatorConfig(max_recoveries=limit))
        nav.set_goal(Goal(4.0, 2.5, tolerance=0.25))
        pose = Pose2D(1.0, 2.5, 0.0)
        actions = []
        for _ in range(120):  # the robot never moves: every forward step is blocked
            a = nav.step(grid, pose)
            actions.append(a)
            if a == DiscreteAction.STOP:
                break
            if a in (DiscreteAction.TURN_LEFT, DiscreteAction.TURN_RIGHT):
                turn = math.radians(30.0) * (1 if a == DiscreteAction.TURN_LEFT else -1)
                pose = Pose2D(pose.x, pose.y, pose.yaw + turn)
        assert (nav.status == "stuck") == gives_up, nav.status
        assert (actions[-1] == DiscreteAction.STOP) == gives_up
        assert nav.n_recoveries == limit - 1 if gives_up else nav.n_recoveries >= 3
        assert not nav.reached
    nav.set_goal(Goal(3.0, 2.5, tolerance=0.25))  # a new goal starts its count afresh
    assert nav.status == "following" and nav._recoveries_at == []


def test_velocity_mode_gives_a_goal_up_after_max_recoveries_in_one_spot():
    grid = snapshot(open_room())
    nav = Navigator(NavigatorConfig(max_recoveries=2))
    nav.set_goal(Goal(4.0, 2.5))
    pose = Pose2D(1.0, 2.5, 0.0)
    for _ in range(200):  # the robot never moves
        cmd = nav.step_velocity(grid, pose, dt=0.1)
        if nav.status == "stuck":
            break
    assert nav.status == "stuck" and cmd.v == 0.0 and cmd.omega == 0.0 and nav.n_recoveries == 1


def test_resending_the_same_goal_changes_nothing():
    grid = snapshot(open_room())
    nav = Navigator()
    goal = Goal(2.0, 2.0, tolerance=0.3)
    nav.set_goal(goal)
    simulate_discrete(nav, grid, Pose2D(1.0, 2.0, 0.0))
    assert nav.reached
    nav.set_goal(Goal(2.0, 2.0, tolerance=0.3))
    assert nav.reached
    nav.set_goal(Goal(3.0, 2.0, tolerance=0.3))
    assert not nav.reached and nav.path_xy is None


def _doorway_grid(gap_cells: int) -> GridSnapshot:
    """A wall across the room at column 50 with one doorway ``gap_cells`` wide; lethal = radius 3.6 cells,
    inflated = radius 4.6 cells (robot radius + margin, as the occupancy grid defaults)."""
    s = open_room()
    s[:, 50] = 1
    s[50 - gap_cells // 2:50 - gap_cells // 2 + gap_cells, 50] = 0
    occ = (s == 1).astype(np.uint8)
    return GridSnapshot(state=s, inflated=cv2.dilate(occ, disk_kernel(4.6)).astype(bool),
                        lethal=cv2.dilate(occ, disk_kernel(3.6)).astype(bool), explored=s != -1,
                        origin=np.zeros(2), resolution=RES, version=1, stamp=0.0)


def test_a_doorway_the_margin_closes_is_crossed_on_the_tight_fallback():
    grid = _doorway_grid(8)  # 0.40 m: the 0.36 m robot fits, robot + 2 x 5 cm margin does not
    assert grid.inflated[:, 50].all() and not grid.lethal[:, 50].all()
    nav = Navigator()
    nav.set_goal(Goal(4.0, 2.5, tolerance=0.25))
    pose, actions = simulate_discrete(nav, grid, Pose2D(1.0, 2.5, 0.0), true_blocked=grid.lethal, steps=300)
    assert nav.reached and np.hypot(pose.x - 4.0, pose.y - 2.5) <= 0.25
    first = Navigator()
    first.set_goal(Goal(4.0, 2.5, tolerance=0.25))
    assert first.plan(grid, Pose2D(1.0, 2.5, 0.0)) and first.tight

    strict = Navigator()
    strict.config.tight_fallback = False
    strict.set_goal(Goal(4.0, 2.5, tolerance=0.25))
    assert strict.step(grid, Pose2D(1.0, 2.5, 0.0)) == DiscreteAction.STOP and strict.status == "no_path"


def test_a_wide_doorway_keeps_the_margin():
    grid = _doorway_grid(20)
    nav = Navigator()
    nav.set_goal(Goal(4.0, 2.5, tolerance=0.25))
    assert nav.plan(grid, Pose2D(1.0, 2.5, 0.0)) and not nav.tight


def test_a_diagonal_path_is_followed_without_zig_zag():
    """A path between two of the 30-degree headings: turning whenever the error passes 15 degrees
    costs about one turn per forward step; the forward tolerance keeps turns rare."""
    grid = snapshot(open_room())

    def turns(forward_tolerance: float) -> tuple[int, int, bool]:
        nav = Navigator()
        nav.config.discrete.forward_tolerance_deg = forward_tolerance
        nav.set_goal(Goal(4.5, 4.5, tolerance=0.25))  # bearing 45 degrees: between two headings
        _, actions = simulate_discrete(nav, grid, Pose2D(0.6, 0.6, 0.0), steps=300)
        n_turn = sum(a in (DiscreteAction.TURN_LEFT, DiscreteAction.TURN_RIGHT) for a in actions)
        n_fwd = sum(a == DiscreteAction.MOVE_FORWARD for a in actions)
        return n_turn, n_fwd, nav.reached

    old_turns, old_fwd, old_ok = turns(15.0)
    new_turns, new_fwd, new_ok = turns(35.0)
    assert old_ok and new_ok
    assert new_turns <= 8 and old_turns >= 15, (new_turns, old_turns)  # measured: 5 vs 23
    assert new_turns + new_fwd < old_turns + old_fwd


def test_virtual_obstacles_that_wall_the_robot_in_are_cleared_when_no_path_is_left():
    """Stuck steps leave virtual obstacles; once they close every way out, the navigator clears
    them and plans on what the sensors saw instead of reporting no path for good."""
    s = open_room()
    nav = Navigator()
    nav.set_goal(Goal(4.0, 2.5))
    pose = Pose2D(1.0, 2.5, 0.0)
    for yaw in np.linspace(0.0, 2 * math.pi, 16, endpoint=False):  # a ring of them round the robot
        nav._add_virtual_obstacle(Pose2D(pose.x, pose.y, float(yaw)))
    assert nav.step(snapshot(s), pose) != DiscreteAction.STOP
    assert nav.status == "following" and nav._virtual == []


def test_a_creep_through_unknown_floor_plans_on_the_robot_radius_alone():
    """A creep toward an object (``Goal.through_unknown``) ends inside the inflation margin, as the
    robot radius allows; on the normal mask its goal snapped back to a roomy cell the robot had
    already reached (Gibson Ranchester/0/1 ended 0.96 m from a plant, 0.85 m was reachable)."""
    grid = _doorway_grid(0)  # a wall at x = 2.5 m: inflated from 2.27 m, lethal from 2.32 m
    creep = Navigator()
    creep.set_goal(Goal(2.3, 2.5, tolerance=0.1, through_unknown=True))
    assert creep.plan(grid, Pose2D(1.0, 2.5, 0.0)) and creep.tight
    assert abs(creep.path_xy[-1][0] - 2.3) <= 0.05
    roomy = Navigator()
    roomy.set_goal(Goal(2.3, 2.5, tolerance=0.1))
    assert roomy.plan(grid, Pose2D(1.0, 2.5, 0.0)) and not roomy.tight
    assert roomy.path_xy[-1][0] <= 2.275  # the last roomy cell


def test_a_goal_through_unknown_floor_squeezes_through_a_gap_the_lethal_layer_closes():
    """The map's occupied cells reach 0.5-1.5 cells past a surface (grid phase): a 0.45 m passage
    that the 0.36 m robot fits through lost its last lethal-free cell (Gibson Stockman/0/3). A push
    or a creep (``through_unknown``) plans once more on the lethal layer one cell thinner; an
    ordinary goal never does, and ``squeeze_fallback`` off restores the old behaviour."""
    s = open_room()
    s[:, 50] = 1
    s[47:53, 50] = 0  # 6 free cells between the occupied ones
    occ = (s == 1).astype(np.uint8)
    grid = GridSnapshot(state=s, inflated=cv2.dilate(occ, disk_kernel(4.1)).astype(bool),
                        lethal=cv2.dilate(occ, disk_kernel(3.1)).astype(bool), explored=s != -1,
                        origin=np.zeros(2), resolution=RES, version=1, stamp=0.0)
    ordinary = Navigator()
    ordinary.set_goal(Goal(4.0, 2.5, tolerance=0.25))
    assert not ordinary.plan(grid, Pose2D(1.0, 2.5, 0.0))
    push = Navigator()
    push.set_goal(Goal(4.0, 2.5, tolerance=0.25, through_unknown=True))
    assert push.plan(grid, Pose2D(1.0, 2.5, 0.0)) and push.squeeze and push.tight
    crossing = [p for p in push._dense_xy if 2.5 <= p[0] <= 2.55]  # the wall's column
    assert crossing and all(2.35 <= p[1] <= 2.65 for p in crossing)  # through the gap itself
    off = Navigator()
    off.config.squeeze_fallback = False
    off.set_goal(Goal(4.0, 2.5, tolerance=0.25, through_unknown=True))
    assert not off.plan(grid, Pose2D(1.0, 2.5, 0.0))
    # the squeeze mask keeps every occupied cell blocked and only ever frees lethal cells
    sq = squeeze_mask(grid)
    assert sq[occ.astype(bool)].all() and not (sq & ~grid.lethal).any()


def test_a_stuck_robot_inside_the_inflation_turns_toward_the_farther_obstacle():
    """Gibson Lakeville/0/3: between two obstacles 0.45 m apart, inside the inflation of both, the
    rays on the inflated mask ended at once on either side and the tie turned the robot toward
    the nearer obstacle, for 140 steps. Rays to the occupied cells see which side is open."""
    s = open_room()
    s[45, 20:80] = 1  # y 2.25-2.30
    s[52, 20:80] = 1  # y 2.60-2.65
    grid = snapshot(s)
    nav = Navigator()
    assert nav._open_side(grid, Pose2D(2.5, 2.40, math.pi)) == -1  # facing west: north, to its right
    assert nav._open_side(grid, Pose2D(2.5, 2.40, 0.0)) == 1  # facing east: north, to its left


def test_a_straight_goal_steps_up_to_the_obstacle_without_a_plan():
    """``Goal.straight`` (an Approach creep's last centimetres): face the point and step until a
    step is blocked. The map's lethal zone plus its cells kept a creep 0.11 m short of where the
    robot fits (Gibson Ranchester/0/1 ended 1.005 m from a plant, success at 1 m)."""
    grid = _doorway_grid(0)  # a wall at x = 2.50 m; the robot centre fits up to x = 2.32 m

    def run(goal: Goal) -> tuple[Pose2D, Navigator]:
        nav = Navigator()
        nav.set_goal(goal)
        pose = Pose2D(1.55, 2.5, 0.0)
        for _ in range(30):
            a = nav.step(grid, pose)
            if a == DiscreteAction.STOP:
                break
            if a == DiscreteAction.MOVE_FORWARD:  # the simulator's partial move, stopped by the wall
                x = pose.x
                for _ in range(10):
                    if x + 0.025 > 2.32:
                        break
                    x += 0.025
                pose = Pose2D(x, pose.y, pose.yaw)
            elif a in (DiscreteAction.TURN_LEFT, DiscreteAction.TURN_RIGHT):
                pose = Pose2D(pose.x, pose.y, pose.yaw + math.radians(30 if a == DiscreteAction.TURN_LEFT else -30))
        return pose, nav

    pose, nav = run(Goal(2.6, 2.5, 0.0, tolerance=0.1, straight=True))
    assert nav.reached and nav.n_plans == 0 and pose.x >= 2.29  # up to the wall, to within a sub-step
    assert nav.step(grid, pose) == DiscreteAction.STOP
    far, nav = run(Goal(2.0, 2.5, 0.0, tolerance=0.1, straight=True))
    assert nav.reached and abs(far.x - 2.05) < 1e-9  # within half a step of the point: done


def test_a_straight_goal_ends_when_a_step_slides_along_the_obstacle_without_coming_nearer():
    """Gibson Ranchester/0/3: creeping toward a plant's box corner, each forward step slid the
    robot 0.05-0.08 m along the plant's side, one way then the other as its heading to the point
    swung, for 3 s and 1.2 m of path without coming nearer. A step that moved the robot but
    brought it no nearer the point is blocked too."""
    grid = snapshot(open_room())
    nav = Navigator()
    goal = Goal(2.5, 3.5, None, tolerance=0.1, straight=True)
    nav.set_goal(goal)
    pose = Pose2D(2.5, 2.5, math.pi / 2)  # facing the point, 1 m off
    assert nav.step(grid, pose) == DiscreteAction.MOVE_FORWARD
    slid = Pose2D(2.57, 2.51, math.pi / 2)  # the step slid 0.07 m sideways, 0.01 m nearer
    assert nav.step(grid, slid) == DiscreteAction.STOP and nav.reached
    # a step that does bring it nearer goes on
    nav = Navigator()
    nav.set_goal(goal)
    assert nav.step(grid, pose) == DiscreteAction.MOVE_FORWARD
    assert nav.step(grid, Pose2D(2.5, 2.75, math.pi / 2)) == DiscreteAction.MOVE_FORWARD


def test_a_robot_circling_near_its_goal_settles_there_but_not_far_from_it():
    """ProcTHOR val/45/2: 0.25 m steps carried the robot back and forth across a goal it stood
    0.12-0.13 m from, never within its 0.125 m reach, for 460 steps. Within settle_m, settle_steps steps
    without coming 2 cm nearer count as reached; farther out the same rocking does not."""
    from hiconav.planning.config import NavigatorConfig

    grid = snapshot(open_room())

    def rock(nav: Navigator, goal: Goal, offset: float, steps: int) -> int | None:
        nav.set_goal(goal)
        for i in range(steps):  # whatever it asks for, the robot lands on one side or the other
            side = 1.0 if i % 2 else -1.0
            pose = Pose2D(goal.x + side * offset, goal.y + 0.03, 0.0)
            if nav.step(grid, pose) == DiscreteAction.STOP and nav.reached:
                return i
        return None

    goal = Goal(2.5, 2.5, tolerance=0.1)
    assert rock(Navigator(), goal, 0.16, 60) is not None
    assert rock(Navigator(), goal, 0.16, 60) <= NavigatorConfig().settle_steps + 2
    assert rock(Navigator(), goal, 0.5, 60) is None  # 0.5 m off: not there
    assert rock(Navigator(NavigatorConfig(settle_steps=1000)), goal, 0.16, 60) is None


@pytest.mark.parametrize("pose", [Pose2D(1.0, 1.0, math.nan), Pose2D(math.nan, 1.0, 0.0), Pose2D(1.0, math.inf, 0.0)])
def test_a_non_finite_pose_gives_stop_and_no_turn(pose):
    nav = Navigator()
    nav.set_goal(Goal(3.5, 1.0, tolerance=0.2))
    assert nav.step(snapshot(open_room()), pose) == DiscreteAction.STOP
    assert nav.status == "bad_pose" and not nav.reached and nav.n_plans == 0


def test_a_non_finite_pose_gives_the_zero_velocity():
    nav = Navigator()
    nav.set_goal(Goal(3.5, 1.0, tolerance=0.2))
    cmd = nav.step_velocity(snapshot(open_room()), Pose2D(1.0, 1.0, math.nan), 0.1, 2.0)
    assert (cmd.v, cmd.omega, cmd.stamp) == (0.0, 0.0, 2.0) and nav.status == "bad_pose"


def test_the_navigator_goes_on_after_a_non_finite_pose():
    nav = Navigator()
    nav.set_goal(Goal(3.5, 1.0, tolerance=0.2))
    grid = snapshot(open_room())
    nav.step(grid, Pose2D(1.0, 1.0, math.nan))
    assert nav.step(grid, Pose2D(1.0, 1.0, 0.0)) == DiscreteAction.MOVE_FORWARD
