"""``hiconav eval --houses HOUSES --episodes FILE.jsonl``: task episode files (objectnav, ovon,
textnav) read line by line, a bad line one invalid episode naming its file, line and field; and
``hiconav episodes``, which writes them."""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from hiconav.errors import ConfigError
from hiconav.eval.cli import eval as eval_command
from hiconav.eval.runner import Task, run_task
from hiconav.eval.sources import EpisodeSpec, invalid_reason, task_episode_source, validate_spec
from hiconav.sim.episodes_cli import episodes as episodes_command
from hiconav.sim.houses import load_house
from hiconav.sim.task_episodes import generate_task_episodes, write_task_episodes

app = typer.Typer()
app.command("eval")(eval_command)
app.command("episodes")(episodes_command)


@pytest.fixture(scope="module")
def val3_file(shared_data, tmp_path_factory) -> Path:
    """Two episodes of each task on ProcTHOR val/3 (line 3 of val.jsonl.gz)."""
    house = load_house("procthor:val/3", shared_data)
    path = tmp_path_factory.mktemp("eps") / "val3.jsonl"
    write_task_episodes(path, [ep for task in ("objectnav", "ovon", "textnav")
                               for ep in generate_task_episodes(house, 3, task, 2, seed=0)])
    return path


def test_a_written_file_reads_back_as_runnable_specs(shared_data, val3_file) -> None:
    houses = shared_data / "procthor" / "val.jsonl.gz"
    lines = [json.loads(line) for line in val3_file.read_text().splitlines()]
    specs = task_episode_source(houses, [val3_file])
    house = load_house("procthor:val/3", shared_data)
    assert [s.episode_id for s in specs] == [line["episode_id"] for line in lines]
    for spec, line in zip(specs, lines, strict=True):
        assert spec.error is None and spec.house == "procthor:val/3"
        assert (spec.task, spec.instruction, spec.target) == (line["task"], line["instruction"], line["target"])
        assert list(spec.start) == line["start"]
        assert [house.objects[i].source_id for i in spec.goal_instance_ids] == line["goal_object_ids"]
        assert spec.geodesic_distance >= 1.5
        assert validate_spec(spec) is None
    assert {s.task for s in specs} == {"objectnav", "ovon", "textnav"}


def test_the_first_limit_episodes_are_taken(shared_data, val3_file) -> None:
    houses = shared_data / "procthor" / "val.jsonl.gz"
    assert [s.episode_id for s in task_episode_source(houses, [val3_file], limit=2)] == \
        ["objectnav/3/0", "objectnav/3/1"]


def _bad_file(tmp_path: Path, good: dict, house) -> Path:
    fridge = next(o for o in house.objects if o.category == "fridge")
    lines = [
        json.dumps(good),                                                        # 1 valid
        "{not json",                                                             # 2
        json.dumps({**good, "episode_id": "b3", "goal_object_ids": ["Nope|9|9"]}),  # 3 unknown id
        json.dumps({**good, "episode_id": "b4", "start": [-50.0, -50.0, 0.0]}),     # 4 off the map
        json.dumps({**good, "episode_id": "b5", "start": [float(fridge.center[0]), float(fridge.center[1]), 0.0]}),
        json.dumps({**good, "episode_id": "b6", "task": "pointnav"}),              # 6 unknown task
        json.dumps({**good, "episode_id": "b7", "house": 999}),                    # 7 no such house
        json.dumps(good),                                                        # 8 the same id again
        "",                                                                      # 9 blank: skipped
        json.dumps({**good, "episode_id": "b10", "target": "bed"}),                 # 10 goal not a bed
        json.dumps({**good, "episode_id": "b11", "start": [1.0, 2.0]}),             # 11 bad field
    ]
    path = tmp_path / "bad.jsonl"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_bad_lines_become_invalid_episodes_naming_file_line_and_field(shared_data, val3_file, tmp_path) -> None:
    houses = shared_data / "procthor" / "val.jsonl.gz"
    good = json.loads(val3_file.read_text().splitlines()[0])
    path = _bad_file(tmp_path, good, load_house("procthor:val/3", shared_data))
    specs = task_episode_source(houses, [path])
    assert len(specs) == 10
    assert specs[0].error is None
    expected = {2: (None, "malformed episode line"), 3: ("goal_object_ids[0]", "unknown goal object id"),
                4: ("start", "start off the robot's free space"), 5: ("start", "start off the robot's free space"),
                6: ("task", "unknown task"), 7: ("house", "house not in the houses file"),
                8: ("episode_id", "episode id given twice"), 10: ("goal_object_ids[0]", "goal object of another category"),
                11: ("start", "missing or bad field")}
    for spec, (line, (field, reason)) in zip(specs[1:], sorted(expected.items()), strict=True):
        assert spec.error is not None and spec.error.startswith(f"{path}:{line}"), (line, spec.error)
        if field is not None:
            assert f"[{field}]" in spec.error, spec.error
        assert invalid_reason(spec.error) == reason, spec.error
    assert specs[1].episode_id == "bad.jsonl:2"  # a line without a readable id is named by its place


def test_an_invalid_line_is_recorded_as_an_invalid_episode(shared_data, val3_file, tmp_path) -> None:
    houses = shared_data / "procthor" / "val.jsonl.gz"
    good = json.loads(val3_file.read_text().splitlines()[0])
    spec = task_episode_source(houses, [_bad_file(tmp_path, good, load_house("procthor:val/3", shared_data))])[2]
    record = run_task(Task(spec, "full", runner="eval_walker:run_episode"))
    assert record.failure == "invalid_episode" and "Nope|9|9" in record.error


def test_houses_and_episodes_anywhere_on_disk(shared_data, tmp_path) -> None:
    with gzip.open(shared_data / "procthor" / "val.jsonl.gz", "rt", encoding="utf-8") as fh:
        lines = [line for line in fh.read().splitlines() if line.strip()]
    houses = tmp_path / "two_houses.jsonl"
    houses.write_text(lines[3] + "\n" + lines[5] + "\n")
    house = load_house(f"{houses}#1")
    episodes = tmp_path / "mine.jsonl"
    write_task_episodes(episodes, generate_task_episodes(house, 1, "ovon", 2, seed=4))
    specs = task_episode_source(houses, [episodes])
    assert len(specs) == 2
    for spec in specs:
        assert spec.error is None and spec.house == f"{houses.resolve()}#1" and spec.task == "ovon"
        assert validate_spec(spec) is None


def test_task_reaches_the_record_and_objectnav_records_stay_as_they_were() -> None:
    spec = EpisodeSpec("e", "h", "chair", start=(0.0, 0.0, 0.0), geodesic_distance=3.0, task="textnav")
    record = run_task(Task(spec, "full", runner="eval_walker:run_episode"))
    assert record.extra["task"] == "textnav"
    plain = run_task(Task(EpisodeSpec("e", "h", "chair", geodesic_distance=3.0), "full",
                          runner="eval_walker:run_episode"))
    assert "task" not in plain.extra


def test_specs_carry_the_task_and_objectnav_specs_are_written_as_before() -> None:
    spec = EpisodeSpec("e", "h", "sofa", task="ovon", instruction="find the couch")
    assert EpisodeSpec.from_json(spec.to_json()) == spec
    plain = EpisodeSpec("e", "h", "sofa")
    assert sorted(plain.to_json()) == ["episode_id", "error", "geodesic_distance", "goal_instance_ids", "house",
                                       "instruction", "source_id", "start", "target"]
    assert EpisodeSpec.from_json(plain.to_json()).task == "objectnav"
    assert "task" not in plain.to_episode().to_json()
    assert spec.to_episode().task == "ovon"


def test_eval_dry_run_reads_an_episode_file_with_houses(shared_data, val3_file, tmp_path) -> None:
    houses = shared_data / "procthor" / "val.jsonl.gz"
    good = json.loads(val3_file.read_text().splitlines()[0])
    path = _bad_file(tmp_path, good, load_house("procthor:val/3", shared_data))
    result = CliRunner().invoke(app, ["eval", "--houses", str(houses), "--episodes", str(path), "--dry-run",
                                      "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    counts = json.loads(result.output.strip().splitlines()[-1])
    assert counts["episodes"] == 10 and counts["valid"] == 1
    assert counts["invalid"]["start off the robot's free space"] == 2
    assert f"{path}:3" in result.output


def test_episodes_command_writes_a_file_eval_reads(shared_data, tmp_path) -> None:
    with gzip.open(shared_data / "procthor" / "val.jsonl.gz", "rt", encoding="utf-8") as fh:
        lines = [line for line in fh.read().splitlines() if line.strip()]
    houses = tmp_path / "houses.jsonl"
    houses.write_text("\n".join(lines[3:6]) + "\n")
    out = tmp_path / "ovon.jsonl"
    result = CliRunner().invoke(app, ["episodes", "--houses", str(houses), "--task", "ovon", "--per-house", "2",
                                      "--seed", "0", "--out", str(out)])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.output.strip().splitlines()[-1])
    assert summary["episodes"] == 6 and summary["houses_with_episodes"] == 3
    specs = task_episode_source(houses, [out])
    assert len(specs) == 6 and all(s.error is None and s.task == "ovon" for s in specs)


def test_episodes_command_refuses_an_unknown_task(shared_data, tmp_path) -> None:
    result = CliRunner().invoke(app, ["episodes", "--houses", str(shared_data / "procthor" / "val.jsonl.gz"),
                                      "--task", "pointnav", "--out", str(tmp_path / "x.jsonl")])
    assert isinstance(result.exception, ConfigError) and "objectnav, ovon, textnav" in str(result.exception)


def test_episodes_is_a_hiconav_command(tmp_path, capsys) -> None:
    from hiconav import cli

    assert ("episodes", "hiconav.sim.episodes_cli", "episodes") in cli.SUBCOMMANDS
    assert cli.main(["episodes", "--houses", str(tmp_path / "none.jsonl"), "--task", "ovon",
                     "--out", str(tmp_path / "x.jsonl")]) == 2
    assert "none.jsonl" in capsys.readouterr().err
