"""Presets: the ablation group, unknown names, overrides merged with --set, dotted -> nested."""

from __future__ import annotations

import pytest

from hiconav.errors import ConfigError
from hiconav.eval.presets import PRESETS, nest, overrides_for, resolve_presets


def test_ablations_expands_to_every_preset_with_full_first() -> None:
    assert resolve_presets("ablations") == list(PRESETS)
    assert resolve_presets(["no_vis,full", "no_vis"]) == ["no_vis", "full"]


def test_unknown_preset_names_the_known_ones() -> None:
    with pytest.raises(ConfigError, match="known: full"):
        resolve_presets("fast")


def test_each_ablation_changes_something_and_full_changes_nothing() -> None:
    assert overrides_for("full") == {}
    assert all(PRESETS[name] for name in PRESETS if name != "full")
    assert overrides_for("no_vis", {"mission.verify": False}) == {"exploration.utility.use_vis": False,
                                                                  "mission.verify": False}


def test_presets_name_real_exploration_settings() -> None:
    from hiconav.exploration.config import ExplorationConfig

    for overrides in PRESETS.values():
        tree = nest(overrides).get("exploration")
        if tree:
            ExplorationConfig.model_validate(tree)  # extra="forbid": a wrong key fails here


def test_nest_builds_nested_dicts_and_rejects_conflicts() -> None:
    assert nest({"a.b.c": 1, "a.d": 2}) == {"a": {"b": {"c": 1}, "d": 2}}
    with pytest.raises(ConfigError):
        nest({"a": 1, "a.b": 2})
