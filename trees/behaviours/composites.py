"""py_trees composites and decorators registered for mission YAML, with declared parameters.

Sequence / Selector (``memory`` flag), Parallel (``policy: all|one``, ``synchronise``), Retry,
Timeout (on the mission clock, so it counts virtual seconds in stepped mode), Repeat, Inverter,
SuccessIsRunning, FailureIsSuccess, RunningIsFailure. Composite parameters are constructor
arguments, so they must be literals (no ``{key}``).
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import py_trees
from hiconav.limits import MAX_DURATION_S
from hiconav.trees.registry import BEHAVIOURS, NodeSpec, Param

Status = py_trees.common.Status


class ClockTimeout(py_trees.decorators.Timeout):
    """py_trees' Timeout on the mission clock (``context.now()``; wall monotonic without a context)."""

    def setup(self, **kwargs: Any) -> None:
        ctx = kwargs.get("context")
        self._now = ctx.now if ctx is not None else time.monotonic

    def _clock(self) -> float:
        return getattr(self, "_now", time.monotonic)()

    def initialise(self) -> None:
        self.finish_time = self._clock() + self.duration
        self.feedback_message = ""

    def update(self) -> Status:
        if self.decorated.status == Status.RUNNING and self._clock() > self.finish_time:
            self.feedback_message = "timed out"
            self.decorated.stop(Status.INVALID)
            return Status.FAILURE
        return self.decorated.status


def _literal(**params: Param) -> dict[str, Param]:
    return {k: dataclasses.replace(p, blackboard=False) for k, p in params.items()}


_POLICIES = {"all": py_trees.common.ParallelPolicy.SuccessOnAll, "one": py_trees.common.ParallelPolicy.SuccessOnOne}

_COMPOSITES = {
    "Sequence": (lambda n, c, p: py_trees.composites.Sequence(n, memory=p["memory"], children=c),
                 _literal(memory=Param(bool, True, doc="resume at the running child"))),
    "Selector": (lambda n, c, p: py_trees.composites.Selector(n, memory=p["memory"], children=c),
                 _literal(memory=Param(bool, False, doc="lock in a running lower priority"))),
    "Parallel": (lambda n, c, p: py_trees.composites.Parallel(
                     n, policy=_POLICIES[p["policy"]](synchronise=p["synchronise"]) if p["policy"] == "all"
                     else _POLICIES[p["policy"]](), children=c),
                 _literal(policy=Param(str, "all", choices=("all", "one")), synchronise=Param(bool, True))),
}
_DECORATORS = {
    "Retry": (lambda n, c, p: py_trees.decorators.Retry(n, c, num_failures=p["num_failures"]),
              _literal(num_failures=Param(int, minimum=1, maximum=1000))),
    "Timeout": (lambda n, c, p: ClockTimeout(n, c, duration=float(p["duration"])),
                _literal(duration=Param(float, minimum=1e-3, maximum=MAX_DURATION_S,
                                                doc="seconds on the mission clock"))),
    "Repeat": (lambda n, c, p: py_trees.decorators.Repeat(n, c, num_success=p["num_success"]),
               _literal(num_success=Param(int, minimum=1, maximum=100000))),
    "Inverter": (lambda n, c, p: py_trees.decorators.Inverter(n, c), {}),
    "SuccessIsRunning": (lambda n, c, p: py_trees.decorators.SuccessIsRunning(n, c), {}),
    "FailureIsSuccess": (lambda n, c, p: py_trees.decorators.FailureIsSuccess(n, c), {}),
    "RunningIsFailure": (lambda n, c, p: py_trees.decorators.RunningIsFailure(n, c), {}),
}

for _name, (_factory, _params) in _COMPOSITES.items():
    BEHAVIOURS.add(_name, NodeSpec(_name, "composite", _factory, _params))
for _name, (_factory, _params) in _DECORATORS.items():
    BEHAVIOURS.add(_name, NodeSpec(_name, "decorator", _factory, _params))
BEHAVIOURS.add("Subtree", NodeSpec("Subtree", "include", lambda *a: None,
                                   {"tree": Param(str, blackboard=False)}, "include another mission tree by name"))
