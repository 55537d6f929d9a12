"""The harness: parallel runs are deterministic, resume skips done episodes, bad input is recorded."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest
from eval_walker import make_specs

from hiconav.errors import ConfigError
from hiconav.eval.config import EvalConfig
from hiconav.eval.records import WALL_FIELDS, read_records
from hiconav.eval.runner import evaluate, resolve_runner

RUNNER = "eval_walker:run_episode"


def config(**kw) -> EvalConfig:
    kw.setdefault("workers", 0)
    kw.setdefault("report", False)
    return EvalConfig(runner=RUNNER, progress=False, **kw)


def without_wall_fields(path) -> list[dict]:
    rows = [json.loads(line) for line in path.read_text().splitlines()]
    for row in rows:
        for name in WALL_FIELDS:
            row.pop(name)
    return rows


def test_one_and_two_worker_processes_give_identical_episodes_jsonl(tmp_path) -> None:
    specs = make_specs(8, seed=1)
    evaluate(specs, tmp_path / "w1", config(workers=1, presets=("full", "no_struct")))
    evaluate(specs, tmp_path / "w2", config(workers=2, presets=("full", "no_struct")))
    one = without_wall_fields(tmp_path / "w1" / "episodes.jsonl")
    two = without_wall_fields(tmp_path / "w2" / "episodes.jsonl")
    assert len(one) == 16
    assert one == two
    assert len({round(row["spl"], 6) for row in one}) >= 8  # the walker really varies


def test_resume_skips_episodes_already_in_the_output(tmp_path) -> None:
    specs = make_specs(6, seed=2)
    evaluate(specs[:4], tmp_path, config())
    first = (tmp_path / "episodes.jsonl").read_text().splitlines()
    evaluate(specs, tmp_path, config())
    second = (tmp_path / "episodes.jsonl").read_text().splitlines()
    assert len(second) == 6
    assert second[:4] == first  # wall times included: the first 4 were not run again


def test_resume_reruns_a_record_cut_off_by_a_kill(tmp_path) -> None:
    specs = make_specs(3, seed=3)
    evaluate(specs, tmp_path, config())
    path = tmp_path / "episodes.jsonl"
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines[:2]) + lines[2][:40])
    evaluate(specs, tmp_path, config())
    assert [r.episode_id for r in read_records(path)] == [s.episode_id for s in specs]


def test_each_episode_seed_is_the_same_for_every_preset(tmp_path) -> None:
    summary = evaluate(make_specs(3), tmp_path, config(presets=("ablations",)))
    records = read_records(tmp_path / "episodes.jsonl")
    seeds = {}
    for r in records:
        seeds.setdefault(r.episode_id, set()).add(r.seed)
    assert all(len(s) == 1 for s in seeds.values())
    from hiconav.eval.presets import PRESETS

    assert len(summary["presets"]) == len(PRESETS) == 9 and set(summary["ablations"]) == set(summary["presets"]) - {"full"}


def test_bad_input_and_crashes_are_recorded_and_never_abort_the_run(tmp_path) -> None:
    specs = make_specs(3, seed=4)
    specs[0] = replace(specs[0], target="unicorn")  # unknown category -> DataError in the runner
    specs[1] = replace(specs[1], error="house failed to load")  # bad input found by the source
    summary = evaluate(specs, tmp_path, config())
    by_id = {r.episode_id: r for r in read_records(tmp_path / "episodes.jsonl")}
    assert by_id[specs[0].episode_id].failure == "invalid_episode"
    assert "unicorn" in by_id[specs[0].episode_id].error
    assert by_id[specs[1].episode_id].failure == "invalid_episode"
    assert summary["episodes"] == 3 and summary["valid_episodes"] == 1
    crashed = evaluate(make_specs(2), tmp_path / "crash", config(overrides={"walker.crash": True}))
    assert crashed["failures"]["error"] == 2 and crashed["success_rate"] == 0.0


def test_runner_import_path_errors_are_config_errors() -> None:
    with pytest.raises(ConfigError, match="module:function"):
        resolve_runner("no_colon")
    with pytest.raises(ConfigError, match="cannot import"):
        resolve_runner("hiconav.nosuchmodule:run")


def test_ray_backend_without_ray_says_how_to_install(tmp_path, monkeypatch) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "ray", None)  # import ray -> ImportError
    with pytest.raises(ConfigError, match=r"hiconav\[ray\]"):
        evaluate(make_specs(1), tmp_path, config(backend="ray"))


def test_unknown_runner_fails_once_before_any_episode(tmp_path) -> None:
    with pytest.raises(ConfigError, match="hiconav.nosuch"):
        evaluate(make_specs(2), tmp_path, EvalConfig(runner="hiconav.nosuch:run", workers=0, progress=False))
    path = tmp_path / "episodes.jsonl"
    assert not path.exists() or not path.read_text()


def test_worker_processes_render_in_their_own_thread_unless_the_user_says_otherwise(monkeypatch) -> None:
    from hiconav.eval import runner

    for name in runner.WORKER_THREAD_ENV:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("OMP_NUM_THREADS", "3")
    runner._init_worker()
    import os

    assert os.environ["LP_NUM_THREADS"] == "0"  # llvmpipe: no render threads beside the worker
    assert os.environ["NUMBA_NUM_THREADS"] == "1"
    assert os.environ["OMP_NUM_THREADS"] == "3"  # the user's value wins
