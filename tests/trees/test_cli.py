"""``hiconav tree``: validates and prints a mission; errors carry file:line."""

from __future__ import annotations

from pathlib import Path

import typer
from hiconav.trees import TreeError
from hiconav.trees.cli import tree
from typer.testing import CliRunner

app = typer.Typer()
app.command()(tree)


def test_tree_prints_the_default_mission(tmp_path: Path):
    dot = tmp_path / "objectnav.dot"
    result = CliRunner().invoke(app, ["objectnav", "--params", "--dot", str(dot)])
    assert result.exit_code == 0, result.output
    for name in ("ParseInstruction", "TargetConfirmed", "Explore", "VerifyTarget", "Approach", "Stop"):
        assert name in result.output
    assert "objectnav.yaml:" in result.output
    assert "digraph" in dot.read_text()


def test_tree_rejects_a_bad_file_with_its_line():
    bad = Path(__file__).parent / "data" / "bad" / "03_wrong_type.yaml"
    result = CliRunner().invoke(app, [str(bad)])
    assert result.exit_code != 0
    assert isinstance(result.exception, TreeError)
    assert f"{bad}:4" in str(result.exception)
