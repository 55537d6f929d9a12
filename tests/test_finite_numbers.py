"""Every float setting, robot-profile field and behaviour parameter is finite; rates and timeouts bounded.

The parametrised cases are generated from the models and the behaviour registry, so a float added
later is covered without touching this file.
"""

from __future__ import annotations

import math
import types
from pathlib import Path
from typing import Any, Union, get_args, get_origin

import pytest
from pydantic import BaseModel

from hiconav.errors import ConfigError
from hiconav.limits import MAX_DURATION_S, MAX_RATE_HZ
from hiconav.settings import AREAS, area_model, load_settings_file, parse_set_options, resolve
from hiconav.trees import TreeError, load_tree
from hiconav.trees.registry import BEHAVIOURS, NodeSpec, Param, spec_for
from hiconav.drivers.profiles import RobotProfile, load_profile


def _is_float(annotation: Any) -> bool:
    if annotation is float:
        return True
    return get_origin(annotation) in (Union, types.UnionType) and float in get_args(annotation)


def _submodel(annotation: Any) -> type[BaseModel] | None:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    models = [a for a in get_args(annotation) if isinstance(a, type) and issubclass(a, BaseModel)]
    return models[0] if len(models) == 1 else None


def float_fields(model: type[BaseModel], prefix: str) -> list[str]:
    """Dotted paths of every float field of ``model`` and its sub-models."""
    out = []
    for name, info in model.model_fields.items():
        sub = _submodel(info.annotation)
        if sub is not None:
            out += float_fields(sub, f"{prefix}.{name}")
        elif _is_float(info.annotation):
            out.append(f"{prefix}.{name}")
    return out


def nested_yaml(path: str, value: str) -> str:
    parts = path.split(".")
    return "".join("  " * i + f"{p}:\n" for i, p in enumerate(parts[:-1])) + "  " * (len(parts) - 1) + \
        f"{parts[-1]}: {value}\n"


SETTINGS_FLOATS = [p for area in AREAS for p in float_fields(area_model(area), area)]
PROFILE_FLOATS = [p.partition(".")[2] for p in float_fields(RobotProfile, "robot")]


def test_the_models_have_float_fields_to_check() -> None:
    assert len(SETTINGS_FLOATS) > 50 and "mission.rates.control" in SETTINGS_FLOATS
    assert "failsafe.link_timeout_s" in PROFILE_FLOATS


# -- settings -----------------------------------------------------------------------------------
@pytest.mark.parametrize("path", SETTINGS_FLOATS)
@pytest.mark.parametrize("value", [".nan", ".inf", "-.inf"])
def test_a_float_setting_refuses_nan_and_infinity(tmp_path: Path, path: str, value: str) -> None:
    file = tmp_path / "settings.yaml"
    file.write_text(nested_yaml(path, value))
    with pytest.raises(ConfigError, match="finite number") as info:
        load_settings_file(file)
    assert f"{file}:{path.count('.') + 1} [{path}]" in str(info.value)


def test_an_infinite_control_rate_from_set_is_refused() -> None:
    with pytest.raises(ConfigError, match=r"\[mission.rates.control\]: Input should be a finite number"):
        resolve(None, ["mission.rates.control=.inf"])


@pytest.mark.parametrize("name", ["driver", "perception", "memory", "reasoning", "exploration", "mission",
                                  "control"])
def test_a_rate_above_the_bound_is_refused(name: str) -> None:
    resolve(None, [f"mission.rates.{name}={MAX_RATE_HZ}"])
    with pytest.raises(ConfigError, match=f"less than or equal to {MAX_RATE_HZ:g}"):
        resolve(None, [f"mission.rates.{name}={MAX_RATE_HZ + 1}"])


@pytest.mark.parametrize("path", [
    "mission.max_time_s", "mission.vlm_latency_s", "mission.parse_latency_s", "reasoning.vlm.timeout_s",
    "reasoning.vlm.connect_timeout_s", "reasoning.vlm.backoff_s", "reasoning.vlm.backoff_max_s",
    "reasoning.max_latency_s", "memory.prune_time_limit_s", "exploration.ordering.time_limit",
    "planning.back_off_s", "planning.stuck_time_s",
])
def test_a_timeout_longer_than_a_day_is_refused(path: str) -> None:
    resolve(None, [f"{path}={MAX_DURATION_S}"])
    with pytest.raises(ConfigError, match=f"less than or equal to {MAX_DURATION_S:g}") as info:
        resolve(None, [f"{path}={MAX_DURATION_S * 2}"])
    assert info.value.field == path


def test_set_values_go_through_the_same_loader() -> None:
    with pytest.raises(ConfigError, match=r"--set memory.tau: .*recursive alias \*x"):
        parse_set_options(["memory.tau=&x [*x]"])
    with pytest.raises(ConfigError, match=r"--set memory.tau: .*duplicate key 'a'"):
        parse_set_options(["memory.tau={a: 1, a: 2}"])


# -- robot profiles -------------------------------------------------------------------------------
@pytest.mark.parametrize("path", PROFILE_FLOATS)
def test_a_float_profile_field_refuses_nan(tmp_path: Path, path: str) -> None:
    file = tmp_path / "robot.yaml"
    file.write_text("name: r\n" + nested_yaml(path, ".nan"))
    with pytest.raises(ConfigError, match="finite number") as info:
        load_profile(file)
    assert info.value.field == path and info.value.line == path.count(".") + 2


@pytest.mark.parametrize("path", ["failsafe.link_timeout_s", "failsafe.heartbeat_timeout_s",
                                  "failsafe.pose_timeout_s", "failsafe.command_timeout_s",
                                  "mavlink.heartbeat_wait_s", "mavlink.ack_timeout_s"])
def test_a_profile_timeout_longer_than_a_day_is_refused(tmp_path: Path, path: str) -> None:
    file = tmp_path / "robot.yaml"
    file.write_text("name: r\n" + nested_yaml(path, str(MAX_DURATION_S + 1)))
    with pytest.raises(ConfigError, match="less than or equal to") as info:
        load_profile(file)
    assert info.value.field == path


def test_a_profile_goes_through_the_same_loader(tmp_path: Path) -> None:
    file = tmp_path / "robot.yaml"
    file.write_text("name: r\nlimits:\n  max_linear: 0.5\n  max_linear: 0.6\n")
    with pytest.raises(ConfigError, match="duplicate key 'max_linear'") as info:
        load_profile(file)
    assert f"{file}:4" in str(info.value)


# -- behaviour parameters -------------------------------------------------------------------------
def _behaviour_floats() -> list[tuple[str, str]]:
    spec_for("Sequence")  # registers the built-in behaviours
    out = []
    for name in BEHAVIOURS.names():
        spec = BEHAVIOURS.get(name)
        if isinstance(spec, NodeSpec):
            out += [(name, key) for key, p in spec.params.items() if p.type is float]
    return out


BEHAVIOUR_FLOATS = _behaviour_floats()


def test_there_are_behaviour_floats_to_check() -> None:
    assert ("Timeout", "duration") in BEHAVIOUR_FLOATS and ("Explore", "max_idle_s") in BEHAVIOUR_FLOATS


@pytest.mark.parametrize(("behaviour", "key"), BEHAVIOUR_FLOATS)
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_a_float_behaviour_parameter_refuses_nan_and_infinity(behaviour: str, key: str, value: float) -> None:
    assert "not a finite number" in BEHAVIOURS.get(behaviour).params[key].check(value)


def test_a_nan_parameter_in_a_mission_file_names_its_line(tmp_path: Path) -> None:
    file = tmp_path / "mission.yaml"
    file.write_text("root:\n  Sequence:\n    children:\n      - Explore:\n          max_idle_s: .nan\n")
    with pytest.raises(TreeError, match=r"Explore.max_idle_s: nan is not a finite number") as info:
        load_tree(file)
    assert f"{file}:5 [max_idle_s]" in str(info.value)


def test_a_timeout_decorator_longer_than_a_day_is_refused(tmp_path: Path) -> None:
    file = tmp_path / "mission.yaml"
    file.write_text(f"root:\n  Timeout:\n    duration: {MAX_DURATION_S * 2}\n    child:\n      Stop: {{}}\n")
    with pytest.raises(TreeError, match="above the maximum") as info:
        load_tree(file)
    assert info.value.line == 3


def test_a_parameter_may_declare_that_it_takes_infinity() -> None:
    assert Param(float, 1.0, finite=False).check(math.inf) is None
    assert Param(float, 1.0).check(math.inf) == "inf is not a finite number"
