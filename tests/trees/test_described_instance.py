"""For a described instance the reasoning layer decides: label matches propose nothing (issue #27)."""

from __future__ import annotations

from types import SimpleNamespace

from hiconav.trees import MissionContext
from hiconav.types import Pose2D, TaskSpec

from .fakes import obj, world


def _ctx(task: TaskSpec, **kw) -> MissionContext:
    ctx = MissionContext(instruction=task.instruction, clock=lambda: 0.0, **kw)
    ctx.task = task
    ctx.world = world(Pose2D(0.0, 0.0, 0.0), [obj(1, "armchair", 2.0, 0.0, n_obs=5), obj(2, "armchair", 6.0, 0.0)])
    return ctx


DESCRIBED = TaskSpec("the armchair next to the floor lamp", ("armchair",), ("floor_lamp",),
                     relations=(("armchair", "next to", "floor_lamp"),))
PLAIN = TaskSpec("find the armchair", ("armchair",))


def test_a_label_match_proposes_an_object_goal_but_not_a_described_instance():
    assert [c.object_id for c in _ctx(PLAIN).candidates()] == [1, 2]
    assert _ctx(DESCRIBED).described and _ctx(DESCRIBED).candidates() == []


def test_only_the_reasoning_verdict_proposes_the_described_instance():
    ctx = _ctx(DESCRIBED)
    ctx.hypotheses.append(SimpleNamespace(object_id=2, confidence=0.9, anchor_id=0, bbox=(0, 0, 1, 1)))
    assert [(c.object_id, c.source) for c in ctx.candidates()] == [(2, "hypothesis")]


def test_without_reasoning_labels_decide_again():
    assert [c.object_id for c in _ctx(DESCRIBED, reasoning=False).candidates()] == [1, 2]
