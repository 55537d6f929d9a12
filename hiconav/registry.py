"""One registry per kind of pluggable part (detectors, reasoners, WTRP solvers, drivers, behaviours).

Parts register themselves by name with ``@REGISTRY.register("name")``; config refers to them by
that name, or by an import path ``package.module:Class`` for user extensions.
"""

from __future__ import annotations

import importlib
from typing import Any, Callable, Generic, TypeVar

from hiconav.errors import ConfigError

T = TypeVar("T")


class Registry(Generic[T]):
    """Name -> factory map for one kind of part."""

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self._items: dict[str, T] = {}

    def register(self, name: str) -> Callable[[T], T]:
        def decorator(item: T) -> T:
            if name in self._items and self._items[name] is not item:
                raise ValueError(f"{self.kind} {name!r} registered twice")
            self._items[name] = item
            return item

        return decorator

    def add(self, name: str, item: T) -> None:
        self.register(name)(item)

    def get(self, name: str, *, field: str | None = None) -> T:
        if name in self._items:
            return self._items[name]
        if ":" in name:  # user extension by import path
            module_name, _, attr = name.partition(":")
            try:
                return getattr(importlib.import_module(module_name), attr)
            except (ImportError, AttributeError) as exc:
                raise ConfigError(f"cannot import {self.kind} {name!r}: {exc}", field=field) from exc
        known = ", ".join(sorted(self._items)) or "(none)"
        raise ConfigError(f"unknown {self.kind} {name!r}; known: {known}", field=field)

    def names(self) -> list[str]:
        return sorted(self._items)

    def __contains__(self, name: object) -> bool:
        return name in self._items

    def items(self) -> list[tuple[str, Any]]:
        return sorted(self._items.items())
