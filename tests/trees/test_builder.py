"""Mission YAML builder: every malformed file is rejected with file:line [key]; good files build."""

from __future__ import annotations

import re
from pathlib import Path

import py_trees
import pytest
from hiconav.trees import BlackboardRef, TreeError, build_tree, load_tree
from hiconav.trees.builder import TREES_DIR

from hiconav.errors import ConfigError

BAD = sorted((Path(__file__).parent / "data" / "bad").glob("*.yaml"))


def _expected_location(path: Path) -> str:
    text = path.read_text()
    match = re.search(r"# expect-at: (\S+)", text)
    if match:
        name, line = match.group(1).rsplit(":", 1)
        return f"{path.parent / name}:{line}"
    lines = text.splitlines()
    line = next(i + 1 for i, text in enumerate(lines) if "# <-" in text)
    return f"{path}:{line}"


def test_there_are_at_least_fifteen_malformed_files():
    assert len(BAD) >= 15


@pytest.mark.parametrize("path", BAD, ids=[p.stem for p in BAD])
def test_malformed_file_is_rejected_with_file_and_line(path: Path):
    with pytest.raises(TreeError) as info:
        load_tree(path)
    message = str(info.value)
    assert _expected_location(path) in message, message
    assert isinstance(info.value, ConfigError)
    assert info.value.line is not None


@pytest.mark.parametrize("name", ["objectnav", "find_and_return", "locate_target"])
def test_shipped_missions_build(name: str):
    root, definition = build_tree(name)
    assert isinstance(root, py_trees.behaviour.Behaviour)
    assert definition.name == name


def test_objectnav_has_the_documented_shape():
    root, _ = build_tree(TREES_DIR / "objectnav.yaml")
    names = [type(n).__name__ for n in root.iterate()]
    for expected in ("ParseInstruction", "TargetConfirmed", "Explore", "VerifyTarget", "Approach", "Stop"):
        assert expected in names
    assert isinstance(root, py_trees.composites.Sequence) and root.memory is True
    find = next(n for n in root.iterate() if n.name == "find")
    assert isinstance(find, py_trees.composites.Selector) and find.memory is False


def test_blackboard_reference_is_kept_as_a_reference():
    definition = load_tree("objectnav")
    parse = definition.root.children[0]
    assert parse.params["instruction"] == BlackboardRef("instruction")
    assert definition.blackboard["instruction"] == "find the bed"


def test_subtree_is_included_by_name_and_recorded():
    definition = load_tree("find_and_return")
    assert any(p.endswith("locate_target.yaml") for p in definition.includes)
    names = [n.name for n in build_tree(definition)[0].iterate()]
    assert "until verified" in names


def test_defaults_fill_missing_optional_parameters(tmp_path: Path):
    f = tmp_path / "m.yaml"
    f.write_text("root:\n  Explore: {max_idle_s: 2}\n")
    definition = load_tree(f)
    assert definition.root.params == {"max_idle_s": 2, "goal_tolerance": 0.3, "switch_distance": 0.5, "look_turns": 4,
                                      "spent_radius": 0.4, "spent_after_s": 0.5,
                                      "start_look_turns": 0, "push_through": True, "push_radius": 1.5,
                                      "push_m": 0.6, "push_s": 6.0, "stall_s": 8.0,
                                      "squeeze": True}


def test_user_behaviour_by_import_path(tmp_path: Path):
    f = tmp_path / "m.yaml"
    f.write_text("root:\n  Sequence:\n    children:\n      - hiconav.trees.behaviours.mission:Stop: {reason: x}\n")
    root, _ = build_tree(f)
    assert type(root.children[0]).__name__ == "Stop"


def test_unknown_tree_name_is_an_error():
    with pytest.raises(TreeError):
        load_tree("no_such_mission_anywhere")
