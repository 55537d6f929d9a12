"""decisions.*: every threshold of the mission's decisions has one typed home."""

from __future__ import annotations

from typing import get_origin

import pytest
from typer.testing import CliRunner

from hiconav.cli import app
from hiconav.decisions.config import DecisionsConfig
from hiconav.errors import ConfigError
from hiconav.settings import describe_settings, validate
from hiconav.trees.behaviours.base import MissionBehaviour
from hiconav.trees.registry import BEHAVIOURS, NodeSpec, spec_for


def _fields():
    for section, info in DecisionsConfig.model_fields.items():
        for key, field in info.annotation.model_fields.items():
            yield section, key, field


def test_every_decision_setting_has_a_reason_and_every_number_a_range():
    for section, key, field in _fields():
        assert field.description, f"decisions.{section}.{key} has no reason"
        if field.annotation in (int, float):
            bounds = {type(m).__name__ for m in field.metadata}
            assert {"Ge", "Le"} <= bounds, f"decisions.{section}.{key} has no range"


def test_mission_behaviours_declare_no_thresholds_of_their_own():
    """A behaviour's PARAMS are its inputs and choices (an instruction, a reason, an alert kind);
    every number it uses is a decisions.* field, overridable per node through the same field."""
    spec_for("Sequence")
    for name in BEHAVIOURS.names():
        spec = BEHAVIOURS.get(name)
        cls = spec.factory if isinstance(spec, NodeSpec) else None
        if not (isinstance(cls, type) and issubclass(cls, MissionBehaviour)):
            continue
        own = {k: p.type for k, p in cls.PARAMS.items()}
        assert all(t in (str, bool) for t in own.values()), f"{name} declares {own}"
        if cls.SETTINGS is not None:
            assert cls.SETTINGS in DecisionsConfig.model_fields
            assert all(p.from_settings for k, p in spec.params.items() if k not in own)


def test_a_decisions_override_is_validated_with_its_path():
    assert validate({"decisions.approach.distance": 0.9})["decisions"].approach.distance == 0.9
    with pytest.raises(ConfigError) as info:
        validate({"decisions.verify.min_detection_rate": 1.5})
    assert "decisions.verify.min_detection_rate" in str(info.value)


def test_config_describe_lists_each_setting_with_its_value_range_and_reason():
    lines = describe_settings({"decisions.approach.distance": 0.9})
    line = next(x for x in lines if x.startswith("decisions.approach.distance ="))
    assert line.startswith("decisions.approach.distance = 0.9  [0.1, 5.0]  stop this near")
    out = CliRunner().invoke(app, ["config", "--describe"]).output
    assert "decisions.explore.start_look_turns = 4  [0, 100]" in out
    assert all(f"decisions.{s}.{k} = " in out for s, k, f in _fields() if get_origin(f.annotation) is None)


def test_the_mission_actor_hands_its_decisions_to_the_tree():
    from hiconav.actors.mission import MissionNode
    from hiconav.decisions.config import ApproachSettings

    decisions = DecisionsConfig(approach=ApproachSettings(distance=0.7))
    node = MissionNode("objectnav", "find the bed", decisions=decisions)
    node.start(0.0)
    approach = next(b for b in node.tree.root.iterate() if type(b).__name__ == "Approach")
    assert approach.param("distance") == 0.7 and approach.settings.distance == 0.7
