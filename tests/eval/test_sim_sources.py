"""Episode sources through the real simulator (hiconav.sim): generated ProcTHOR episodes,
Habitat episode files on Gibson floors, and a harness run on real houses."""

from __future__ import annotations

import gzip
import json

import pytest

from hiconav.eval.sources import gibson_source, procthor_source


def test_generated_procthor_episodes_round_trip_through_the_simulator(shared_data) -> None:
    sim = pytest.importorskip("hiconav.sim")
    if not hasattr(sim, "generate_episodes"):
        pytest.skip("hiconav.sim.generate_episodes not available yet")
    specs = procthor_source(shared_data / "procthor" / "val.jsonl.gz", 2, seed=0, limit=3)
    assert len(specs) == 3 and all(s.error is None for s in specs), [s.error for s in specs]
    assert specs[0].house == "procthor:val/0" and specs[2].house == "procthor:val/1"
    assert len({s.episode_id for s in specs}) == 3
    episode = specs[0].to_episode()
    assert episode.target == specs[0].target
    assert specs[0].load_house() is specs[1].load_house()  # cached per process
    again = procthor_source(shared_data / "procthor" / "val.jsonl.gz", 2, seed=0, limit=3)
    assert again == specs  # deterministic per seed


@pytest.mark.slow
def test_real_procthor_episodes_run_identically_with_1_and_2_workers(shared_data, tmp_path) -> None:
    sim = pytest.importorskip("hiconav.sim")
    if not hasattr(sim, "generate_episodes"):
        pytest.skip("hiconav.sim.generate_episodes not available yet")
    from hiconav.eval.config import EvalConfig
    from hiconav.eval.records import read_records
    from hiconav.eval.runner import evaluate

    specs = procthor_source(shared_data / "procthor" / "val.jsonl.gz", 2, seed=1, limit=4)
    outputs = []
    for workers in (1, 2):
        config = EvalConfig(runner="sim_walker:run_episode", workers=workers, progress=False, report=False)
        evaluate(specs, tmp_path / str(workers), config)
        outputs.append([r.deterministic_view() for r in read_records(tmp_path / str(workers) / "episodes.jsonl")])
    assert outputs[0] == outputs[1]
    assert len(outputs[0]) == 4 and all(r["error"] is None for r in outputs[0])
    assert sum(r["success"] for r in outputs[0]) >= 2  # the walker descends the real geodesic field


def test_one_bad_habitat_episode_is_one_invalid_spec_the_rest_load(shared_data, tmp_path) -> None:
    sim = pytest.importorskip("hiconav.sim")
    if not hasattr(sim, "load_habitat_episodes"):
        pytest.skip("hiconav.sim.load_habitat_episodes not available yet")
    (good,) = sim.generate_episodes(sim.load_house("gibson:Allensville/0"), 1, seed=3)
    floor_height = sim.load_house("gibson:Allensville/0").floor_height
    habitat_start = [good.start.y, floor_height, good.start.x]  # world (x, y, z) = (z_h, x_h, y_h - floor)
    base = {"scene_id": "gibson/Allensville.glb", "start_rotation": [0, 0, 0, 1], "floor_id": 0}
    episodes = {"episodes": [
        {**base, "episode_id": "ok", "start_position": habitat_start, "object_category": "chair"},
        {**base, "episode_id": "far", "start_position": [900.0, 0.0, 900.0], "object_category": "chair"},
        {**base, "episode_id": "odd", "start_position": habitat_start, "object_category": "unicorn"},
    ]}
    path = tmp_path / "Allensville_episodes.json.gz"
    with gzip.open(path, "wt") as fh:
        json.dump(episodes, fh)
    specs = gibson_source(shared_data / "gibson" / "train_info.pbz2", [path])
    by_id = {s.episode_id.rsplit("/", 1)[-1]: s for s in specs}
    assert set(by_id) == {"ok", "far", "odd"}
    assert by_id["ok"].error is None and by_id["ok"].house == "gibson:Allensville/0"
    assert by_id["ok"].target == "chair"
    assert "outside" in by_id["far"].error and "episodes[1]" in by_id["far"].error
    assert "unicorn" in by_id["odd"].error


def test_houses_file_outside_the_data_root_loads_by_line(shared_data, tmp_path) -> None:
    sim = pytest.importorskip("hiconav.sim")
    if not hasattr(sim, "generate_episodes"):
        pytest.skip("hiconav.sim.generate_episodes not available yet")
    source = shared_data / "procthor" / "val.jsonl.gz"
    with gzip.open(source, "rt") as fh:
        lines = [next(fh) for _ in range(2)]
    mine = tmp_path / "mine.jsonl.gz"
    with gzip.open(mine, "wt") as fh:
        fh.writelines(lines)
    specs = procthor_source(mine, 1, seed=0, limit=2)
    assert [s.error for s in specs] == [None, None]
    assert specs[1].house == f"{mine.resolve()}#1"
    reference = procthor_source(source, 1, seed=0, limit=2)
    assert [s.target for s in specs] != [] and len(reference) == 2
    assert specs[1].load_house().objects[0].category == sim.load_house("procthor:val/1").objects[0].category
