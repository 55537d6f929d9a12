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
    f.write_text("root:\n  Sequence:\n    children:\n      - Stop: {}\n      - Explore: {max_idle_s: 2}\n")
    definition = load_tree(f)
    assert definition.root.children[0].params == {"reason": "mission complete"}
    # a settings field is a node parameter only where the tree sets it: the rest are the mission's
    assert definition.root.children[1].params == {"max_idle_s": 2}


def test_a_node_reads_its_settings_section_and_its_own_overrides(tmp_path: Path):
    from hiconav.decisions.config import DecisionsConfig, ExploreSettings
    from hiconav.trees.context import MissionContext

    f = tmp_path / "m.yaml"
    f.write_text("root:\n  Explore: {max_idle_s: 2}\n")
    root, _ = build_tree(f)
    ctx = MissionContext("find the bed", clock=lambda: 0.0,
                         decisions=DecisionsConfig(explore=ExploreSettings(look_turns=7, max_idle_s=9.0)))
    root.setup(context=ctx)
    assert root.param("look_turns") == 7  # the mission's decisions.explore
    assert root.param("max_idle_s") == 2  # the tree's own value for this node
    assert root.settings.max_idle_s == 2 and root.settings.look_turns == 7


def test_a_settings_override_in_a_tree_is_checked_against_the_field(tmp_path: Path):
    f = tmp_path / "m.yaml"
    f.write_text("root:\n  Approach:\n    distance: 9.0\n")
    with pytest.raises(TreeError, match="above the maximum 5.0") as info:
        load_tree(f)
    assert info.value.line == 3


def test_user_behaviour_by_import_path(tmp_path: Path):
    f = tmp_path / "m.yaml"
    f.write_text("root:\n  Sequence:\n    children:\n      - hiconav.trees.behaviours.mission:Stop: {reason: x}\n")
    root, _ = build_tree(f)
    assert type(root.children[0]).__name__ == "Stop"


def test_unknown_tree_name_is_an_error():
    with pytest.raises(TreeError):
        load_tree("no_such_mission_anywhere")


def test_a_list_setting_override_checks_each_item(tmp_path: Path):
    f = tmp_path / "m.yaml"
    f.write_text("root:\n  Approach:\n    settle_rings: [1.0, wide]\n")
    with pytest.raises(TreeError, match=r"settle_rings: item 1: expected float") as info:
        load_tree(f)
    assert info.value.line == 3
    f.write_text("root:\n  Approach:\n    settle_rings: [1.0, 1.4]\n")
    assert load_tree(f).root.params == {"settle_rings": [1.0, 1.4]}
