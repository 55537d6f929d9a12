"""Base class of the mission behaviours: parameters (literal or ``{key}``), context, blackboard.

A ``MissionBehaviour`` receives its validated parameters from the YAML builder and the mission's
``MissionContext`` in ``setup(context=...)``. ``param(key)`` returns the literal, or reads the
blackboard for a ``{key}`` parameter and checks its type against the declaration, naming the
YAML file:line on a mismatch. Subclasses do their work in ``update()`` and return quickly; they
must never block a tick (no waiting on futures, no sleeping).
"""

from __future__ import annotations

from typing import Any

import py_trees
from hiconav.decisions.config import robot_time_fields
from hiconav.trees.builder import BlackboardRef
from hiconav.trees.context import MissionContext
from hiconav.trees.errors import BlackboardError, TreeError
from hiconav.trees.registry import Param, behaviour_params

Status = py_trees.common.Status


class MissionBehaviour(py_trees.behaviour.Behaviour):
    """A leaf of a mission tree; ``PARAMS`` declares its YAML parameters, ``WRITES`` its outputs."""

    PARAMS: dict[str, Param] = {}
    #: the ``decisions.<section>`` settings this behaviour reads (None: none); each of their fields
    #: is also a parameter a mission tree may set for this node (``param(key)``)
    SETTINGS: str | None = None
    WRITES: tuple[str, ...] = ()
    READS: tuple[str, ...] = ()

    def __init__(self, name: str, params: dict[str, Any] | None = None, origin: dict[str, str] | None = None):
        super().__init__(name)
        given = dict(params or {})
        for key, decl in self.PARAMS.items():
            if key not in given and not decl.required:
                given[key] = decl.default
        self._params = given
        self._origin = dict(origin or {})
        self.ctx: MissionContext | None = None
        self.bb: Any = None
        self.terminations: list[Status] = []  # every terminate() status, for tests and the report

    # -- life cycle ------------------------------------------------------------------------------
    def setup(self, **kwargs: Any) -> None:
        ctx = kwargs.get("context")
        if not isinstance(ctx, MissionContext):
            raise TreeError(f"{type(self).__name__} {self.name!r} needs setup(context=MissionContext)")
        self.ctx = ctx
        self.bb = self.attach_blackboard_client(name=self.name, namespace=ctx.namespace)
        keys = {v.key for v in self._params.values() if isinstance(v, BlackboardRef)} | set(self.READS)
        for key in sorted(keys - set(self.WRITES)):
            self.bb.register_key(key=key, access=py_trees.common.Access.READ)
        for key in self.WRITES:
            self.bb.register_key(key=key, access=py_trees.common.Access.WRITE)

    def tick(self) -> Any:
        """py_trees' tick, with the context told which behaviour acts (``MissionContext.acting``):
        the goals sent from ``initialise`` and ``update`` name it as their source."""
        if self.ctx is not None:
            self.ctx.acting = type(self).__name__
        yield from super().tick()

    def terminate(self, new_status: Status) -> None:
        self.terminations.append(new_status)
        self.cleanup(new_status)

    def cleanup(self, new_status: Status) -> None:
        """Undo what ``initialise`` started (cancel goals...); called on success, failure and preemption."""

    # -- parameters ------------------------------------------------------------------------------
    def param(self, key: str) -> Any:
        """The node's value of ``key``: its YAML literal, the blackboard entry it names, or, for a
        settings field the tree does not set, the mission's ``decisions.<SETTINGS>.<key>``."""
        if key not in self._params and self.SETTINGS is not None:
            return getattr(getattr(self.context.decisions, self.SETTINGS), key)
        value = self._params[key]
        if not isinstance(value, BlackboardRef):
            return self._on_clock(key, value)
        where = self._origin.get(key, "?")
        file, _, line = where.rpartition(":")
        if self.bb is None or not self.bb.exists(value.key):
            raise BlackboardError(f"{type(self).__name__}.{key} reads blackboard key {value.key!r}, which is not set",
                                  file=file or None, line=int(line) if line.isdigit() else None, field=key)
        got = self.bb.get(value.key)
        problem = behaviour_params(type(self))[key].check(got)
        if problem is not None:
            raise BlackboardError(f"{type(self).__name__}.{key} from blackboard key {value.key!r}: {problem}",
                                  file=file or None, line=int(line) if line.isdigit() else None, field=key)
        return self._on_clock(key, got)

    def _on_clock(self, key: str, value: Any) -> Any:
        """A duration of this node's settings section that the tree sets (robot time) on the
        mission's clock (``MissionContext.time_scale``); any other value as it is."""
        if self.SETTINGS is None or self.ctx is None or self.ctx.time_scale == 1.0:
            return value
        section = type(getattr(self.ctx.decisions, self.SETTINGS))
        if key in robot_time_fields(section) and isinstance(value, (int, float)) and not isinstance(value, bool):
            return value * self.ctx.time_scale
        return value

    @property
    def settings(self) -> Any:
        """This node's ``decisions.<SETTINGS>`` section: the mission's, with what the tree sets for
        this node applied (blackboard references read now)."""
        section = getattr(self.context.decisions, self.SETTINGS)
        own = {k: self.param(k) for k in self._params if k in type(section).model_fields}
        return section.model_copy(update=own) if own else section

    def write(self, key: str, value: Any) -> None:
        self.bb.set(key, value, overwrite=True)

    def read(self, key: str, default: Any = None) -> Any:
        return self.bb.get(key) if self.bb.exists(key) else default

    @property
    def context(self) -> MissionContext:
        assert self.ctx is not None, "setup(context=...) was not called"
        return self.ctx
