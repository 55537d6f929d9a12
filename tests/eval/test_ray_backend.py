"""The Ray backend gives the same episodes.jsonl as local worker processes (local Ray, 2 CPUs)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from eval_walker import make_specs

from hiconav.eval.config import EvalConfig
from hiconav.eval.records import WALL_FIELDS
from hiconav.eval.runner import evaluate

pytestmark = pytest.mark.slow


def rows(path: Path) -> list[dict]:
    out = [json.loads(line) for line in path.read_text().splitlines()]
    for row in out:
        for name in WALL_FIELDS:
            row.pop(name)
    return out


def test_ray_and_local_backends_write_identical_episodes(tmp_path) -> None:
    ray = pytest.importorskip("ray")
    specs = make_specs(5, seed=7)
    common = {"runner": "eval_walker:run_episode", "presets": ("full", "no_vis"), "progress": False,
              "report": False}
    evaluate(specs, tmp_path / "local", EvalConfig(workers=2, **common))
    here = str(Path(__file__).resolve().parent)
    path = os.pathsep.join(p for p in (here, os.environ.get("PYTHONPATH", "")) if p)
    ray.init(num_cpus=2, _node_ip_address="127.0.0.1", include_dashboard=False, log_to_driver=False,
             runtime_env={"env_vars": {"PYTHONPATH": path}})
    try:
        evaluate(specs, tmp_path / "ray", EvalConfig(backend="ray", **common))
    finally:
        ray.shutdown()
    local = rows(tmp_path / "local" / "episodes.jsonl")
    assert len(local) == 10
    assert rows(tmp_path / "ray" / "episodes.jsonl") == local
