"""The view planner (hiconav.decisions.viewing) on small hand-built grids and boxes: how far to
stand for an object's height, within which distance frames count, what may hide an object, the
point on the line it was seen along, the closer cell, and the next move of a verification."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiconav.decisions import viewing as view
from hiconav.decisions.config import VerifySettings
from hiconav.types import Pose2D, camera_pose_from_base

from .fakes import Grid

S = VerifySettings()
LO, HI = np.array([4.5, 4.5, 0.0]), np.array([5.5, 5.5, 0.8])  # a 1 m x 1 m object at (5, 5)
CENTRE = np.array([5.0, 5.0, 0.4])


def room() -> Grid:
    """A 10 m x 10 m free room at 0.1 m, walls on its border."""
    state = np.zeros((100, 100), dtype=np.int8)
    state[0, :] = state[-1, :] = state[:, 0] = state[:, -1] = 1
    return Grid(state, state == 1)


@dataclass(frozen=True)
class Obj:
    id: int
    box_min: np.ndarray
    box_max: np.ndarray


@dataclass(frozen=True)
class Anchor:
    id: int
    T_world_cam: np.ndarray


def box(oid: int, x: float, y: float, half: float = 0.5, z: tuple[float, float] = (0.0, 0.8)) -> Obj:
    return Obj(oid, np.array([x - half, y - half, z[0]]), np.array([x + half, y + half, z[1]]))


def test_an_object_at_camera_height_is_viewed_from_inside_the_verify_distance():
    camera = (0.4, math.radians(63.0))
    assert view.view_ring(S, 0.4, camera) == S.verify_distance - S.view_margin
    assert view.view_ring(S, 0.4, None) == S.verify_distance - S.view_margin


def test_an_object_high_above_the_camera_is_viewed_from_farther_off_up_to_the_widest_ring():
    camera = (0.88, math.radians(63.0))
    ring = view.view_ring(S, 1.9, camera)  # a tv 1.9 m up is out of view from 1.15 m
    half = 0.5 * math.radians(63.0) - math.radians(S.fov_spare_deg)
    assert ring > S.verify_distance - S.view_margin
    assert math.isclose(ring, (1.9 - 0.88) / math.tan(half))
    assert view.view_ring(S, 20.0, camera) == S.max_view_ring


def test_frames_count_a_margin_beyond_the_farther_of_the_verify_distance_and_the_view_ring():
    assert view.close_distance(S, 1.15) == S.verify_distance + S.close_margin
    assert view.close_distance(S, 3.0) == 3.0 + S.close_ring_gap + S.close_margin


def test_the_objects_own_and_supporting_nodes_never_hide_it():
    objects = [box(1, 5.0, 5.0), box(2, 5.1, 5.0), box(3, 3.0, 5.0)]
    lo, hi = view.blockers(objects, LO, HI, {1, 3}, S) or (None, None)
    assert lo is None
    assert view.blockers([box(1, 5.0, 5.0)], LO, HI, {1}, S) is None


def test_what_an_object_stands_on_never_hides_it_but_a_chair_in_front_does():
    desk = box(2, 5.0, 5.3, half=0.9)  # its footprint overlaps the object's
    chair = box(3, 3.0, 5.0, half=0.3)
    lo, hi = view.blockers([desk, chair], LO, HI, {1}, S)
    assert lo.shape == (1, 3)
    assert np.allclose(lo[0], chair.box_min + [S.blocker_shrink, S.blocker_shrink, 0.0])
    assert np.allclose(hi[0], chair.box_max - [S.blocker_shrink, S.blocker_shrink, 0.0])


def test_a_box_thinner_than_its_shrink_hides_nothing():
    sliver = box(3, 3.0, 5.0, half=0.04)
    assert view.blockers([sliver], LO, HI, {1}, S) is None


def test_any_cell_sees_an_object_when_no_camera_is_known_or_nothing_may_hide_it():
    hiding = (np.zeros((1, 3)), np.ones((1, 3)))
    assert view.sight(CENTRE, None, hiding) is None
    assert view.sight(CENTRE, (0.88, 1.1), None) is None
    centre, height, lo, hi = view.sight(CENTRE, (0.88, 1.1), hiding)
    assert np.array_equal(centre, CENTRE) and height == 0.88 and lo is hiding[0]


def test_the_preferred_point_lies_on_the_line_to_the_camera_that_stood_nearest_the_ring():
    far = Anchor(7, camera_pose_from_base(Pose2D(1.0, 5.0, 0.0), 0.88))  # 4 m off, west
    near = Anchor(8, camera_pose_from_base(Pose2D(5.0, 7.0, 0.0), 0.88))  # 2 m off, north
    point = view.seen_from(CENTRE, [far, near], {7, 8}, 1.5)
    assert np.allclose(point, [5.0, 6.5])
    point = view.seen_from(CENTRE, [far, near], {7}, 1.5)  # only the far one observed it
    assert np.allclose(point, [3.5, 5.0])


def test_a_camera_nearer_than_the_ring_gives_its_own_place_and_none_gives_no_preference():
    close = Anchor(9, camera_pose_from_base(Pose2D(5.0, 6.0, 0.0), 0.88))
    assert np.allclose(view.seen_from(CENTRE, [close], {9}, 1.5), [5.0, 6.0])
    assert view.seen_from(CENTRE, [close], set(), 1.5) is None
    assert view.seen_from(CENTRE, [close], {4}, 1.5) is None


def test_a_candidate_much_nearer_is_verified_first_the_nearest_of_several():
    others = [(3.0, "b"), (2.0, "c"), (2.0, "d")]
    assert view.nearer_candidate(4.5, others, S) == "c"  # the first of equals
    assert view.nearer_candidate(2.5, others, S) is None  # not switch_margin nearer
    assert view.nearer_candidate(4.5, [], S) is None


def test_no_switch_once_frames_are_judged_after_max_switches_or_with_no_margin():
    assert view.may_switch(S, 0, judging=False)
    assert not view.may_switch(S, 0, judging=True)
    assert not view.may_switch(S, S.max_switches, judging=False)
    assert not view.may_switch(VerifySettings(switch_margin=0.0), 0, judging=False)


def test_a_closer_cell_lies_nearer_the_object_and_none_when_the_robot_is_about_as_near():
    robot = np.array([1.0, 5.0])
    gap = view.box_distance(LO, HI, robot)
    assert gap == 3.5
    cell = view.closer_cell(room(), LO, HI, robot, gap, view.close_distance(S, 1.15), S, None, None)
    assert cell is not None and view.box_distance(LO, HI, cell) <= gap - S.closer_min_gain
    near = np.array([3.0, 5.0])
    assert view.closer_cell(room(), LO, HI, near, 1.5, view.close_distance(S, 1.15), S, None, None) is None


def test_a_way_through_unknown_floor_only_for_an_object_seen_often_and_a_few_times():
    assert view.may_try_unknown(S, 0, S.unknown_min_observations)
    assert not view.may_try_unknown(S, 0, S.unknown_min_observations - 1)
    assert not view.may_try_unknown(S, S.unknown_moves, 10)


def test_the_view_cell_through_unknown_floor_is_free_and_within_the_ring():
    state = np.full((100, 100), -1, dtype=np.int8)  # unknown everywhere but two patches
    state[45:56, 25:40] = 0  # west of the object, where the robot cannot walk on the known map
    state[45:56, 5:15] = 0  # where the robot stands
    grid = Grid(state, np.zeros_like(state, dtype=bool))
    robot = np.array([1.0, 5.0])
    cell = view.through_unknown_cell(grid, LO, HI, robot, 1.15, [], None, None, None)
    assert cell is not None and view.box_distance(LO, HI, cell) <= 1.15 + 1e-9
    r, c = int(cell[1] / 0.1), int(cell[0] / 0.1)
    assert state[r, c] == 0


def test_there_and_glancing_while_frames_may_still_show_it():
    move = view.next_view_move(S, close=True, sent=True, state="reached", unseen=0, excluded=0, has_cell=True,
                               closing=False, stalled=False)
    assert move == view.ViewMove(tries=("glance",))


def test_a_cell_that_cannot_show_the_object_is_set_aside_for_another_then_glances_if_none():
    move = view.next_view_move(S, close=True, sent=True, state="reached", unseen=S.reposition_after, excluded=0,
                               has_cell=True, closing=False, stalled=False)
    assert move.tries == ("view", "glance") and move.exclude_cell and move.reset_unseen and move.another_cell


def test_a_closer_cell_that_cannot_show_the_object_leads_on_to_a_view_cell_unknown_floor_or_the_map_not_glances():
    move = view.next_view_move(S, close=True, sent=True, state="reached", unseen=S.reposition_after, excluded=0,
                               has_cell=True, closing=True, stalled=False)
    assert move.tries == ("view", "unknown", "remap") and move.stop_closing and move.reset_unseen
    assert "glance" not in move.tries and move.reason is None
    before = view.next_view_move(S, close=True, sent=True, state="reached", unseen=S.reposition_after - 1, excluded=0,
                                 has_cell=True, closing=True, stalled=False)
    assert before.tries == ("glance",)  # frames that may still show it: glance on


def test_after_view_cells_cells_that_cannot_show_it_the_object_is_deferred_as_hidden():
    move = view.next_view_move(S, close=True, sent=True, state="failed", unseen=S.reposition_after,
                               excluded=S.view_cells, has_cell=True, closing=False, stalled=False)
    assert move.reason == "no view cell shows it" and not move.tries


def test_no_progress_on_the_way_defers_the_object():
    move = view.next_view_move(S, close=False, sent=True, state="active", unseen=0, excluded=0, has_cell=True,
                               closing=False, stalled=True)
    assert move.reason == "no progress toward a view cell"


def test_a_failed_view_cell_is_set_aside_and_the_fallbacks_follow_a_new_view_cell():
    move = view.next_view_move(S, close=False, sent=True, state="failed", unseen=0, excluded=0, has_cell=True,
                               closing=False, stalled=False)
    assert move.tries == ("view", "closer", "unknown", "remap") and move.exclude_cell and move.stop_closing


def test_a_closer_cell_reached_is_not_set_aside_as_a_view_cell():
    move = view.next_view_move(S, close=False, sent=True, state="reached", unseen=0, excluded=0, has_cell=True,
                               closing=True, stalled=False)
    assert not move.exclude_cell and move.tries[0] == "view"


def test_with_more_than_view_cells_set_aside_only_the_fallbacks_remain():
    move = view.next_view_move(S, close=False, sent=True, state="failed", unseen=0, excluded=S.view_cells,
                               has_cell=True, closing=False, stalled=False)
    assert move.tries == ("closer", "unknown", "remap")


def test_a_goal_in_flight_and_making_progress_carries_on():
    move = view.next_view_move(S, close=False, sent=True, state="active", unseen=0, excluded=0, has_cell=True,
                               closing=False, stalled=False)
    assert move == view.ViewMove()


def test_the_stall_clock_is_read_on_the_way_and_while_a_goal_close_by_is_in_flight():
    assert view.stall_matters(close=False, sent=False, state="pending")
    assert view.stall_matters(close=True, sent=True, state="active")
    assert not view.stall_matters(close=True, sent=True, state="reached")
    assert not view.stall_matters(close=True, sent=False, state="pending")


# -- judging from where the robot stands ------------------------------------------------------------
CAMERA = (0.88, math.radians(63.0))
TOP = np.array([5.0, 5.0, 0.8])  # the object's top half, near the camera's height
RING = view.view_ring(S, float(TOP[2]), CAMERA)  # 1.15 m


def _here(xy, *, grid=None, hiding=None, excluded=(), center=TOP, ring=RING) -> bool:
    xy = np.asarray(xy, dtype=np.float64)
    gap = view.box_distance(LO, HI, xy)
    sight = view.sight(center, CAMERA, hiding)
    return view.views_from_here(S, xy, gap, ring, center, CAMERA, sight, grid if grid is not None else room(),
                                [(LO, HI)], None, excluded)


def test_a_robot_inside_the_view_ring_with_the_object_in_sight_judges_it_from_where_it_stands():
    assert _here([5.0, 6.3])  # 0.8 m north of the footprint
    assert not _here([5.0, 7.0])  # 1.5 m: beyond the ring, it drives to a view cell
    assert not _here([5.0, 5.6])  # 0.1 m: the robot's body overlaps the object
    assert not _here([5.0, 6.3], center=CENTRE)  # a low centre drops out of the bottom of the image


def test_a_robot_too_near_a_high_object_to_hold_it_in_view_does_not_judge_from_there():
    tv = np.array([5.0, 5.0, 1.9])  # high on a wall: out of the top of the image from 0.8 m
    ring = view.view_ring(S, 1.9, CAMERA)
    assert view.nearest_view(S, 1.9, CAMERA) > 0.8
    assert not _here([5.0, 6.3], center=tv, ring=ring)
    assert not _here([5.0, 5.5 + ring - 0.05], center=tv, ring=ring)
    assert _here([5.0, 5.5 + ring + 0.05], center=tv, ring=ring + 0.1)


def test_a_robot_behind_a_chair_a_wall_or_on_a_spot_set_aside_goes_to_a_view_cell():
    chair = (np.array([[4.7, 5.7, 0.0]]), np.array([[5.3, 6.0, 1.0]]))  # between the robot and the object
    assert not _here([5.0, 6.3], hiding=chair)
    walled = room()
    walled.state[58, 40:60] = 1  # a wall 0.3 m north of the footprint, between it and the robot
    assert not _here([5.0, 6.3], grid=walled)
    assert not _here([5.0, 6.3], excluded=[np.array([5.1, 6.2])])
    assert _here([5.0, 6.3], excluded=[np.array([5.0, 7.0])])
