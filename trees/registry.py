"""The behaviour registry: every node type a mission YAML file may name, with its parameters.

A node type is a ``NodeSpec``: the py_trees class (or a factory), its kind (``leaf``,
``composite`` with ``children:``, ``decorator`` with ``child:``) and a declaration of its
parameters (``Param``: type, default or required, range, choices, whether a ``{key}``
blackboard reference is allowed). The builder (``trees/builder.py``) validates YAML against these
declarations. Users add behaviours with ``@register_behaviour`` or by import path
(``package.module:Class``, the class must carry ``PARAMS``). This module does not build trees.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from hiconav.registry import Registry

REQUIRED: Any = object()  # sentinel: the parameter has no default
#: sentinel default: the value comes from the mission's ``decisions.<section>`` settings at tick time
FROM_SETTINGS: Any = object()

#: ``{key}`` (BehaviorTree.CPP's blackboard-port syntax): the value is read from the mission's
#: blackboard at tick time instead of being a literal.
BLACKBOARD_REF = re.compile(r"^\{([A-Za-z_][A-Za-z0-9_./]*)\}$")


@dataclass(frozen=True)
class Param:
    """Declaration of one parameter of a node type.

    ``type`` is one of bool, int, float, str, list; ints are accepted where floats are expected.
    ``minimum``/``maximum`` are inclusive bounds for numbers; ``choices`` limits strings.
    ``blackboard``: whether the YAML may give ``{key}`` instead of a literal.
    ``finite``: a float must be a finite number (``.nan`` and ``.inf`` are refused) unless False.
    """

    type: type
    default: Any = REQUIRED
    minimum: float | None = None
    maximum: float | None = None
    choices: tuple[Any, ...] | None = None
    blackboard: bool = True
    doc: str = ""
    finite: bool = True
    items: type | None = None  # a list's element type (float: finite numbers within the bounds)

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    @property
    def from_settings(self) -> bool:
        return self.default is FROM_SETTINGS

    def check(self, value: Any) -> str | None:
        """Return why ``value`` is not acceptable, or None when it is."""
        expected = self.type
        if expected is float:
            ok = isinstance(value, (int, float)) and not isinstance(value, bool)
        elif expected is int:
            ok = isinstance(value, int) and not isinstance(value, bool)
        else:
            ok = isinstance(value, expected)
        if not ok:
            return f"expected {expected.__name__}, got {type(value).__name__} {value!r}"
        if expected is list and self.items is not None:
            for i, item in enumerate(value):
                problem = Param(self.items, minimum=self.minimum, maximum=self.maximum, finite=self.finite).check(item)
                if problem is not None:
                    return f"item {i}: {problem}"
            return None
        if expected is float and self.finite and not math.isfinite(value):
            return f"{value!r} is not a finite number"
        if self.minimum is not None and value < self.minimum:
            return f"{value!r} is below the minimum {self.minimum}"
        if self.maximum is not None and value > self.maximum:
            return f"{value!r} is above the maximum {self.maximum}"
        if self.choices is not None and value not in self.choices:
            return f"{value!r} is not one of {list(self.choices)}"
        return None


@dataclass(frozen=True)
class NodeSpec:
    """One registered node type.

    ``factory(name, children_or_child, params: dict, origin: dict[str, str])`` builds the
    py_trees behaviour; ``kind`` is "leaf", "composite" or "decorator".
    """

    name: str
    kind: str
    factory: Callable[..., Any]
    params: dict[str, Param] = field(default_factory=dict)
    doc: str = ""


BEHAVIOURS: Registry[NodeSpec] = Registry("behaviour")


@functools.lru_cache(maxsize=None)
def _settings_params(section: str) -> tuple[tuple[str, Param], ...]:
    return tuple(_field_params(section).items())


def settings_params(section: str | None) -> dict[str, Param]:
    """One ``Param`` per field of the ``decisions.<section>`` settings (see ``_field_params``),
    built once per section: a node's blackboard parameter is checked against it at tick time."""
    return dict(_settings_params(section)) if section else {}


def _field_params(section: str) -> dict[str, Param]:
    """One ``Param`` per field of the ``decisions.<section>`` settings (type, range, reason), with
    the ``FROM_SETTINGS`` default: a mission tree may override a field for one node, checked
    against the field's own declaration, and a node that does not reads the mission's settings."""
    from typing import Literal, get_args, get_origin

    from hiconav.decisions.config import DecisionsConfig
    from hiconav.settings import field_bounds

    model = DecisionsConfig.model_fields[section].annotation
    out: dict[str, Param] = {}
    for key, info in model.model_fields.items():  # type: ignore[union-attr]
        annotation, choices, items = info.annotation, None, None
        if get_origin(annotation) is Literal:
            choices = get_args(annotation)
            annotation = type(choices[0])
        elif get_origin(annotation) is list:
            items = (get_args(annotation) or (None,))[0]
            annotation = list
        lo, hi = field_bounds(info)
        out[key] = Param(annotation, FROM_SETTINGS, minimum=lo, maximum=hi, choices=choices, items=items,
                         doc=f"{info.description} (default: decisions.{section}.{key})")
    return out


def behaviour_params(cls: type) -> dict[str, Param]:
    """A behaviour class's YAML parameters: its own ``PARAMS`` and its settings section's fields."""
    return {**settings_params(getattr(cls, "SETTINGS", None)), **dict(getattr(cls, "PARAMS", {}))}


def register_behaviour(name: str | None = None) -> Callable[[type], type]:
    """Class decorator registering a leaf behaviour (a ``MissionBehaviour`` subclass) by name.

    The class declares ``PARAMS: dict[str, Param]``; it is built as
    ``cls(name=..., params=..., origin=...)``.
    """

    def decorator(cls: type) -> type:
        key = name or cls.__name__
        BEHAVIOURS.add(key, NodeSpec(key, "leaf", cls, behaviour_params(cls),
                                     (cls.__doc__ or "").strip().splitlines()[0] if cls.__doc__ else ""))
        return cls

    return decorator


def spec_for(name: str, *, field: str | None = None) -> NodeSpec:
    """Look a node type up by registered name or ``package.module:Class`` import path.

    Raises ``ConfigError`` naming the known types when ``name`` is unknown.
    """
    import hiconav.trees.behaviours  # noqa: F401  (registers the built-in node types)

    item = BEHAVIOURS.get(name, field=field)
    if isinstance(item, NodeSpec):
        return item
    if isinstance(item, type):  # user extension by import path: a leaf behaviour class
        return NodeSpec(name, "leaf", item, behaviour_params(item), (item.__doc__ or "").strip())
    from hiconav.errors import ConfigError

    raise ConfigError(f"{name!r} is not a behaviour class", field=field)
