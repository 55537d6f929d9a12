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


def test_durations_are_robot_time_and_the_stepped_clock_takes_them_at_a_fifth():
    """A discrete action takes a robot 0.5 s and the stepped clock one 0.1 s tick: the defaults,
    stated in robot time, give the simulator the clock seconds the figures were tuned with (15 s
    of no frontier = 150 actions), and a robot the same 150 actions' worth (75 s)."""
    from types import SimpleNamespace

    from hiconav.decisions.config import ApproachSettings, DecisionsConfig, VerifySettings, robot_time_fields
    from hiconav.mission import stepped_time_scale

    robot = DecisionsConfig()
    stepped = robot.in_clock(stepped_time_scale(SimpleNamespace(driver=10.0, control=10.0), "discrete"))
    assert robot.explore.max_idle_s == 75.0 and stepped.explore.max_idle_s == 15.0
    assert (stepped.explore.spent_after_s, stepped.explore.push_s, stepped.explore.stall_s) == (0.5, 6.0, 8.0)
    assert (stepped.verify.timeout_s, stepped.verify.defer_s, stepped.verify.stall_s) == (60.0, 30.0, 6.0)
    assert (stepped.verify.keyframe_every_s, stepped.verify.keyframe_window_s) == (1.0, 2.0)
    assert (stepped.approach.timeout_s, stepped.approach.defer_s, stepped.approach.creep_s,
            stepped.approach.stall_s) == (120.0, 30.0, 3.0, 6.0)
    assert (stepped.parse.timeout_s, stepped.return_home.timeout_s) == (60.0, 300.0)
    # compared with the frames' own stamps, which are robot time already
    assert "recent_view_s" not in robot_time_fields(VerifySettings)
    assert stepped.verify.recent_view_s == robot.verify.recent_view_s
    # lengths, counts and angles are no time
    assert stepped.approach.distance == robot.approach.distance and stepped.verify.glance_deg == 35.0
    assert robot_time_fields(ApproachSettings) == {"timeout_s", "defer_s", "creep_s", "stall_s"}
    assert robot.in_clock(1.0) is robot  # a robot's clock is robot time


def test_a_duration_a_tree_sets_for_one_node_is_robot_time_too(tmp_path):
    from hiconav.decisions.config import DecisionsConfig
    from hiconav.trees import MissionContext
    from hiconav.trees.mission_tree import MissionTree

    f = tmp_path / "m.yaml"
    f.write_text("root:\n  Explore:\n    max_idle_s: 20.0\n    look_turns: 6\n")
    for scale, idle in ((0.2, 4.0), (1.0, 20.0)):
        ctx = MissionContext(instruction="", clock=lambda: 0.0, decisions=DecisionsConfig().in_clock(scale),
                             time_scale=scale)
        tree = MissionTree(f, ctx)
        explore = next(n for n in tree.root.iterate() if n.name == "Explore")
        assert explore.param("max_idle_s") == pytest.approx(idle) and explore.settings.max_idle_s == pytest.approx(idle)
        assert explore.param("look_turns") == 6  # a count is no time
        assert explore.param("stall_s") == pytest.approx(40.0 * scale)  # the mission's, on its clock
