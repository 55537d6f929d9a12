"""The tree orchestrates, the core decides (issue #28): size and wording guards on trees/."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TREE_FILES = sorted((ROOT / "trees").rglob("*.py"))
CORE = sorted((ROOT / "hiconav" / "decisions").glob("*.py"))
EPISODE = re.compile(r"(?:val|train)/\d+/\d|[A-Z][a-z]+/\d+/\d")  # a trace id: ProcTHOR val/52/1, Gibson Onaga/0/1
CODE = sorted(p for d in ("hiconav", "actors", "trees", "drivers") for p in (ROOT / d).rglob("*.py"))


def test_the_tree_files_exist():
    assert (ROOT / "trees" / "behaviours" / "verify.py") in TREE_FILES and CORE


@pytest.mark.parametrize("path", TREE_FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_file_of_the_tree_layer_is_over_400_lines(path: Path):
    assert len(path.read_text().splitlines()) <= 400


@pytest.mark.parametrize("path", [p for p in TREE_FILES if p.parent.name == "behaviours"],
                         ids=lambda p: p.name)
def test_no_behaviour_class_is_over_about_100_lines(path: Path):
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.ClassDef):
            assert node.end_lineno - node.lineno + 1 <= 120, f"{path.name}:{node.lineno} {node.name}"


@pytest.mark.parametrize("path", CODE, ids=lambda p: str(p.relative_to(ROOT)))
def test_comments_state_the_case_not_the_episode(path: Path):
    """The traces behind the rules live in docs/results_history.md."""
    hits = [f"{path.name}:{i}" for i, line in enumerate(path.read_text().splitlines(), 1) if EPISODE.search(line)]
    assert not hits, hits
