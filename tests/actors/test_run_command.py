"""``hiconav run`` end to end: prints the outcome, writes result.json and a Rerun recording."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from hiconav.mission import run_command

app = typer.Typer()
app.command()(run_command)


@pytest.mark.slow
def test_run_command_finds_the_sofa_and_records(tmp_path: Path, shared_data):
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["--house", "procthor:val/3", "--seed", "0", "--episode", "4", "--out", str(out),
                                      "--record", str(out / "mission.rrd")])
    assert result.exit_code == 0, result.output
    assert "success: True" in result.output
    assert "detector: oracle" in result.output and "reasoner: offline" in result.output
    summary = json.loads((out / "result.json").read_text())
    assert summary["success"] is True and summary["spl"] > 0
    assert (out / "mission.rrd").stat().st_size > 10_000


def test_run_command_rejects_an_unknown_clock(tmp_path: Path):
    from hiconav.errors import ConfigError

    result = CliRunner().invoke(app, ["--clock", "sundial"])
    assert isinstance(result.exception, ConfigError)
