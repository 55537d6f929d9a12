"""Frontier following (hiconav.decisions.frontiers): small hand-built plans, poses and clocks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiconav.decisions.config import DecisionsConfig, ExploreSettings
from hiconav.decisions.frontiers import (ExploreLedger, FrontierFollower, PlanView, facing_yaw, look_goal,
                                         near_any, pick_frontier, pick_squeeze, push_goal, settle_reached,
                                         start_look_step)
from hiconav.types import Frontier, Pose2D

# the clocks below are the simulator's stepped clock, where a second of clock is five of robot time
# (one 0.1 s driver tick carries a 0.5 s discrete action): the settings' durations on that clock
STEPPED = 0.2
S = DecisionsConfig(explore=ExploreSettings()).in_clock(STEPPED).explore
NO_START = DecisionsConfig(explore=ExploreSettings(start_look_turns=0)).in_clock(STEPPED).explore


def _frontier(fid: int, viewpoint: tuple[float, float], centroid: tuple[float, float]) -> Frontier:
    return Frontier(fid, np.array(centroid, dtype=np.float64), np.array(viewpoint, dtype=np.float64), 10)


def _plan(*frontiers: Frontier, order: tuple[int, ...] | None = None, goal_id: int | None = None,
          stamp: float = 0.0) -> PlanView:
    return PlanView(tuple(frontiers), tuple(f.id for f in frontiers) if order is None else order, goal_id, stamp)


def _ledger(**kw) -> ExploreLedger:
    return ExploreLedger(kw.pop("last_frontier_time", 0.0), kw.pop("start_looks", 0), None, 0, **kw)


def test_a_spot_within_the_radius_of_a_visited_one_counts_as_visited():
    assert near_any(np.array([1.0, 1.0]), [(1.3, 1.0)], 0.4)
    assert not near_any(np.array([1.0, 1.0]), [(1.5, 1.0)], 0.4)
    assert not near_any(np.array([1.0, 1.0]), [], 0.4)


def test_a_viewpoint_faces_its_frontier_unless_it_stands_on_it():
    assert facing_yaw(np.array([0.0, 0.0]), np.array([0.0, 2.0])) == pytest.approx(math.pi / 2)
    assert facing_yaw(np.array([0.0, 0.0]), np.array([0.1, 0.1])) is None


def test_the_first_frontier_of_the_order_not_visited_is_picked():
    plan = _plan(_frontier(0, (1, 0), (2, 0)), _frontier(1, (0, 1), (0, 2)), order=(1, 0))
    fid, xy, yaw, push = pick_frontier(plan, set(), None, _ledger(), S)
    assert (fid, push) == (1, False) and list(xy) == [0, 1] and yaw == pytest.approx(math.pi / 2)
    assert pick_frontier(plan, {1}, None, _ledger(), S)[0] == 0
    assert pick_frontier(plan, {0, 1}, None, _ledger(), S) is None


def test_the_plans_goal_frontier_comes_first_when_the_order_lacks_it():
    plan = _plan(_frontier(0, (1, 0), (2, 0)), _frontier(1, (0, 1), (0, 2)), order=(0,), goal_id=1)
    assert pick_frontier(plan, set(), None, _ledger(), S)[0] == 1


def test_a_frontier_seen_from_a_spent_viewpoint_far_from_the_robot_is_skipped():
    plan = _plan(_frontier(0, (5, 0), (6, 0)), _frontier(1, (0, 1), (0, 2)))
    ledger = _ledger(spent_viewpoints=[(5.1, 0.0)])
    assert pick_frontier(plan, set(), Pose2D(0.0, 0.0, 0.0), ledger, S)[0] == 1
    assert ledger.pushed_frontiers == []


def test_a_spent_frontier_beside_the_robot_is_pushed_into_once_beyond_its_centroid():
    plan = _plan(_frontier(0, (0.5, 0), (1, 0)))
    ledger = _ledger(spent_viewpoints=[(0.5, 0.0)])
    fid, xy, yaw, push = pick_frontier(plan, set(), Pose2D(0.0, 0.0, 0.0), ledger, S)
    assert (fid, push) == (0, True) and yaw == pytest.approx(0.0)
    assert xy == pytest.approx([1.0 + S.push_m, 0.0])
    assert ledger.pushed_frontiers == [(1.0, 0.0)]
    assert pick_frontier(plan, set(), Pose2D(0.0, 0.0, 0.0), ledger, S) is None  # pushed before


def test_no_push_when_pushing_is_off_or_the_centroid_is_beyond_the_push_radius():
    robot = Pose2D(0.0, 0.0, 0.0)
    assert push_goal(np.array([1.0, 0.0]), robot, [], ExploreSettings(push_through=False)) is None
    assert push_goal(np.array([S.push_radius + 0.1, 0.0]), robot, [], S) is None
    assert push_goal(np.array([1.0, 0.0]), None, [], S) is None


def test_a_push_into_a_centroid_under_the_robot_keeps_the_robots_heading():
    goal, yaw = push_goal(np.array([0.05, 0.0]), Pose2D(0.0, 0.0, 1.0), [], S)
    assert yaw == 1.0 and goal == pytest.approx([0.05 + S.push_m * math.cos(1.0), S.push_m * math.sin(1.0)])


def test_a_reached_viewpoint_still_showing_a_frontier_on_a_later_plan_is_spent():
    reached = [(np.array([1.0, 1.0]), 2.0)]
    spent: list = []
    waiting, new = settle_reached(reached, _plan(_frontier(7, (1.1, 1.0), (2, 1)), stamp=3.0), spent, S)
    assert waiting == [] and new == [(1.0, 1.0)] and spent == [(1.0, 1.0)]


def test_a_reached_viewpoint_waits_for_a_plan_made_spent_after_s_after_the_visit():
    reached = [(np.array([1.0, 1.0]), 2.0)]
    waiting, new = settle_reached(reached, _plan(_frontier(7, (1.0, 1.0), (2, 1)), stamp=2.1), [], S)
    assert len(waiting) == 1 and new == []


def test_a_robot_standing_idle_judges_its_reached_viewpoint_on_the_plan_of_its_newest_frame():
    """A robot whose frames come only with its actions gets no newer plan while it waits: the plan
    made from its newest frame judges the visit once spent_after_s have passed."""
    reached = [(np.array([1.0, 1.0]), 2.0)]
    stale = PlanView((_frontier(7, (1.0, 1.0), (2, 1)),), (7,), None, 1.5, newest=True)
    # a goal in flight, or too soon after the visit, or a frame newer than the plan: it waits
    assert len(settle_reached(reached, stale, [], S, 3.0, idle=False)[0]) == 1
    assert len(settle_reached(reached, stale, [], S, 2.2, idle=True)[0]) == 1
    older = PlanView(stale.frontiers, stale.order, None, 1.5, newest=False)
    assert len(settle_reached(reached, older, [], S, 3.0, idle=True)[0]) == 1
    spent: list = []
    waiting, new = settle_reached(reached, stale, spent, S, 3.0, idle=True)
    assert waiting == [] and new == [(1.0, 1.0)] and spent == [(1.0, 1.0)]


def test_a_plan_is_the_newest_when_made_from_the_newest_world_snapshot():
    from types import SimpleNamespace

    msg = SimpleNamespace(plan=SimpleNamespace(order=(1,), goal=None), frontiers=(), stamp=4.0, snapshot_seq=12)
    assert PlanView.of(msg, 12).newest and not PlanView.of(msg, 13).newest and not PlanView.of(msg).newest


def test_explored_out_the_robot_goes_back_to_push_through_a_spent_frontier_it_never_pushed_into():
    """A doorway whose viewpoint was reached without clearing it, left for another frontier while
    the robot was near it: with nothing else left, the robot pushes through it from afar."""
    plan = _plan(_frontier(4, (5.0, 0.0), (6.0, 0.0)))
    ledger = _ledger(spent_viewpoints=[(5.0, 0.0)])
    pose = Pose2D(0.0, 0.0, 0.0)
    assert pick_frontier(plan, set(), pose, ledger, S) is None  # beyond push_radius: skipped
    fid, xy, yaw = pick_squeeze(plan, ledger, S, pose)
    assert fid == 4 and xy.tolist() == pytest.approx([6.0 + S.push_m, 0.0]) and yaw == pytest.approx(0.0)
    assert ledger.pushed_frontiers == [(6.0, 0.0)] and ledger.squeezed_frontiers == [(6.0, 0.0)]
    assert pick_squeeze(plan, ledger, S, pose) is None  # once per centroid
    # one pushed into before, or pushing off, or no pose: nothing to go back to
    assert pick_squeeze(plan, _ledger(spent_viewpoints=[(5.0, 0.0)], pushed_frontiers=[(6.0, 0.0)]), S, pose) is None
    assert pick_squeeze(plan, _ledger(spent_viewpoints=[(5.0, 0.0)]), ExploreSettings(push_through=False),
                        pose) is None
    assert pick_squeeze(plan, _ledger(spent_viewpoints=[(5.0, 0.0)]), S) is None
    # the follower sends it as a squeeze through unknown floor before it idles
    f, ledger = FrontierFollower(), _ledger(spent_viewpoints=[(5.0, 0.0)])
    step = f.step(None, pose, 1.0, plan, ledger, (), NO_START)
    assert step.goal.kind == "squeeze" and step.goal.frontier == 4 and step.goal.through_unknown


def test_a_reached_viewpoint_whose_frontier_cleared_is_forgotten_not_spent():
    reached = [(np.array([1.0, 1.0]), 2.0)]
    waiting, new = settle_reached(reached, _plan(_frontier(7, (4.0, 1.0), (5, 1)), stamp=3.0), [], S)
    assert waiting == [] and new == []


def test_a_failed_frontier_is_squeezed_toward_once_per_centroid():
    plan = _plan(_frontier(0, (1, 0), (2, 0)), _frontier(1, (0, 1), (0, 2)))
    ledger = _ledger(failed_frontiers={1})
    fid, xy, yaw = pick_squeeze(plan, ledger, S)
    assert fid == 1 and list(xy) == [0, 1] and ledger.squeezed_frontiers == [(0.0, 2.0)]
    assert pick_squeeze(plan, ledger, S) is None
    assert pick_squeeze(plan, _ledger(failed_frontiers={1}), ExploreSettings(squeeze=False)) is None


def test_frontiers_the_planner_found_no_path_to_are_squeezed_toward_after_the_failed_ones():
    """A doorway seen from across the room: the wedge of floor seen through it is tight at the
    doorway, its frontiers have no path on the lethal layer and are left out of the order."""
    plan = PlanView((_frontier(0, (1, 0), (2, 0)), _frontier(2, (3, -2), (3, -3)), _frontier(3, (4, -2), (4, -3))),
                    (0,), None, 0.0, dropped=(3, 2))
    ledger = _ledger(failed_frontiers={0})
    assert pick_squeeze(plan, ledger, S)[0] == 0
    assert pick_squeeze(plan, ledger, S)[0] == 3
    assert pick_squeeze(plan, ledger, S)[0] == 2
    assert pick_squeeze(plan, ledger, S) is None
    # a dropped frontier without a viewpoint is not a goal
    bare = Frontier(5, np.array([1.0, 1.0]), np.full(2, np.nan), 10)
    assert pick_squeeze(PlanView((bare,), (), None, 0.0, dropped=(5,)), _ledger(), S) is None


def test_an_explored_out_search_squeezes_toward_a_dropped_frontier_before_it_idles():
    f, ledger = FrontierFollower(), _ledger(start_looks=0, last_frontier_time=0.0)
    plan = PlanView((_frontier(2, (3, -2), (3, -3)),), (), None, 0.0, dropped=(2,))
    step = f.step(None, Pose2D(0.0, 0.0, 0.0), 1.0, plan, ledger, (), NO_START)
    assert step.goal is not None and step.goal.kind == "squeeze" and step.goal.frontier == 2


def test_the_start_is_looked_around_in_quarter_turns_before_any_frontier():
    f, ledger = FrontierFollower(), _ledger(start_looks=0)
    plan = _plan(_frontier(0, (1, 0), (2, 0)))
    step = f.step(None, Pose2D(0.0, 0.0, 0.0), 1.0, plan, ledger, {}, ExploreSettings(start_look_turns=1))
    assert step.goal.kind == "look" and step.goal.yaw == pytest.approx(math.pi / 2)
    assert step.feedback == "looking around the start (0/1)" and ledger.last_frontier_time == 1.0
    step = f.step("reached", Pose2D(0.0, 0.0, math.pi / 2), 2.0, plan, ledger, {}, ExploreSettings(start_look_turns=1))
    assert ledger.start_looks == 1 and step.ended and step.goal.kind == "frontier" and step.goal.frontier == 0


def test_a_frontier_goal_is_not_resent_while_its_viewpoint_stays_put():
    f, ledger = FrontierFollower(), _ledger()
    plan = _plan(_frontier(0, (3, 0), (4, 0)))
    first = f.step(None, Pose2D(0.0, 0.0, 0.0), 1.0, plan, ledger, {}, NO_START)
    again = f.step("active", Pose2D(0.1, 0.0, 0.0), 1.5, plan, ledger, {}, NO_START)
    assert first.goal is not None and first.goal.tolerance == S.goal_tolerance and again.goal is None
    moved = _plan(_frontier(0, (3, 1), (4, 1)))
    assert f.step("active", Pose2D(0.2, 0.0, 0.0), 2.0, moved, ledger, {}, NO_START).goal is not None


def test_a_frontier_goal_without_progress_for_stall_s_is_skipped_and_fails_for_the_mission():
    f, ledger = FrontierFollower(), _ledger()
    plan = _plan(_frontier(0, (3, 0), (4, 0)), _frontier(1, (0, 3), (0, 4)))
    f.step(None, Pose2D(0.0, 0.0, 0.0), 0.0, plan, ledger, {}, NO_START)
    f.step("active", Pose2D(0.0, 0.0, 0.0), 1.0, plan, ledger, {}, NO_START)
    step = f.step("active", Pose2D(0.0, 0.0, 0.0), 1.0 + S.stall_s + 0.5, plan, ledger, {}, NO_START)
    assert step.log == ("frontier #0: no progress for 8 s, skipped",)
    assert step.ended and ledger.failed_frontiers == {0} and step.goal.frontier == 1


def test_re_picking_a_failed_frontier_does_not_reset_the_idle_clock():
    f, ledger = FrontierFollower(), _ledger(last_frontier_time=0.0, failed_frontiers={0})
    f.step(None, Pose2D(0.0, 0.0, 0.0), 5.0, _plan(_frontier(0, (3, 0), (4, 0))), ledger, {}, NO_START)
    assert ledger.last_frontier_time == 0.0


def test_with_no_frontier_the_robot_looks_around_then_fails_after_max_idle_s():
    f, ledger = FrontierFollower(), _ledger(last_frontier_time=0.0)
    s = ExploreSettings(start_look_turns=0, look_turns=1)
    step = f.step(None, Pose2D(0.0, 0.0, 0.0), 1.0, _plan(), ledger, {}, s)
    assert step.goal.kind == "look" and ledger.looks_here == 1 and step.feedback == "looking around"
    step = f.step("reached", Pose2D(0.0, 0.0, 0.0), 2.0, _plan(), ledger, {}, s)
    assert step.goal is None and step.feedback == "waiting for a frontier"  # turns per spot spent
    step = f.step(None, Pose2D(0.0, 0.0, 0.0), 1.0 + s.max_idle_s + 1.0, _plan(), ledger, {}, s)
    assert step.status == "failure" and step.feedback == "no frontier left"


def test_explored_out_with_deferred_candidates_makes_them_due_instead_of_failing():
    f, ledger = FrontierFollower(), _ledger(last_frontier_time=0.0)
    step = f.step(None, Pose2D(0.0, 0.0, 0.0), 100.0, _plan(), ledger, {5: 130.0, 2: 120.0}, NO_START)
    assert step.status == "running" and step.release_deferred and ledger.last_frontier_time == 100.0
    assert step.log == ("no frontier left: deferred candidates [2, 5] are due now",)


def test_a_look_is_a_quarter_turn_left_in_place():
    goal = look_goal(Pose2D(1.0, 2.0, math.pi))
    assert (goal.kind, goal.x, goal.y, goal.frontier) == ("look", 1.0, 2.0, None)
    assert goal.yaw == pytest.approx(-math.pi / 2)


def test_explored_out_asks_for_the_best_unresolved_candidate_while_asks_are_left():
    f, ledger = FrontierFollower(), _ledger(last_frontier_time=0.0)
    ledger.unresolved_asks_left = 1
    step = f.step(None, Pose2D(0.0, 0.0, 0.0), 100.0, _plan(), ledger, {}, NO_START)
    assert step.status == "running" and step.ask_unresolved and ledger.last_frontier_time == 100.0
    assert ledger.unresolved_asks_left == 0
    # one more idle period without an answer that ended the search: the search fails
    step = f.step(None, Pose2D(0.0, 0.0, 0.0), 100.0 + NO_START.max_idle_s + 1.0, _plan(), ledger, {}, NO_START)
    assert step.status == "failure" and not step.ask_unresolved
    # deferred candidates go first: they are the mission's own
    ledger = _ledger(last_frontier_time=0.0)
    ledger.unresolved_asks_left = 1
    step = f.step(None, Pose2D(0.0, 0.0, 0.0), 100.0, _plan(), ledger, {5: 130.0}, NO_START)
    assert step.release_deferred and not step.ask_unresolved and ledger.unresolved_asks_left == 1


def test_explored_out_with_nothing_deferred_or_to_ask_the_last_resort_comes_once_before_failing():
    f, ledger = FrontierFollower(), _ledger(last_frontier_time=0.0, last_resort_left=1)
    step = f.step(None, Pose2D(0.0, 0.0, 0.0), 100.0, _plan(), ledger, {}, NO_START)
    assert step.status == "running" and step.last_resort and ledger.last_resort_left == 0
    assert step.log == ("no frontier left: taking back the best candidate set aside as out of reach",)
    step = f.step(None, Pose2D(0.0, 0.0, 0.0), 100.0 + NO_START.max_idle_s + 1.0, _plan(), ledger, {}, NO_START)
    assert step.status == "failure" and not step.last_resort
    # after the deferred candidates and the reasoning layer's unresolved ones; never when turned off
    ledger = _ledger(last_frontier_time=0.0, last_resort_left=1, unresolved_asks_left=1)
    assert f.step(None, Pose2D(0.0, 0.0, 0.0), 100.0, _plan(), ledger, {5: 130.0}, NO_START).release_deferred
    assert f.step(None, Pose2D(0.0, 0.0, 0.0), 200.0, _plan(), ledger, {}, NO_START).ask_unresolved
    off = ExploreSettings(start_look_turns=0, last_resort=False)
    assert f.step(None, Pose2D(0.0, 0.0, 0.0), 300.0, _plan(), ledger, {}, off).status == "failure"
    assert f.step(None, Pose2D(0.0, 0.0, 0.0), 300.0, _plan(), ledger, {}, NO_START).last_resort


def test_the_start_look_as_a_step_of_its_own_counts_each_ended_quarter_turn():
    s = ExploreSettings(start_look_turns=2)
    pose = Pose2D(1.0, 2.0, 0.0)
    looks, goal, done = start_look_step(None, pose, 0, s)
    assert (looks, done) == (0, False) and goal.kind == "look" and goal.yaw == pytest.approx(math.pi / 2)
    assert start_look_step("following", pose, 0, s) == (0, None, False)  # in flight: nothing new
    looks, goal, done = start_look_step("reached", Pose2D(1.0, 2.0, math.pi / 2), 0, s)
    assert (looks, done) == (1, False) and math.cos(goal.yaw) == pytest.approx(-1.0)
    assert start_look_step("failed", pose, 1, s) == (2, None, True)  # a turn that failed counts as made
    assert start_look_step(None, None, 0, s) == (0, None, False)  # no pose yet
    assert start_look_step(None, pose, 0, ExploreSettings(start_look_turns=0)) == (0, None, True)
