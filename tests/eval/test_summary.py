"""Summary math (paper's SR / SPL equation, DTS, failures, paired ablation deltas) on hand-made records."""

from __future__ import annotations

import math

import pytest

from hiconav.eval.records import EpisodeRecord
from hiconav.eval.summary import semexp_code_spl, spl_value, summarize


def rec(i: int, preset: str = "full", **kw) -> EpisodeRecord:
    kw.setdefault("failure", "success" if kw.get("success") else "step_out")
    return EpisodeRecord(episode_id=f"e{i}", house="h", target=kw.pop("target", "bed"), preset=preset, **kw)


def test_spl_value_is_success_times_shortest_over_longer_path() -> None:
    assert spl_value(True, 4.0, 8.0) == pytest.approx(0.5)
    assert spl_value(True, 4.0, 2.0) == pytest.approx(1.0)  # max(l_s, l_a) caps it at 1
    assert spl_value(False, 4.0, 4.0) == 0.0
    assert spl_value(True, 0.0, 0.0) == 1.0


def test_semexp_code_spl_adds_the_success_distance_to_the_shortest_path() -> None:
    """SemExp's objectgoal_env: min(S * (fmm distance to the region + object_boundary) / path, 1)."""
    assert semexp_code_spl(True, 4.0, 1.0, 10.0) == pytest.approx(0.5)
    assert spl_value(True, 4.0, 10.0) == pytest.approx(0.4)  # ours, Habitat's l^s, on the same episode
    assert semexp_code_spl(True, 4.0, 1.0, 4.5) == 1.0  # capped
    assert semexp_code_spl(False, 4.0, 1.0, 10.0) == 0.0


def test_semexp_code_spl_is_summarised_apart_and_only_over_the_records_that_carry_it() -> None:
    records = [rec(0, success=True, spl=0.4, extra={"spl_semexp": 0.5}),
               rec(1, success=False, spl=0.0, extra={"spl_semexp": 0.0}),
               rec(2, success=True, spl=1.0)]  # a ProcTHOR-rule house: no SemExp figure
    s = summarize(records)
    assert s["spl"] == pytest.approx(1.4 / 3)
    assert s["spl_semexp_code"] == pytest.approx(0.25) and s["spl_semexp_code_episodes"] == 2
    none = summarize([rec(0, success=True, spl=1.0)])
    assert none["spl_semexp_code"] is None and none["spl_semexp_code_episodes"] == 0


def test_sr_spl_dts_are_means_over_valid_episodes() -> None:
    records = [
        rec(0, success=True, spl=spl_value(True, 5.0, 10.0), dts=0.0, target="bed"),
        rec(1, success=True, spl=spl_value(True, 3.0, 3.0), dts=0.0, target="tv"),
        rec(2, success=False, spl=0.0, dts=2.5, failure="false_positive", target="tv"),
        rec(3, success=False, spl=0.0, dts=math.inf, failure="no_frontier"),  # unknown DTS
        rec(4, success=False, failure="invalid_episode", error="start not navigable", error_kind="data"),
    ]
    s = summarize(records)
    assert s["episodes"] == 5 and s["valid_episodes"] == 4
    assert s["success_rate"] == pytest.approx(2 / 4)
    assert s["spl"] == pytest.approx((0.5 + 1.0) / 4)
    assert s["dts"] == pytest.approx((0.0 + 0.0 + 2.5) / 3)
    assert s["dts_unknown"] == 1
    assert s["failures"]["success"] == 2 and s["failures"]["false_positive"] == 1
    assert s["failures"]["no_frontier"] == 1 and s["failures"]["invalid_episode"] == 1
    assert s["failures"]["stuck"] == 0
    assert s["by_target"]["tv"] == {"episodes": 2, "success_rate": 0.5, "spl": 0.5}


def test_timing_is_seconds_per_frame_per_layer_and_step_speed() -> None:
    records = [rec(0, success=True, spl=1.0, task_time_s=10.0, path_length=5.0, wall_time_s=2.0,
                   layer_time_s={"fast": 1.0, "reasoning": 4.0}, layer_frames={"fast": 100, "reasoning": 2}),
               rec(1, task_time_s=30.0, path_length=10.0, wall_time_s=4.0, vlm_calls=3,
                   layer_time_s={"fast": 2.0}, layer_frames={"fast": 100})]
    timing = summarize(records)["timing"]
    assert timing["layers"]["fast"]["seconds_per_frame"] == pytest.approx(3.0 / 200)
    assert timing["layers"]["reasoning"]["seconds_per_frame"] == pytest.approx(2.0)
    assert timing["task_time_s_mean"] == pytest.approx(20.0)
    assert timing["step_speed_m_per_s"] == pytest.approx(15.0 / 40.0)
    assert timing["wall_time_s_total"] == pytest.approx(6.0)
    assert timing["vlm_calls_mean"] == pytest.approx(1.5)


def test_ablation_deltas_are_paired_on_common_episodes_with_sign() -> None:
    records = [rec(0, success=True, spl=0.8), rec(1, success=True, spl=0.6), rec(2, success=False),
               rec(0, "no_vis", success=True, spl=0.4), rec(1, "no_vis", success=False),
               rec(5, "no_vis", success=True, spl=1.0)]  # e5 has no full run: not paired
    s = summarize(records)
    assert s["preset"] == "full" and set(s["presets"]) == {"full", "no_vis"}
    delta = s["ablations"]["no_vis"]
    assert delta["paired_episodes"] == 2
    assert delta["delta_success_rate"] == pytest.approx(-0.5)
    assert delta["delta_spl"] == pytest.approx(((0.4 - 0.8) + (0.0 - 0.6)) / 2)
    assert s["success_rate"] == pytest.approx(2 / 3)  # top level = the full preset


def test_actions_split_counts_the_turns_in_place_of_the_records_that_count_them() -> None:
    records = [
        rec(0, success=True, spl=0.5, steps=100, extra={"turns": 40}),
        rec(1, success=False, spl=0.0, steps=500, extra={"turns": 260}),
        rec(2, success=True, spl=1.0, steps=30),  # an older record: no such field
    ]
    a = summarize(records)["actions"]
    assert a == {"episodes_measured": 2, "actions": 600, "turns": 300, "turn_share": 0.5, "by_behaviour": {}}
    assert summarize([rec(3, success=True, spl=1.0, steps=30)])["actions"]["turn_share"] is None


def test_path_split_counts_the_successes_path_before_and_after_the_goal_came_in_view() -> None:
    view = lambda path, to_success: {"goal_in_view": {"steps": 10, "path_m": path, "to_success_m": to_success}}  # noqa: E731
    records = [
        rec(0, success=True, spl=0.5, path_length=10.0, extra={"shortest_to_success": 5.0, **view(6.0, 2.0)}),
        rec(1, success=True, spl=1.0, path_length=3.0, extra={"shortest_to_success": 3.0, **view(0.0, 3.0)}),
        rec(2, success=True, spl=1.0, path_length=3.0),  # an older record: no such field
        rec(3, success=False, spl=0.0, path_length=40.0, extra={"goal_in_view": None}),
        rec(4, success=False, spl=0.0, path_length=40.0, extra=view(30.0, 4.0)),
    ]
    p = summarize(records)["path"]
    assert p["successes_measured"] == 2 and p["failures_measured"] == 2 and p["failures_never_in_view"] == 1
    assert p["driven_m"] == pytest.approx(13.0) and p["shortest_m"] == pytest.approx(8.0)
    assert p["before_view_m"] == pytest.approx(6.0) and p["before_view_share"] == pytest.approx(6.0 / 13.0)
    assert p["after_view_m"] == pytest.approx(7.0) and p["after_view_shortest_m"] == pytest.approx(5.0)


def test_actions_split_by_the_behaviour_whose_goal_they_served() -> None:
    records = [
        rec(0, success=True, spl=0.5, steps=31, extra={"turns": 12, "actions_by_behaviour": {
            "Explore": {"turns": 10, "forward": 10, "other": 0}, "Approach": {"turns": 2, "forward": 8, "other": 0}}}),
        rec(1, success=False, spl=0.0, steps=10, extra={"turns": 6, "actions_by_behaviour": {
            "Explore": {"turns": 6, "forward": 4, "other": 0}}}),
        rec(2, success=True, spl=1.0, steps=9, extra={"turns": 3, "actions_by_behaviour": None}),  # velocity control
    ]
    by = summarize(records)["actions"]["by_behaviour"]
    assert list(by) == ["Explore", "Approach"]  # most actions first
    assert by["Explore"] == {"actions": 30, "turns": 16, "share": 0.75}
    assert by["Approach"] == {"actions": 10, "turns": 2, "share": 0.25}


def test_excess_split_sums_the_successes_path_beyond_the_shortest_by_behaviour() -> None:
    ex = lambda by, inside: {"excess_path": {"by_behaviour": by, "inside_m": inside, "unmeasured_m": 0.0}}  # noqa: E731
    records = [
        rec(0, success=True, spl=0.5, path_length=10.0, extra=ex({"Explore": 4.0, "Approach": 1.0}, 0.5)),
        rec(1, success=True, spl=0.8, path_length=5.0, extra=ex({"VerifyTarget": 3.0, "Explore": 2.0}, 0.25)),
        rec(2, success=False, spl=0.0, path_length=40.0, extra=ex({"Explore": 30.0}, 0.0)),  # a failure: left out
        rec(3, success=True, spl=1.0, path_length=3.0),  # an older record: no such field
    ]
    e = summarize(records)["path"]["excess"]
    assert e["successes_measured"] == 2 and e["excess_m"] == pytest.approx(10.0) and e["inside_m"] == pytest.approx(0.75)
    assert list(e["by_behaviour"]) == ["Explore", "VerifyTarget", "Approach"]  # most first
    assert e["by_behaviour"]["Explore"] == {"m": pytest.approx(6.0), "share": pytest.approx(0.6)}
    assert summarize([records[3]])["path"]["excess"] == {"successes_measured": 0, "excess_m": 0.0, "inside_m": 0.0,
                                                          "by_behaviour": {}}
