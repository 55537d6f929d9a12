"""Failure taxonomy (docs/evaluation.md) on hand-made traces: one category per test."""

from __future__ import annotations

import numpy as np

from hiconav.eval.taxonomy import CATEGORIES, Failure, classify, last_progress_step


def trace(**fields):
    base = {"success": False, "termination": "step_limit", "steps": 500, "max_steps": 500,
            "last_progress_step": 499, "error": None}
    base.update(fields)
    return base


def test_success_wins_over_every_other_field() -> None:
    assert classify(trace(success=True, termination="stop", last_progress_step=0)) is Failure.SUCCESS


def test_stop_away_from_goal_is_false_positive() -> None:
    assert classify(trace(termination="stop", steps=120)) is Failure.FALSE_POSITIVE


def test_no_frontier_left() -> None:
    assert classify(trace(termination="no_frontier", steps=300, last_progress_step=100)) is Failure.NO_FRONTIER


def test_step_limit_while_moving_is_step_out() -> None:
    assert classify(trace(termination="step_limit", steps=500, last_progress_step=490)) is Failure.STEP_OUT


def test_step_limit_without_progress_for_the_window_is_stuck() -> None:
    assert classify(trace(steps=500, last_progress_step=450), stuck_window=50) is Failure.STUCK
    assert classify(trace(steps=500, last_progress_step=451), stuck_window=50) is Failure.STEP_OUT


def test_runner_reported_stuck() -> None:
    assert classify(trace(termination="stuck", steps=80, last_progress_step=None)) is Failure.STUCK


def test_bad_input_is_invalid_episode_and_crash_is_error() -> None:
    assert classify(trace(error="start not navigable", error_kind="data")) is Failure.INVALID_EPISODE
    assert classify(trace(error="ZeroDivisionError", error_kind="runtime")) is Failure.ERROR


def test_unknown_termination_is_an_error_not_a_silent_step_out() -> None:
    assert classify(trace(termination="teleported", steps=10, last_progress_step=9)) is Failure.ERROR


def test_last_progress_step_finds_when_the_robot_stopped_moving() -> None:
    walk = np.stack([np.arange(10) * 0.25, np.zeros(10)], axis=1)  # 9 steps forward
    parked = np.repeat(walk[-1:], 20, axis=0) + np.random.default_rng(0).normal(0, 0.01, (20, 2))
    positions = np.concatenate([walk, parked])
    # x = 1.5 (index 6) is 0.75 m from the parking spot, x = 1.75 (index 7) only 0.5 m
    assert last_progress_step(positions, radius=0.6) == 6
    assert last_progress_step(positions[:8], radius=0.6) == 7 - 3  # x = 1.0 is the last > 0.6 m from 1.75
    assert last_progress_step(np.zeros((5, 2))) == 0


def test_categories_are_listed_in_display_order() -> None:
    assert CATEGORIES[:5] == ("success", "false_positive", "no_frontier", "stuck", "step_out")
