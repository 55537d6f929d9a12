"""Errors of the mission-tree layer.

``TreeError`` is a ``ConfigError`` that always names the YAML file, the line and the key that is
wrong, so that a user can fix a mission file without reading a traceback. This module must not
import py_trees or anything heavy.
"""

from __future__ import annotations

from hiconav.errors import ConfigError


class TreeError(ConfigError):
    """A mission tree that cannot be built: unknown behaviour, bad parameter, bad structure, cycle."""


class BlackboardError(ConfigError):
    """A ``{key}`` parameter whose blackboard value is missing or has the wrong type at tick time."""
