"""The Ray backend gives the same episodes.jsonl as local worker processes: two real episodes
(generated on procthor:val/3, the whole navigator on the stepped clock), local Ray started in
this process. Ray is a dev dependency: a missing one fails here, it does not skip."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import ray

from hiconav.eval.config import EvalConfig
from hiconav.eval.records import WALL_FIELDS
from hiconav.eval.runner import evaluate
from hiconav.eval.sources import generate_for_house


def rows(path: Path) -> list[dict]:
    out = [json.loads(line) for line in path.read_text().splitlines()]
    for row in out:
        for name in WALL_FIELDS:
            row.pop(name)
    return out


@pytest.mark.timeout(1200)  # ~30 s on 2 idle cores; 285 s beside four busy loops
def test_ray_and_local_backends_write_identical_episodes(tmp_path, shared_data) -> None:
    specs = generate_for_house("procthor:val/3", 2, seed=0)  # as `hiconav eval ... --limit 2`
    assert len(specs) == 2 and all(s.error is None for s in specs)
    common = {"progress": False, "report": False}
    evaluate(specs, tmp_path / "local", EvalConfig(workers=1, **common))
    ray.init(num_cpus=1, _node_ip_address="127.0.0.1", include_dashboard=False, log_to_driver=False)
    try:
        evaluate(specs, tmp_path / "ray", EvalConfig(backend="ray", **common))
    finally:
        ray.shutdown()
    local = rows(tmp_path / "local" / "episodes.jsonl")
    assert [r["episode_id"] for r in local] == [s.episode_id for s in specs]
    assert all(r["error"] is None and r["steps"] > 0 for r in local)  # real episodes ran
    assert rows(tmp_path / "ray" / "episodes.jsonl") == local
