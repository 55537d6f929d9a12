"""How sure a figure is: SR / SPL intervals, the sign test and the paired comparison of two runs."""

from __future__ import annotations

import json

import pytest

from hiconav.eval.compare import main as compare_main
from hiconav.eval.records import EpisodeRecord, dumps
from hiconav.eval.stats import bootstrap_interval, paired_comparison, sign_test_p, wilson_interval
from hiconav.eval.summary import summarize


def rec(i: int, success: bool, spl: float = 0.0, preset: str = "full", seed: int = 7, **kw) -> EpisodeRecord:
    return EpisodeRecord(episode_id=f"e{i}", house="h", target="bed", preset=preset, seed=seed, success=success,
                         spl=spl, failure="success" if success else kw.pop("failure", "step_out"), **kw)


def test_wilson_interval_matches_the_textbook_values() -> None:
    lo, hi = wilson_interval(5, 10)
    assert lo == pytest.approx(0.2366, abs=1e-4) and hi == pytest.approx(0.7634, abs=1e-4)
    lo, hi = wilson_interval(0, 10)
    assert lo == 0.0 and hi == pytest.approx(0.2775, abs=1e-4)  # never a zero-width interval at 0%
    assert wilson_interval(10, 10)[1] == pytest.approx(1.0) and wilson_interval(0, 0) is None
    with pytest.raises(ValueError):
        wilson_interval(11, 10)


def test_bootstrap_interval_is_seeded_and_holds_the_mean() -> None:
    values = [0.0, 0.2, 0.9, 0.4, 0.0, 0.7, 0.55, 0.1]
    a, b = bootstrap_interval(values), bootstrap_interval(values)
    assert a == b and a[0] < sum(values) / len(values) < a[1]
    assert bootstrap_interval([0.5] * 5) == (0.5, 0.5) and bootstrap_interval([]) is None
    with pytest.raises(ValueError):
        bootstrap_interval([0.1, float("nan")])


def test_sign_test_p_is_the_exact_two_sided_binomial() -> None:
    assert sign_test_p(0, 0) == 1.0 and sign_test_p(3, 3) == 1.0
    assert sign_test_p(5, 0) == pytest.approx(2 / 32) and sign_test_p(0, 5) == pytest.approx(2 / 32)
    assert sign_test_p(4, 1) == pytest.approx(0.375)
    assert sign_test_p(10, 0) == pytest.approx(2 / 1024)


def test_paired_comparison_counts_the_episodes_that_turned_each_way() -> None:
    before = [rec(0, True, 0.5), rec(1, False), rec(2, True, 0.4), rec(3, False), rec(4, True, 0.9),
              rec(5, False, failure="invalid_episode")]
    after = [rec(0, True, 0.6), rec(1, True, 0.3), rec(2, False), rec(3, True, 0.2), rec(4, True, 0.9, seed=8),
             rec(6, True, 1.0)]
    c = paired_comparison(before, after)
    assert c["paired"] == 5 and c["only_before"] == 0 and c["only_after"] == 1 and c["same_seed"] == 4
    assert (c["up"], c["down"]) == (2, 1) and c["up_ids"] == ["e1", "e3"] and c["down_ids"] == ["e2"]
    assert c["before"]["sr"] == pytest.approx(3 / 5) and c["after"]["sr"] == pytest.approx(4 / 5)
    assert c["delta_sr"] == pytest.approx(1 / 5) and c["sign_test_p"] == pytest.approx(1.0)
    assert c["delta_spl"] == pytest.approx((0.1 + 0.3 - 0.4 + 0.2 + 0.0) / 5)
    lo, hi = c["delta_spl_ci95"]
    assert lo <= c["delta_spl"] <= hi


def test_the_summary_carries_intervals_and_the_ablations_their_sign_test() -> None:
    records = [rec(i, i % 2 == 0, 0.5 if i % 2 == 0 else 0.0) for i in range(10)]
    records += [rec(i, i < 2, 0.5 if i < 2 else 0.0, preset="no_vis") for i in range(10)]
    s = summarize(records)
    assert s["success_rate_ci95"] == pytest.approx(list(wilson_interval(5, 10)))
    assert s["spl_ci95"][0] < s["spl"] < s["spl_ci95"][1]
    delta = s["ablations"]["no_vis"]
    assert (delta["up"], delta["down"]) == (1, 4) and delta["sign_test_p"] == pytest.approx(0.375)
    json.dumps(s, allow_nan=False)  # summary.json stays strict JSON


def _write(folder, records) -> None:
    folder.mkdir()
    (folder / "episodes.jsonl").write_text("".join(dumps(r) + "\n" for r in records), encoding="utf-8")


def test_compare_prints_the_changed_episodes_and_ends_with_a_json_line(tmp_path, capsys) -> None:
    _write(tmp_path / "a", [rec(i, i != 3, 0.4 if i != 3 else 0.0) for i in range(6)])
    _write(tmp_path / "b", [rec(i, i not in (1, 2), 0.5 if i not in (1, 2) else 0.0) for i in range(6)])
    assert compare_main([str(tmp_path / "a"), str(tmp_path / "b")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert [line.split()[:2] for line in out[:3]] == [["-", "e1"], ["-", "e2"], ["+", "e3"]]
    last = json.loads(out[-1])
    assert (last["paired"], last["up"], last["down"]) == (6, 1, 2)
    assert last["sign_test_p"] == pytest.approx(1.0)


def test_compare_names_the_file_when_a_preset_is_missing_or_ambiguous(tmp_path, capsys) -> None:
    _write(tmp_path / "run", [rec(0, True, 0.5), rec(0, False, preset="no_vis")])
    assert compare_main([str(tmp_path / "run"), str(tmp_path / "run")]) == 2
    assert "several presets (full, no_vis)" in capsys.readouterr().err
    assert compare_main([str(tmp_path / "run"), str(tmp_path / "run"), "--preset", "no_reasoning"]) == 2
    err = capsys.readouterr().err
    assert "no records of preset 'no_reasoning'" in err and "episodes.jsonl" in err
    assert compare_main([str(tmp_path / "run"), str(tmp_path / "run"), "--preset", "full",
                         "--preset-after", "no_vis"]) == 0
    assert json.loads(capsys.readouterr().out.splitlines()[-1])["down"] == 1
    assert compare_main([str(tmp_path / "nowhere"), str(tmp_path / "run")]) == 2
    (tmp_path / "bad.jsonl").write_text(dumps(rec(0, True, 0.5)) + "\n{not json\n" + dumps(rec(1, True)) + "\n")
    assert compare_main([str(tmp_path / "bad.jsonl"), str(tmp_path / "run"), "--preset", "full"]) == 2
    err = capsys.readouterr().err
    assert "bad.jsonl:2: not a JSON line" in err
    (tmp_path / "binary.jsonl").write_bytes(b"\xff\xfe\x00garbage\n")
    assert compare_main([str(tmp_path / "binary.jsonl"), str(tmp_path / "run"), "--preset", "full"]) == 2
    assert "cannot read episode records" in capsys.readouterr().err


def test_compare_splits_the_path_of_the_episodes_both_runs_won_at_the_goal_in_view(tmp_path, capsys) -> None:
    from dataclasses import replace

    def viewed(r, path: float, before: float):
        return replace(r, path_length=path, extra={"goal_in_view": {"steps": 5, "path_m": before, "to_success_m": 1.0}})

    a = [viewed(rec(0, True, 0.5), 10.0, 6.0), viewed(rec(1, True, 0.5), 8.0, 2.0), viewed(rec(2, False), 40.0, 30.0)]
    b = [viewed(rec(0, True, 0.5), 7.0, 3.0), rec(1, True, 0.5), viewed(rec(2, True, 0.2), 20.0, 15.0)]
    _write(tmp_path / "a", a)
    _write(tmp_path / "b", b)
    assert compare_main([str(tmp_path / "a"), str(tmp_path / "b")]) == 0
    out = capsys.readouterr().out.splitlines()
    # only e0 won in both with the field in both: e1's second record predates it, e2 failed before
    assert json.loads(out[-1])["path"] == {"episodes": 1, "before_view_m": [6.0, 3.0], "after_view_m": [4.0, 4.0]}
    assert "before a goal in view 6.0 -> 3.0 m, after 4.0 -> 4.0 m" in out[-2]
    _write(tmp_path / "c", [rec(0, True, 0.5)])
    assert compare_main([str(tmp_path / "c"), str(tmp_path / "c")]) == 0
    assert "path" not in json.loads(capsys.readouterr().out.splitlines()[-1])
