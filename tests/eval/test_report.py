"""summary.json, report.md (paper-like tables, component labels) and PNG plots are written."""

from __future__ import annotations

import json
import re

from eval_walker import make_specs

from hiconav.eval.config import EvalConfig
from hiconav.eval.runner import evaluate


def test_report_summary_and_plots_are_written(tmp_path) -> None:
    config = EvalConfig(runner="eval_walker:run_episode", presets=("full", "utility_greedy"), workers=0,
                        progress=False)
    evaluate(make_specs(10, seed=5), tmp_path, config, run_info={"command": "hiconav eval --test"})
    summary = json.loads((tmp_path / "summary.json").read_text())
    for key in ("success_rate", "spl", "dts", "episodes", "failures", "timing"):
        assert key in summary
    assert summary["episodes"] == 10
    assert set(summary["ablations"]) == {"utility_greedy"}

    report = (tmp_path / "report.md").read_text()
    for heading in ("## Main results", "## Ablations", "## Failure taxonomy", "## Efficiency"):
        assert heading in report
    assert "oracle detector" in report and "offline reasoner" in report
    assert "w/o WTRP formulation" in report
    assert "control (ms/frame)" in report
    assert "hiconav eval --test" in report
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", report)
    assert set(links) == {"success_by_target.png", "spl_hist.png", "failures.png", "layer_latency.png"}
    for link in links:
        assert (tmp_path / link).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_main_table_shows_the_measured_sr(tmp_path) -> None:
    config = EvalConfig(runner="eval_walker:run_episode", workers=0, progress=False)
    summary = evaluate(make_specs(6, seed=6), tmp_path, config)
    row = next(line for line in (tmp_path / "report.md").read_text().splitlines() if line.startswith("| full"))
    assert f"{100 * summary['success_rate']:.1f}" in row
    assert "Only one preset ran" in (tmp_path / "report.md").read_text()


def test_a_report_without_labelled_plots_writes_no_legend_warning(tmp_path, recwarn, capsys) -> None:
    """Every episode invalid: nothing in the SPL histogram or the outcome bars carries a label, so
    no legend is drawn (matplotlib would warn "No artists with labels found")."""
    from hiconav.eval.records import EpisodeRecord
    from hiconav.eval.report import write_report
    from hiconav.eval.summary import summarize

    records = [EpisodeRecord(episode_id="e0", house="h", target="bed", preset="full", failure="invalid_episode")]
    write_report(tmp_path, records, summarize(records))
    assert (tmp_path / "report.md").is_file() and (tmp_path / "failures.png").is_file()
    assert [str(w.message) for w in recwarn] == []
    assert capsys.readouterr() == ("", "")


def test_the_report_says_where_the_path_went_when_records_carry_the_goal_in_view() -> None:
    from hiconav.eval.records import EpisodeRecord
    from hiconav.eval.report import render_markdown
    from hiconav.eval.summary import summarize

    def rec(i: int, success: bool, path: float, **extra) -> EpisodeRecord:
        return EpisodeRecord(episode_id=f"e{i}", house="h", target="bed", preset="full", success=success,
                             failure="success" if success else "step_out", spl=0.5 if success else 0.0,
                             path_length=path, extra={"shortest_to_success": 4.0, **extra})

    records = [rec(0, True, 8.0, goal_in_view={"steps": 9, "path_m": 6.0, "to_success_m": 1.5}),
               rec(1, False, 50.0, goal_in_view=None)]
    text = render_markdown(records, summarize(records))
    assert "## Where the path goes" in text
    row = next(line for line in text.splitlines() if line.startswith("| full") and "75.0" in line)
    assert row.split(" | ")[1:5] == ["1", "4", "8", "6"]  # successes, shortest, driven, before the view
    assert "2 / 2" in row and "1 / 1" in row  # after: driven / shortest; failures never in view
    assert "Turns in place" not in text  # these records do not count their turns
    counted = [EpisodeRecord(**{**r.__dict__, "steps": 100, "extra": {**r.extra, "turns": 45}}) for r in records]
    assert "Turns in place, full: 90 of 200 actions (45.0%) over 2 episodes" in render_markdown(counted, summarize(counted))
    assert "Actions by the behaviour" not in render_markdown(counted, summarize(counted))  # not tallied
    tallied = [EpisodeRecord(**{**r.__dict__, "extra": {**r.extra, "actions_by_behaviour": {
        "Explore": {"turns": 30, "forward": 60, "other": 0}, "VerifyTarget": {"turns": 9, "forward": 0, "other": 1}}}})
        for r in counted]
    assert ("Actions by the behaviour whose goal they served, full: Explore 180 (90.0%, 60 turns), "
            "VerifyTarget 20 (10.0%, 18 turns).") in render_markdown(tallied, summarize(tallied))
    assert "Path beyond SPL's shortest paths" not in render_markdown(tallied, summarize(tallied))  # not measured
    measured = [EpisodeRecord(**{**r.__dict__, "extra": {**r.extra, "excess_path": {
        "by_behaviour": {"Explore": 3.0, "Approach": 1.0}, "inside_m": 0.5, "unmeasured_m": 0.0}}}) for r in records]
    assert ("Path beyond SPL's shortest paths, full: 4 m over 1 successes, by the behaviour whose goal each step "
            "served: Explore 3 m (75.0%), Approach 1 m (25.0%); 0.5 m of it inside the success region"
            ) in render_markdown(measured, summarize(measured))
    older = [rec(2, True, 3.0)]  # records written before the field existed: no such section
    assert "## Where the path goes" not in render_markdown(older, summarize(older))
