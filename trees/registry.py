"""The behaviour registry: every node type a mission YAML file may name, with its parameters.

A node type is a ``NodeSpec``: the py_trees class (or a factory), its kind (``leaf``,
``composite`` with ``children:``, ``decorator`` with ``child:``) and a declaration of its
parameters (``Param``: type, default or required, range, choices, whether a ``{key}``
blackboard reference is allowed). The builder (``trees/builder.py``) validates YAML against these
declarations. Users add behaviours with ``@register_behaviour`` or by import path
(``package.module:Class``, the class must carry ``PARAMS``). This module does not build trees.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from hiconav.registry import Registry

REQUIRED: Any = object()  # sentinel: the parameter has no default

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

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

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


def register_behaviour(name: str | None = None) -> Callable[[type], type]:
    """Class decorator registering a leaf behaviour (a ``MissionBehaviour`` subclass) by name.

    The class declares ``PARAMS: dict[str, Param]``; it is built as
    ``cls(name=..., params=..., origin=...)``.
    """

    def decorator(cls: type) -> type:
        key = name or cls.__name__
        BEHAVIOURS.add(key, NodeSpec(key, "leaf", cls, dict(getattr(cls, "PARAMS", {})),
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
        return NodeSpec(name, "leaf", item, dict(getattr(item, "PARAMS", {})), (item.__doc__ or "").strip())
    from hiconav.errors import ConfigError

    raise ConfigError(f"{name!r} is not a behaviour class", field=field)
