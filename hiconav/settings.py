"""Typed settings for a whole mission: one section per layer, loaded from YAML and validated.

Each layer owns its settings model (``hiconav/<area>/config.py``); this module only assembles
them under their section names, loads a user's YAML file on top of the defaults, and reports
every mistake with the file, the line and the dotted field (``mission.yaml:12 [memory.tau]``).
Unknown keys are errors, not silently ignored: a typo in a robot's config must not fall back to
a default unnoticed. The result is a dict of dotted overrides that ``hiconav.mission`` and
``hiconav eval`` apply (the same form as ``--set area.key=value``).
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any, get_args, get_origin

import yaml
from pydantic import BaseModel, ValidationError

from hiconav import yamlio
from hiconav.errors import ConfigError

#: section name -> "module:Model" of the layer that owns it
AREAS: dict[str, str] = {
    "sim": "hiconav.sim.config:SimConfig",
    "perception": "hiconav.perception.config:PerceptionConfig",
    "mapping": "hiconav.mapping.config:MappingConfig",
    "planning": "hiconav.planning.config:NavigatorConfig",
    "memory": "hiconav.memory.config:MemoryConfig",
    "exploration": "hiconav.exploration.config:ExplorationConfig",
    "reasoning": "hiconav.reasoning.config:ReasoningConfig",
    "mission": "hiconav.mission:MissionConfig",
    "decisions": "hiconav.decisions.config:DecisionsConfig",
}

#: shipped as package data of ``hiconav.config`` (the top-level config/ folder in a checkout)
DEFAULT_FILE = Path(importlib.import_module("hiconav.config").__file__).resolve().parent / "default.yaml"


def area_model(area: str) -> type[BaseModel]:
    """The settings model of one section."""
    if area not in AREAS:
        raise ConfigError(f"unknown settings section {area!r}; known: {', '.join(AREAS)}", field=area)
    module, _, name = AREAS[area].partition(":")
    return getattr(importlib.import_module(module), name)


def _submodel(annotation: Any) -> type[BaseModel] | None:
    """The BaseModel class behind a field annotation (``Sub``, ``Sub | None``), else None."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    if get_origin(annotation) is not None:
        models = [a for a in get_args(annotation) if isinstance(a, type) and issubclass(a, BaseModel)]
        if len(models) == 1:
            return models[0]
    return None


def _line_index(node: yaml.Node, prefix: str, out: dict[str, int]) -> None:
    """Dotted key path -> 1-based line, from a composed YAML mapping node."""
    if not isinstance(node, yaml.MappingNode):
        return
    for key_node, value_node in node.value:
        key = f"{prefix}.{key_node.value}" if prefix else str(key_node.value)
        out[key] = key_node.start_mark.line + 1
        _line_index(value_node, key, out)


def flatten(model: type[BaseModel], values: dict[str, Any], prefix: str, *, source: str,
            lines: dict[str, int]) -> dict[str, Any]:
    """Dotted overrides from a nested dict, checking every key against ``model``'s fields."""
    out: dict[str, Any] = {}
    for key, value in values.items():
        path = f"{prefix}.{key}"
        if key not in model.model_fields:
            known = ", ".join(model.model_fields)
            raise ConfigError(f"unknown setting {key!r}; known here: {known}", file=source,
                              line=lines.get(path), field=path)
        sub = _submodel(model.model_fields[key].annotation)
        if sub is not None and isinstance(value, dict):
            out.update(flatten(sub, value, path, source=source, lines=lines))
        else:
            out[path] = value
    return out


def nest(overrides: dict[str, Any]) -> dict[str, Any]:
    """``{"a.b": 1}`` -> ``{"a": {"b": 1}}`` (a fresh dict; the input is not modified)."""
    out: dict[str, Any] = {}
    for path, value in overrides.items():
        node = out
        parts = path.split(".")
        for part in parts[:-1]:
            child = node.setdefault(part, {})
            if not isinstance(child, dict):
                raise ConfigError(f"override {path!r} conflicts with a value at {part!r}", field=path)
            node = child
        node[parts[-1]] = value
    return out


def validate(overrides: dict[str, Any], *, source: str = "<settings>",
             lines: dict[str, int] | None = None) -> dict[str, BaseModel]:
    """Build every section's model with ``overrides`` applied; errors name file, line and field."""
    lines = lines or {}
    nested = nest(overrides)
    unknown = [a for a in nested if a not in AREAS]
    if unknown:
        raise ConfigError(f"unknown settings section {unknown[0]!r}; known: {', '.join(AREAS)}",
                          file=source, line=lines.get(unknown[0]), field=unknown[0])
    models: dict[str, BaseModel] = {}
    for area in AREAS:
        model = area_model(area)
        values = nested.get(area, {})
        flatten(model, values, area, source=source, lines=lines)  # unknown keys -> ConfigError
        try:
            models[area] = model.model_validate(_merge(model().model_dump(), values))
        except ValidationError as exc:
            err = exc.errors()[0]
            path = ".".join([area, *(str(p) for p in err["loc"])])
            near = path
            while near and near not in lines:
                near = near.rpartition(".")[0]
            raise ConfigError(f"{err['msg']} (got {err.get('input')!r})", file=source,
                              line=lines.get(near), field=path) from exc
    return models


def _merge(base: dict[str, Any], extra: dict[str, Any]) -> dict[str, Any]:
    out = dict(base)
    for k, v in extra.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def load_settings_file(path: str | Path) -> dict[str, Any]:
    """Read a settings YAML file into dotted overrides, validated against every section's model."""
    path = Path(path)
    source = str(path)
    data, node = yamlio.load_file(path, what="settings file")
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError("a settings file is a mapping of sections (sim, memory, ...)", file=source, line=1)
    lines: dict[str, int] = {}
    _line_index(node, "", lines)
    overrides: dict[str, Any] = {}
    for area, values in data.items():
        if area not in AREAS:
            raise ConfigError(f"unknown settings section {area!r}; known: {', '.join(AREAS)}", file=source,
                              line=lines.get(str(area)), field=str(area))
        if not isinstance(values, dict):
            raise ConfigError("a section holds a mapping of settings", file=source,
                              line=lines.get(area), field=area)
        overrides.update(flatten(area_model(area), values, area, source=source, lines=lines))
    validate(overrides, source=source, lines=lines)
    return overrides


def parse_set_options(items: list[str]) -> dict[str, Any]:
    """``--set area.key=value`` options (values parsed as YAML) into dotted overrides."""
    overrides: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or "." not in key:
            raise ConfigError(f"--set expects area.key=value, got {item!r}", field="--set")
        try:
            overrides[key] = yamlio.load_text(value, source="--set", field=key)[0]
        except ConfigError as exc:
            reason = exc.reason if exc.reason.startswith("not valid YAML") else f"not valid YAML: {exc.reason}"
            raise ConfigError(f"--set {key}: {reason}", field=key) from None
    return overrides


def resolve(config_file: str | Path | None, set_options: list[str]) -> dict[str, Any]:
    """The dotted overrides of a run: the settings file (if any), then ``--set`` on top; validated."""
    overrides = load_settings_file(config_file) if config_file else {}
    extra = parse_set_options(set_options)
    if extra:
        for key in extra:
            area, _, rest = key.partition(".")
            flatten(area_model(area), nest({rest: extra[key]}), area, source="--set", lines={})
        overrides.update(extra)
        validate(overrides, source="--set")
    return overrides


def effective_settings(overrides: dict[str, Any] | None = None) -> dict[str, Any]:
    """Every section with defaults and overrides applied, as plain data (for printing)."""
    models = validate(dict(overrides or {}))
    return {area: model.model_dump(mode="json") for area, model in models.items()}


def field_bounds(info: Any) -> tuple[float | None, float | None]:
    """A pydantic field's inclusive range (``ge``, ``le``), None where it has none."""
    lo = next((m.ge for m in info.metadata if getattr(m, "ge", None) is not None), None)
    hi = next((m.le for m in info.metadata if getattr(m, "le", None) is not None), None)
    return lo, hi


def describe_settings(overrides: dict[str, Any] | None = None) -> list[str]:
    """One line per documented setting (a field with a description), every section:
    ``area.key = value  [min, max]  reason``; the value is the effective one."""
    models = validate(dict(overrides or {}))
    out: list[str] = []

    def walk(model: BaseModel, prefix: str) -> None:
        for key, info in type(model).model_fields.items():
            value = getattr(model, key)
            if isinstance(value, BaseModel):
                walk(value, f"{prefix}.{key}")
                continue
            if not info.description:
                continue
            lo, hi = field_bounds(info)
            bounds = f"  [{'' if lo is None else lo}, {'' if hi is None else hi}]" if lo is not None or hi is not None \
                else ""
            out.append(f"{prefix}.{key} = {value!r}{bounds}  {info.description}")

    for area, model in models.items():
        walk(model, area)
    return out
