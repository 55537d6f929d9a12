"""decisions.linger: which undecided instance of the target's category to turn beside."""

from __future__ import annotations

import numpy as np

from hiconav.decisions import linger

from hiconav.geometry import footprint_distance

from .fakes import Node, open_grid


def node(oid: int, label: str, x: float, y: float, half: float = 0.3) -> Node:
    return Node(oid, label, np.array([x - half, y - half, 0.0]), np.array([x + half, y + half, 0.9]))


ROBOT = np.array([0.0, 0.0])


def test_the_nearest_instance_of_the_category_within_reach_is_lingered_by():
    nodes = [node(1, "chair", 2.0, 0.0), node(2, "Chair", 1.0, 0.0), node(3, "fridge", 0.5, 0.0)]
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 1.5, (), ()) == 2
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 0.5, (), ()) is None  # 0.7 m: too far
    assert linger.undecided_near(nodes, ["sofa"], ROBOT, 1.5, (), ()) is None


def test_an_instance_ruled_out_lingered_by_or_excluded_is_passed_over():
    nodes = [node(1, "chair", 1.0, 0.0), node(2, "chair", 1.5, 0.0)]
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 1.5, {1}, ()) == 2
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 1.5, (), {1}) == 2
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 1.5, (), (), excluded=lambda i: i == 1) == 2
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 1.5, {1}, {2}) is None


def test_a_target_described_below_something_is_one_to_step_back_from():
    assert linger.beneath([("bed", "below", "painting")], ["bed"])
    assert linger.beneath([("toilet", "Under", "painting"), ("toilet", "in", "bathroom")], ["toilet"])
    assert not linger.beneath([("bed", "next to", "dresser")], ["bed"])
    assert not linger.beneath([("painting", "above", "bed")], ["painting"])  # the target is the one above
    assert not linger.beneath([("lamp", "under", "shelf")], ["bed"])  # a related object's relation


def test_the_step_back_ring_holds_what_hangs_above_in_the_camera_view():
    vfov = np.radians(64.0)
    ring = linger.step_back_ring((0.88, vfov), 8.0)
    # from the ring the point ABOVE_CENTRE_M up is 24 degrees above the camera: inside its view
    assert abs(np.degrees(np.arctan((linger.ABOVE_CENTRE_M - 0.88) / ring)) - 24.0) < 1e-6
    assert 1.9 < ring < 2.2
    assert linger.step_back_ring(None, 8.0) == 0.0
    assert linger.step_back_ring((0.88, np.radians(20.0)), 8.0) == 0.0  # no view left to spare


def test_the_step_back_cell_lies_on_the_robots_side_about_the_ring_out():
    grid = open_grid()
    grid.state[45:55, 45:55] = 1  # the instance's footprint, 1 m x 1 m at (5, 5)
    grid.inflated = grid.state == 1
    lo, hi = np.array([4.5, 4.5, 0.0]), np.array([5.5, 5.5, 0.8])
    robot = np.array([5.0, 6.2])  # beside it, north
    cell = linger.step_back_cell(grid, lo, hi, robot, 2.0)
    assert cell is not None
    gap = footprint_distance(lo, hi, cell)
    assert 1.5 <= gap <= 2.3
    assert cell[1] > 5.5  # on the robot's side, not round the far side


def test_a_wall_close_behind_the_robot_leaves_no_step_back_cell_until_the_way_round_it_opens():
    grid = open_grid()
    grid.state[45:55, 45:55] = 1
    grid.state[67, :] = 1  # a wall across the room 1.2 m past the footprint, behind the robot
    grid.inflated = grid.state == 1
    lo, hi = np.array([4.5, 4.5, 0.0]), np.array([5.5, 5.5, 0.8])
    robot = np.array([5.0, 6.2])
    assert linger.step_back_cell(grid, lo, hi, robot, 2.0) is None  # the robot's side holds no cell 1.5 m out
    grid.state[67, :] = 0
    grid.state[67, :40] = 1  # the wall now ends west of the instance: the floor behind it is reachable
    grid.inflated = grid.state == 1
    cell = linger.step_back_cell(grid, lo, hi, robot, 2.0)
    assert cell is not None and footprint_distance(lo, hi, cell) >= 1.5


def test_the_step_back_goal_faces_the_instance_and_only_for_a_target_below_something():
    grid = open_grid()
    grid.state[45:55, 45:55] = 1
    grid.inflated = grid.state == 1
    lo, hi = np.array([4.5, 4.5, 0.0]), np.array([5.5, 5.5, 0.8])
    camera = (0.88, np.radians(64.0))
    below = [("bed", "below", "painting")]
    x, y, yaw = linger.step_back_goal(below, ["bed"], lo, hi, np.array([5.0, 6.2]), grid, camera, 8.0)
    assert abs(yaw - np.arctan2(5.0 - y, 5.0 - x)) < 1e-9 and y > 6.5  # stepped back north, facing the bed
    assert linger.step_back_goal([("bed", "next to", "dresser")], ["bed"], lo, hi, np.array([5.0, 6.2]), grid,
                                 camera, 8.0) is None
    assert linger.step_back_goal(below, ["bed"], lo, hi, np.array([5.0, 6.2]), grid, None, 8.0) is None
