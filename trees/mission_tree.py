"""MissionTree: a built mission tree bound to one MissionContext and one blackboard namespace.

The Mission actor owns exactly one MissionTree and ticks it at its rate. Blackboard defaults from
the YAML file (``blackboard:``) and the caller's overrides (e.g. ``instruction``) are written under
the mission's own namespace, so two missions in one process never see each other's keys.
``setup`` is done node by node (py_trees' ``trees.setup`` installs a signal handler, which only
works on the main thread; the Mission actor runs on its own thread). No threads, no actors here.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import py_trees
from hiconav.trees.builder import TreeDefinition, build_tree
from hiconav.trees.context import MissionContext

_COUNTER = itertools.count()


class MissionTree:
    """Build, set up and tick one mission tree over a ``MissionContext``."""

    def __init__(self, source: str | Path | TreeDefinition, context: MissionContext,
                 blackboard: dict[str, Any] | None = None) -> None:
        root, self.definition = build_tree(source)
        if context.namespace == "/mission":
            context.namespace = f"/mission_{next(_COUNTER)}"
        self.context = context
        self.tree = py_trees.trees.BehaviourTree(root)
        self._writer = py_trees.blackboard.Client(name="mission", namespace=context.namespace)
        values = dict(self.definition.blackboard)
        if context.instruction:
            values["instruction"] = context.instruction
        values.update(blackboard or {})
        for key, value in values.items():
            self._writer.register_key(key=key, access=py_trees.common.Access.WRITE)
            self._writer.set(key, value, overwrite=True)
        for node in self.tree.root.iterate():
            node.setup(context=context)
        self.ticks = 0

    @property
    def root(self) -> py_trees.behaviour.Behaviour:
        return self.tree.root

    @property
    def status(self) -> py_trees.common.Status:
        return self.tree.root.status

    def tick(self) -> py_trees.common.Status:
        """Tick once (never blocks: every behaviour polls the context)."""
        self.tree.tick()
        self.ticks += 1
        return self.tree.root.status

    def tip_name(self) -> str:
        tip = self.tree.root.tip()
        return "" if tip is None else tip.name

    def ascii(self) -> str:
        return py_trees.display.unicode_tree(self.tree.root, show_status=True)

    def stop(self) -> None:
        """Preempt whatever runs (terminate(INVALID) all the way down) and release the blackboard."""
        if self.tree.root.status == py_trees.common.Status.RUNNING:
            self.tree.root.stop(py_trees.common.Status.INVALID)
        self.tree.shutdown()
        for key in list(py_trees.blackboard.Blackboard.keys()):
            if key.startswith(self.context.namespace + "/"):
                py_trees.blackboard.Blackboard.unset(key)
        self._writer.unregister(clear=True)
