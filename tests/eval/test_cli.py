"""``hiconav eval`` options: clear errors for missing files and bad combinations; a real run."""

from __future__ import annotations

import json

import pytest
import typer
from typer.testing import CliRunner

from hiconav.errors import ConfigError, DataError
from hiconav.eval.cli import eval as eval_command

app = typer.Typer()
app.command("eval")(eval_command)
app.command("noop")(lambda: None)  # keeps "eval" a subcommand, as in hiconav.cli


def invoke(*args: str):
    return CliRunner().invoke(app, ["eval", *args])


def test_missing_houses_file_names_the_file_and_option(tmp_path) -> None:
    result = invoke("--houses", str(tmp_path / "nope.jsonl.gz"), "--out", str(tmp_path / "o"))
    assert isinstance(result.exception, DataError)
    assert "nope.jsonl.gz" in str(result.exception) and "--houses" in str(result.exception)
    assert "file not found" in str(result.exception)


def test_missing_maps_and_episode_files_are_reported(tmp_path, shared_data) -> None:
    result = invoke("--maps", str(tmp_path / "maps.pbz2"), "--out", str(tmp_path / "o"))
    assert isinstance(result.exception, DataError) and "--maps" in str(result.exception)
    maps = shared_data / "gibson" / "train_info.pbz2"
    result = invoke("--maps", str(maps), "--episodes", str(tmp_path / "eps"), "--out", str(tmp_path / "o"))
    assert isinstance(result.exception, DataError) and "--episodes" in str(result.exception)


def test_exactly_one_input_is_required(tmp_path, shared_data) -> None:
    result = invoke("--out", str(tmp_path))
    assert isinstance(result.exception, ConfigError) and "exactly one input" in str(result.exception)


def test_unknown_preset_lists_the_known_ones(tmp_path, shared_data) -> None:
    houses = shared_data / "procthor" / "val.jsonl.gz"
    result = invoke("--houses", str(houses), "--preset", "full,nonsense", "--out", str(tmp_path))
    assert isinstance(result.exception, ConfigError)
    assert "nonsense" in str(result.exception) and "ablations" in str(result.exception)


def test_errors_print_one_line_through_the_main_cli(tmp_path, capsys) -> None:
    try:
        from hiconav import cli
    except ImportError as exc:  # another area's subcommand module is not written yet
        pytest.skip(f"hiconav.cli does not import yet: {exc}")
    if not any(name == "eval" for name, _m, _f in cli.SUBCOMMANDS):
        pytest.skip("eval is not registered in hiconav/cli.py yet")
    assert cli.main(["eval", "--houses", str(tmp_path / "x.jsonl.gz"), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "x.jsonl.gz" in err and "Traceback" not in err


@pytest.mark.slow
def test_gibson_run_with_a_custom_runner_writes_outputs(tmp_path, shared_data) -> None:
    pytest.importorskip("hiconav.sim.episodes", reason="simulator episodes not available yet")
    maps = shared_data / "gibson" / "train_info.pbz2"
    result = invoke("--maps", str(maps), "--episodes-per-house", "2", "--limit", "2", "--workers", "0",
                    "--runner", "eval_walker:run_episode", "--no-progress", "--out", str(tmp_path))
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["episodes"] == 2
    lo, hi = summary["success_rate_ci95"]  # the last line gives the SR with its interval
    assert f"[95% CI {lo:.3f}, {hi:.3f}]" in result.output


def test_set_values_are_parsed_as_yaml_and_bad_ones_rejected() -> None:
    from hiconav.eval.cli import _parse_sets

    assert _parse_sets(["exploration.lambda_vis=0.5", "mission.verify=false", "a.b=nearest"]) == {
        "exploration.lambda_vis": 0.5, "mission.verify": False, "a.b": "nearest"}
    with pytest.raises(ConfigError, match="area.key=value"):
        _parse_sets(["novalue"])


@pytest.mark.slow
def test_a_resumed_cli_run_reuses_the_saved_episodes(tmp_path, shared_data) -> None:
    pytest.importorskip("hiconav.sim.episodes", reason="simulator episodes not available yet")
    houses = shared_data / "procthor" / "val.jsonl.gz"
    args = ["--houses", str(houses), "--episodes-per-house", "1", "--limit", "2", "--workers", "0",
            "--runner", "eval_walker:run_episode", "--no-progress", "--out", str(tmp_path)]
    assert invoke(*args).exit_code == 0
    specs = (tmp_path / "specs.jsonl").read_text()
    (tmp_path / "specs.jsonl").write_text(specs.replace('"target": "', '"target": "x'))  # marks reuse
    result = invoke(*args)
    assert result.exit_code == 0, result.output
    assert (tmp_path / "specs.jsonl").read_text() != specs  # not regenerated: the same options
    assert json.loads((tmp_path / "summary.json").read_text())["episodes"] == 2  # nothing ran again


def test_an_output_folder_with_results_from_other_episode_options_is_refused(tmp_path) -> None:
    """Resuming skips episodes by id: records of episodes generated under other options (another
    seed, or an older version's episode rules) must not stand for the new ones."""
    from hiconav.errors import DataError
    from hiconav.eval.cli import _check_resumable, _saved_source
    from hiconav.sim.episodes import EPISODE_RULES

    source = {"houses": "/d/val.jsonl.gz", "maps": None, "episodes": [], "episodes_per_house": 3, "seed": 0,
              "limit": None, "episode_rules": EPISODE_RULES}
    old = {k: v for k, v in source.items() if k != "episode_rules"}  # written before the rules were recorded
    (tmp_path / "source.json").write_text(json.dumps(old))
    _check_resumable(tmp_path, _saved_source(tmp_path), source)  # no results yet: the folder is simply reused
    (tmp_path / "episodes.jsonl").write_text('{"episode_id": "x"}\n')
    with pytest.raises(DataError, match="episode_rules"):
        _check_resumable(tmp_path, _saved_source(tmp_path), source)
    (tmp_path / "source.json").write_text(json.dumps({**source, "limit": 30}))
    _check_resumable(tmp_path, _saved_source(tmp_path), source)  # a longer run over the same list extends it
    (tmp_path / "source.json").write_text(json.dumps({**source, "seed": 1}))
    with pytest.raises(DataError, match="seed"):
        _check_resumable(tmp_path, _saved_source(tmp_path), source)
