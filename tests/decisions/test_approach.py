"""The approach planner (hiconav.decisions.approach) on small hand-built grids: how far the robot
is, which rings it looks on and in which order, when it steps straight in, where a creep goes and
when it is done."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiconav.decisions import approach as plan
from hiconav.decisions import geometry
from hiconav.geometry import rounded_box_distance
from hiconav.decisions.config import ApproachSettings

from .fakes import Grid

LO, HI = np.array([4.5, 4.5, 0.0]), np.array([5.5, 5.5, 0.8])  # a 1 m x 1 m object at (5, 5)
CENTRE = np.array([5.0, 5.0, 0.4])


def room(*walls: tuple[slice, slice]) -> Grid:
    """A 10 m x 10 m free room at 0.1 m with walls on its border, the object's footprint occupied,
    and each (rows, cols) slice of ``walls`` a wall."""
    state = np.zeros((100, 100), dtype=np.int8)
    state[0, :] = state[-1, :] = state[:, 0] = state[:, -1] = 1
    state[45:55, 45:55] = 1
    for rows, cols in walls:
        state[rows, cols] = 1
    return Grid(state, state == 1)


def straight(grid: Grid, robot: tuple[float, float], s: ApproachSettings = ApproachSettings()) -> bool:
    xy = np.array(robot, dtype=np.float64)
    return plan.straight_way_in(grid, xy, LO, HI, plan.gap(xy, LO, HI, None, s), s, [], None)


def test_a_box_is_measured_to_the_nearest_point_of_its_footprint():
    g = plan.gap(np.array([3.5, 6.0]), LO, HI, None, ApproachSettings(corner_radius=0.0))
    assert g.distance == pytest.approx(math.hypot(1.0, 0.5)) and np.allclose(g.near, [4.5, 5.5])


def test_a_box_is_measured_with_its_corners_rounded():
    """Beside a face the rounded box is the box; off a corner, on the diagonal, it is (sqrt(2) - 1)
    x the radius farther (a plant or chair leaves its box's corners empty); the radius is at most
    half the shorter side, and 0 gives the box."""
    s = ApproachSettings()
    assert s.corner_radius == pytest.approx(0.3)
    side = plan.gap(np.array([3.5, 5.2]), LO, HI, None, s)
    assert side.distance == pytest.approx(1.0) and np.allclose(side.near, [4.5, 5.2])
    corner = np.array([4.5 - 0.6, 4.5 - 0.6])
    assert plan.gap(corner, LO, HI, None, s).distance == pytest.approx(math.hypot(0.9, 0.9) - 0.3)
    assert plan.gap(corner, LO, HI, None, ApproachSettings(corner_radius=0.0)).distance == \
        pytest.approx(math.hypot(0.6, 0.6))
    # a 0.2 m deep box (a painting on its wall): the radius stops at 0.1 m
    thin = rounded_box_distance(4.0, 4.0, np.array([4.5, 4.5, 0.0]), np.array([5.5, 4.7, 1.0]), 0.3)
    assert float(thin) == pytest.approx(math.hypot(0.6, 0.6) - 0.1)
    assert float(rounded_box_distance(5.0, 5.0, LO, HI, 0.3)) == 0.0  # inside


def test_approach_cells_keep_the_success_distance_off_a_corner_too():
    """The ring's cells lie within the distance of the rounded box: a cell on the box's diagonal
    ring (0.85 m from its corner) is 0.97 m from a round object the box holds, and is not taken."""
    grid = room()
    robot = np.array([2.0, 2.0])
    for r in (0.0, 0.3):
        cell = geometry.approach_cell(grid, LO, HI, robot, 0.85, corner_radius=r)
        d = float(rounded_box_distance(cell[0], cell[1], LO, HI, 0.3))
        assert (d > 0.85) if r == 0.0 else (d <= 0.85 + 1e-9)


def test_by_points_a_robot_off_a_round_objects_diagonal_is_as_far_as_its_nearest_points_not_its_box_corner():
    # a round object's points on a circle of 0.5 m about the centre; the robot off the box's corner
    angles = np.linspace(0.0, 2.0 * math.pi, 200, endpoint=False)
    pts = np.stack([5.0 + 0.5 * np.cos(angles), 5.0 + 0.5 * np.sin(angles), np.full(200, 0.4)], axis=1)
    robot = np.array([4.0, 4.0])
    by_box = plan.gap(robot, LO, HI, pts, ApproachSettings(corner_radius=0.0))
    by_points = plan.gap(robot, LO, HI, pts, ApproachSettings(measure="points"))
    assert by_box.distance == pytest.approx(math.hypot(0.5, 0.5))
    assert by_points.distance == pytest.approx(math.hypot(1.0, 1.0) - 0.5, abs=0.01)
    assert by_points.distance > by_box.distance


def test_by_points_a_node_with_too_few_points_is_measured_by_its_box():
    pts = np.array([[5.0, 5.0, 0.4]] * 5)
    g = plan.gap(np.array([3.5, 5.0]), LO, HI, pts, ApproachSettings(measure="points"))
    assert g.distance == pytest.approx(1.0) and np.allclose(g.near, [4.5, 5.0])


def test_rings_aim_inside_the_distance_widen_to_it_then_settle_out_to_max_distance():
    assert plan.rings(ApproachSettings(distance=0.85, inner_margin=0.2)) == pytest.approx(
        [0.65, 0.75, 0.85, 1.0, 1.25, 1.5])
    assert plan.rings(ApproachSettings(distance=0.85, inner_margin=0.0)) == pytest.approx([0.85, 1.0, 1.25, 1.5])


def test_rings_never_come_nearer_the_footprint_than_min_ring():
    assert min(plan.rings(ApproachSettings(distance=0.3, inner_margin=0.5))) == pytest.approx(0.2)


def test_ring_order_tries_wall_strict_cells_out_to_strict_within_then_any_within_the_distance_then_the_rest():
    order = [(t.strict, t.ring) for t in plan.ring_order(ApproachSettings(distance=0.85, inner_margin=0.0))]
    assert order == [(True, 0.85), (True, 1.0), (False, 0.85), (True, 1.25), (True, 1.5), (False, 1.0),
                     (False, 1.25), (False, 1.5)]


def test_ring_order_on_settle_rings_prefers_cells_nearest_the_object():
    s = ApproachSettings(distance=0.85)
    assert all((t.box_weight == s.settle_box_weight) == (t.ring > s.distance) for t in plan.ring_order(s))
    assert all(t.box_weight == 0.0 for t in plan.ring_order(s) if t.ring <= s.distance)


def test_a_robot_a_little_beyond_the_distance_with_the_way_clear_steps_straight_in():
    assert straight(room(), (3.5, 5.0))  # 1.0 m off, 0.85 m distance


def test_no_straight_way_in_through_an_obstacle_on_the_line():
    assert not straight(room((slice(1, 99), slice(38, 39))), (3.5, 5.0))


def test_no_straight_way_in_when_the_ring_point_does_not_see_the_footprints_centre_past_a_wall():
    assert not straight(room((slice(1, 99), slice(42, 43))), (3.5, 5.0))  # past the checked run, before the box


def test_no_straight_way_in_from_farther_than_straight_within_beyond_the_distance_or_from_within_it():
    assert not straight(room(), (2.5, 5.0))  # 2.0 m off
    assert not straight(room(), (3.8, 5.0))  # 0.7 m off: already within
    assert not straight(room(), (3.5, 5.0), ApproachSettings(straight_within=0.0))


def test_a_creep_goes_straight_through_unknown_floor_to_the_objects_nearest_point_within_the_distance():
    s = ApproachSettings(distance=0.85)
    goal = plan.creep_goal(plan.Gap(1.0, np.array([4.5, 5.0])), 3, s)
    assert (goal.x, goal.y, goal.tolerance, goal.ref_id) == (4.5, 5.0, 0.85, 3)
    assert goal.straight and goal.through_unknown and goal.kind == "approach"


def test_no_creep_from_within_the_distance():
    assert plan.creep_goal(plan.Gap(0.8, np.array([4.5, 5.0])), 3, ApproachSettings(distance=0.85)) is None


def test_a_turn_in_place_faces_the_objects_centre():
    goal = plan.face_goal(3.0, 5.0, CENTRE, 3, ApproachSettings())
    assert (goal.x, goal.y, goal.kind) == (3.0, 5.0, "look") and goal.yaw == pytest.approx(0.0)


def test_a_robot_done_on_a_settle_ring_creeps_on_and_one_at_a_cell_short_of_a_near_ring_too():
    s = ApproachSettings(distance=0.85)
    assert plan.settled_beyond(1.25, s) and not plan.settled_beyond(0.85, s)
    assert plan.creeps_on(1.0, s) and not plan.creeps_on(1.25, s)
    assert not plan.settled_beyond(1.25, ApproachSettings(creep=False))


def test_done_needs_close_at_the_cell_and_facing_the_object():
    s = ApproachSettings(distance=0.85)
    robot, cell = np.array([3.7, 5.0]), np.array([3.7, 5.0])
    assert plan.done(robot, 0.0, 0.8, 0.85, cell, False, CENTRE, s)
    assert not plan.done(robot, math.pi / 2, 0.8, 0.85, cell, False, CENTRE, s)  # facing away
    assert not plan.done(robot, 0.0, 0.9, 0.85, cell, False, CENTRE, s)  # not within the ring
    assert plan.done(robot, 0.0, 0.9, 1.0, cell, False, CENTRE, s)  # within the ring settled for
    assert not plan.done(robot, 0.0, 0.8, 0.85, np.array([3.7, 4.0]), False, CENTRE, s)  # off its cell


def test_done_without_a_cell_only_once_turned_toward_the_object():
    s = ApproachSettings(distance=0.85)
    robot = np.array([3.7, 5.0])
    assert not plan.done(robot, 0.0, 0.8, 0.0, None, False, CENTRE, s)
    assert plan.done(robot, 0.0, 0.8, 0.0, None, True, CENTRE, s)


def test_without_a_cell_a_last_resort_creeps_then_faces_and_others_face_only_within_the_distance():
    s = ApproachSettings(distance=0.85)
    assert plan.without_cell(2.0, True, False, False, s) == "creep"
    assert plan.without_cell(0.5, True, False, False, s) == "face"
    assert plan.without_cell(2.0, True, False, True, s) is None  # the creep ended: the behaviour faces
    assert plan.without_cell(2.0, True, False, False, ApproachSettings(creep=False)) == "face"
    assert plan.without_cell(2.0, False, False, False, s) is None  # no reachable approach cell
    assert plan.without_cell(0.5, False, False, False, s) == "face"
    assert plan.without_cell(0.5, False, True, False, s) is None


def test_with_path_cost_the_cell_on_the_robots_side_of_furniture_wins_over_the_nearer_in_a_line():
    """A table between the robot and the object: the straight-line nearest cell lies in the gap
    between the table and the object, a walk round the table's end and back; by the path on the
    map a cell off the table's end wins, within the ring all the same."""
    table = (slice(60, 68), slice(35, 66))  # y 6.0-6.8 m, x 3.5-6.6 m: north of the object
    grid = room(table)
    grid.inflated = grid.state == 1
    robot = np.array([5.0, 8.0])  # north of the table
    line = geometry.approach_cell(grid, LO, HI, robot, 1.2)
    path = geometry.approach_cell(grid, LO, HI, robot, 1.2, path_cost=True)
    assert line is not None and path is not None
    lengths = geometry.path_lengths(grid, robot, (0, 100, 0, 100))
    res = grid.resolution

    def walk(c):
        return float(lengths[int(c[1] / res), int(c[0] / res)])
    assert walk(path) < walk(line) - 1.0  # the line's pick is a walk round the table
    assert rounded_box_distance(path[0], path[1], LO, HI, 0.0) <= 1.2 + 1e-9


def test_path_lengths_follow_the_free_cells_and_leave_walled_off_cells_unreached():
    grid = room((slice(0, 100), slice(20, 21)))  # a wall across the room at x = 2.0 m
    grid.inflated = grid.state == 1
    lengths = geometry.path_lengths(grid, np.array([5.0, 1.0]), (0, 100, 0, 100), margin_m=20.0)
    assert lengths[10, 50] == pytest.approx(0.0, abs=0.15)
    assert lengths[10, 80] == pytest.approx(3.0, abs=0.15)  # open floor: the straight line
    assert np.isinf(lengths[10, 10])  # behind the wall
