"""Tree semantics over a MissionContext: preemption calls terminate(), clocks, rejection, blackboard."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from pathlib import Path

import py_trees
import pytest
from hiconav.decisions.config import DecisionsConfig, ExploreSettings
from hiconav.trees import BlackboardError, MissionContext
from hiconav.trees.mission_tree import MissionTree

from hiconav.messages import GoalMsg, KeyframeRequest, NavStatus, ParseRequest, StopRequest
from hiconav.types import Pose2D, TaskSpec

from .fakes import anchor, obj, plan, world

S = py_trees.common.Status


class Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def _write(tmp_path: Path, text: str) -> Path:
    f = tmp_path / "m.yaml"
    f.write_text(text)
    return f


# the tests look at one decision at a time: no look-around at the start unless a test asks for it
NO_START_LOOK = DecisionsConfig(explore=ExploreSettings(start_look_turns=0))
# the clocks here are the simulator's stepped clock, where a second of clock is five of robot time
# (one 0.1 s driver tick carries a 0.5 s discrete action), as the mission actor puts the settings
STEPPED = 0.2


def _ctx(clock: Clock, **kw) -> MissionContext:
    kw["decisions"] = kw.get("decisions", NO_START_LOOK).in_clock(STEPPED)
    ctx = MissionContext(instruction="find the bed", clock=clock, **kw)
    ctx.task = TaskSpec("find the bed", ("bed",))
    ctx.world = world(Pose2D(2.0, 2.0, 0.0))
    return ctx


def _confirmed_then(tmp_path: Path, ctx: MissionContext, leaf: str) -> MissionTree:
    """The tree TargetConfirmed -> ``leaf`` (one YAML line, e.g. "Approach: {distance: 0.8}")."""
    return MissionTree(_write(tmp_path, "root:\n  Sequence:\n    children:\n      - TargetConfirmed: {}\n"
                                        f"      - {leaf}\n"), ctx)


def _approach_bed(tmp_path: Path, pose: Pose2D) -> tuple[MissionContext, MissionTree, object]:
    """Approach (0.8 m) to a bed at (5, 5) from ``pose``: context, tree and the first goal sent."""
    ctx = _ctx(Clock())
    ctx.world = world(pose, [obj(3, "bed", 5.0, 5.0)])
    tree = _confirmed_then(tmp_path, ctx, "Approach: {distance: 0.8}")
    assert tree.tick() == S.RUNNING
    return ctx, tree, [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal


def _tick_while_running(tree: MissionTree, limit: int = 60) -> None:
    """Tick on the same clock time until the tree stops RUNNING (at most ``limit`` ticks)."""
    for _ in range(limit):
        if tree.tick() != S.RUNNING:
            return
    raise AssertionError(f"still running after {limit} ticks")


def _node(tree: MissionTree, name: str):
    return next(n for n in tree.root.iterate() if n.name == name)


FIND = """
root:
  Selector:
    name: find
    memory: false
    children:
      - TargetConfirmed: {}
      - Explore: {}
"""


def test_preemption_by_higher_priority_calls_terminate_and_cancels_the_goal(tmp_path):
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = plan((8.0, 8.0))
    tree = MissionTree(_write(tmp_path, FIND), ctx)
    assert tree.tick() == S.RUNNING
    explore = _node(tree, "Explore")
    goals = [m for m in ctx.outbox if isinstance(m, GoalMsg)]
    assert goals and goals[-1].goal is not None and goals[-1].goal.kind == "frontier"
    ctx.outbox.clear()
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(7, "bed", 5.0, 5.0)])
    assert tree.tick() == S.SUCCESS
    assert explore.terminations == [S.INVALID]
    assert [m.goal for m in ctx.outbox if isinstance(m, GoalMsg)] == [None]
    tree.stop()


def test_each_goal_names_the_behaviour_that_sent_it(tmp_path):
    """The control layer tallies its actions by the goal's source (``GoalMsg.source``)."""
    ctx = _ctx(Clock())
    ctx.plan = plan((8.0, 8.0))
    tree = MissionTree(_write(tmp_path, FIND), ctx)
    assert tree.tick() == S.RUNNING
    assert [m.source for m in ctx.outbox if isinstance(m, GoalMsg)] == ["Explore"]
    tree.stop()
    ctx, tree, _ = _approach_bed(tmp_path, Pose2D(2.0, 2.0, 0.0))
    assert [m.source for m in ctx.outbox if isinstance(m, GoalMsg)] == ["Approach"]
    tree.stop()


def test_stopping_a_running_tree_terminates_the_running_leaf(tmp_path):
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = plan((8.0, 8.0))
    tree = MissionTree(_write(tmp_path, FIND), ctx)
    tree.tick()
    explore = _node(tree, "Explore")
    tree.stop()
    assert explore.terminations == [S.INVALID]


def test_timeout_counts_mission_clock_seconds(tmp_path):
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = plan((8.0, 8.0))
    tree = MissionTree(_write(tmp_path, "root:\n  Timeout:\n    duration: 5\n    child:\n      Explore: {}\n"), ctx)
    assert tree.tick() == S.RUNNING
    clock.t = 4.9
    assert tree.tick() == S.RUNNING
    clock.t = 5.1
    assert tree.tick() == S.FAILURE
    assert _node(tree, "Explore").terminations == [S.INVALID]
    tree.stop()


def test_explore_fails_when_no_frontier_is_left(tmp_path):
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = plan()
    tree = MissionTree(_write(tmp_path, "root:\n  Explore: {max_idle_s: 3}\n"), ctx)
    assert tree.tick() == S.RUNNING
    clock.t = 3.5
    assert tree.tick() == S.FAILURE


def test_explored_out_search_of_a_described_instance_asks_the_reasoning_layer_first(tmp_path):
    from hiconav.messages import ExploredOut

    def explored_out(task: TaskSpec, **kw) -> tuple[list, list]:
        clock = Clock()
        ctx = _ctx(clock, **kw)
        ctx.task = task
        ctx.plan = plan()
        tree = MissionTree(_write(tmp_path, "root:\n  Explore: {max_idle_s: 3, unresolved_asks: 2}\n"), ctx)
        statuses = []
        for t in (0.0, 3.5, 7.0, 10.5, 14.0):
            clock.t = t
            statuses.append(tree.tick())
            if statuses[-1] == S.FAILURE:
                break
        return statuses, [m for m in ctx.outbox if isinstance(m, ExploredOut)]

    described = TaskSpec("the bed under the painting", ("bed",), ("painting",),
                         relations=(("bed", "under", "painting"),))
    statuses, asked = explored_out(described)
    assert statuses == [S.RUNNING, S.RUNNING, S.RUNNING, S.FAILURE] and len(asked) == 2
    # an object goal, or a described one without the reasoning layer: labels decide, nobody to ask
    for task, kw in ((TaskSpec("find the bed", ("bed",)), {}), (described, {"reasoning": False})):
        statuses, asked = explored_out(task, **kw)
        assert statuses == [S.RUNNING, S.FAILURE] and not asked


def test_explore_moves_on_when_a_frontier_is_unreachable(tmp_path):
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = plan((8.0, 8.0), (1.0, 8.0))
    tree = MissionTree(_write(tmp_path, "root:\n  Explore: {}\n"), ctx)
    tree.tick()
    first = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    ctx.nav = NavStatus(first.seq, "failed", 0.0)
    tree.tick()
    second = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    assert second.seq > first.seq and second.goal.ref_id == 1


def test_verify_rejects_a_vanished_candidate_and_retry_explores_again(tmp_path):
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = plan((8.0, 8.0))
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0)])
    text = """
root:
  Retry:
    num_failures: 3
    child:
      Sequence:
        name: locate
        children:
          - Selector:
              name: find
              memory: false
              children:
                - TargetConfirmed: {}
                - Explore: {}
          - VerifyTarget: {}
"""
    tree = MissionTree(_write(tmp_path, text), ctx)
    assert tree.tick() == S.RUNNING  # VerifyTarget going to the candidate
    assert _node(tree, "VerifyTarget").status == S.RUNNING
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [])  # the false positive disappears from memory
    assert tree.tick() == S.RUNNING  # Retry absorbs the failure
    assert 3 in ctx.rejected
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0)])
    tree.tick()
    assert _node(tree, "Explore").status == S.RUNNING  # rejected candidate no longer confirms


FACING_BED = Pose2D(4.0, 4.0, math.pi / 4)  # the bed at (5, 5) is straight ahead, 1.4 m away


def _verify_tree(tmp_path, clock: Clock, params: str, pose: Pose2D = FACING_BED):
    """A context with one bed node (seen by anchor 1) and TargetConfirmed -> VerifyTarget."""
    ctx = _ctx(clock)
    ctx.world = world(pose, [obj(3, "bed", 5.0, 5.0)], anchors=[anchor(1, pose, (3,))])
    tree = _confirmed_then(tmp_path, ctx, f"VerifyTarget: {{{params}}}")
    return ctx, tree


def _view(ctx, anchor_id: int, observed: bool, pose: Pose2D = FACING_BED, extra: tuple = ()) -> None:
    """A new memory anchor ``anchor_id`` taken at ``pose``; it observed the bed when ``observed``.
    ``extra``: other anchors in the snapshot (made between two ticks)."""
    anchors = [*extra, anchor(anchor_id, pose, (3,) if observed else ())]
    ctx.world = world(pose, [obj(3, "bed", 5.0, 5.0)], anchors=anchors)


def test_verify_confirms_with_fresh_views_when_close(tmp_path):
    ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2")
    assert tree.tick() == S.RUNNING  # the anchor from before does not count
    _view(ctx, 2, True)
    assert tree.tick() == S.RUNNING
    _view(ctx, 3, True)
    assert tree.tick() == S.SUCCESS


def test_verify_asks_the_memory_for_keyframes_while_it_judges(tmp_path):
    """Verification judges anchors; glancing from one spot crosses no anchor gate (eq. 2), so the
    verdict waited for frames that only a newly detected, often spurious, object would make (with
    a detector that made no spurious boxes, Gibson tune floors read 76.9% instead of 90.4%)."""
    clock = Clock()
    ctx, tree = _verify_tree(tmp_path, clock, "keyframe_every_s: 0.5, keyframe_window_s: 2.0")
    assert tree.tick() == S.RUNNING
    asked = [m for m in ctx.outbox if isinstance(m, KeyframeRequest)]
    assert len(asked) == 1 and asked[0].until == pytest.approx(2.0) and asked[0].every_s == 0.5
    ctx.outbox.clear()
    clock.t = 0.5
    tree.tick()
    assert not [m for m in ctx.outbox if isinstance(m, KeyframeRequest)]  # still covered
    clock.t = 1.5
    tree.tick()
    assert [m.until for m in ctx.outbox if isinstance(m, KeyframeRequest)] == [pytest.approx(3.5)]


def test_verify_asks_for_no_keyframes_before_it_judges(tmp_path):
    far = Pose2D(0.0, 0.0, 0.0)  # 7 m from the bed: going there, nothing judged yet
    ctx, tree = _verify_tree(tmp_path, Clock(), "", pose=far)
    assert tree.tick() == S.RUNNING
    assert not [m for m in ctx.outbox if isinstance(m, KeyframeRequest)]


def test_verify_hands_on_the_node_its_fresh_views_observed(tmp_path):
    """A table read as a sofa (#3), its box touching the real sofa's (#8): the fresh views saw #8,
    so the target written for Approach is #8, not the table (Gibson Marstons/0/1 stopped on the
    table's far side, 2.1 m from the sofa). Views of the candidate itself keep the candidate."""
    def verify(observed: tuple) -> object:
        ctx = _ctx(Clock())
        objects = [obj(3, "bed", 5.0, 5.0, n_obs=3), obj(8, "bed", 6.0, 5.0)]
        ctx.world = world(FACING_BED, objects, anchors=[anchor(1, FACING_BED, (3,))])
        tree = _confirmed_then(tmp_path, ctx, "VerifyTarget: {min_fresh_views: 2}")
        tree.tick()
        for aid in (2, 3):
            ctx.world = world(FACING_BED, objects, anchors=[anchor(aid, FACING_BED, observed)])
            status = tree.tick()
        assert status == S.SUCCESS
        return _node(tree, "VerifyTarget").read("target")

    assert verify((8,)).object_id == 8
    assert verify((3, 8)).object_id == 3
    assert verify((3,)).object_id == 3


def test_verify_counts_only_frames_that_read_the_candidate_as_a_target(tmp_path):
    """A node's label is a vote over its observations: a sofa read twice as "bed" stays a "bed"
    node while frames that read it "sofa" observe it. Those frames show something there, but a
    bed is confirmed only when more of them read "bed" than not (Gibson Woodbine/0/3 stopped at
    a sofa confirmed as a bed so); read as something else as often as not, the candidate is
    deferred until it is observed as the target again, not rejected."""
    def frames(reads: list[tuple]) -> tuple[list, MissionContext]:
        ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, max_view_frames: 4")
        tree.tick()
        statuses = []
        for aid, labels_seen in enumerate(reads, start=2):
            a = anchor(aid, FACING_BED, (3,), labels_seen=labels_seen)
            ctx.world = world(FACING_BED, [obj(3, "bed", 5.0, 5.0)], anchors=[a])
            statuses.append(tree.tick())
        return statuses, ctx

    statuses, ctx = frames([("sofa",)] * 4)
    assert statuses == [S.RUNNING] * 3 + [S.FAILURE]
    assert "0 of 4 fresh views" in ctx.rejections[-1][1] and 3 not in ctx.rejected and 3 in ctx.deferred_obs
    statuses, _ = frames([("bed",), ("sofa",), ("bed",)])  # 1 to 1 after two views: look on
    assert statuses == [S.RUNNING, S.RUNNING, S.SUCCESS]
    statuses, _ = frames([("sofa", "bed")] * 2)  # a bed detected in the frame
    assert statuses[-1] == S.SUCCESS


def test_verify_counts_a_detection_too_near_for_depth_as_a_fresh_view(tmp_path):
    """0.4 m from the bed's box the depth camera reads nothing, so the bed's detection lands on no
    node; the frame still detected a bed where the candidate is (Gibson Tolstoy/0/3 rejected a
    real toilet so). From 0.7 m, or where the frame placed its bed on another node, it does not count."""
    near = Pose2D(4.1, 5.0, 0.0)  # 0.4 m from the box's face, facing its centre

    def frames(pose, params, other=False):
        ctx, tree = _verify_tree(tmp_path, Clock(), params, pose)
        objects = [obj(3, "bed", 5.0, 5.0)] + ([obj(7, "bed", 9.0, 5.0)] if other else [])
        tree.tick()
        statuses = []
        for aid in range(2, 6):
            a = anchor(aid, pose, (7,) if other else (), labels_seen=("bed",))
            ctx.world = world(pose, objects, anchors=[a])
            statuses.append(tree.tick())
        return statuses, ctx

    params = "min_fresh_views: 2, max_view_frames: 8, unseen_view_frames: 4, min_confidence: 0.0"
    statuses, _ = frames(near, params)
    assert statuses[:2] == [S.RUNNING, S.SUCCESS]
    statuses, ctx = frames(FACING_BED, params)  # 0.7 m from the box: depth reaches it, a miss
    assert statuses[-1] == S.FAILURE and "0 of 4 frames" in ctx.rejections[-1][1]
    statuses, ctx = frames(near, params, other=True)  # the frame's bed is node 7, 4 m off
    assert statuses[-1] == S.FAILURE and "0 of 4 frames" in ctx.rejections[-1][1]
    statuses, ctx = frames(near, params + ", near_view_distance: 0.0")
    assert statuses[-1] == S.FAILURE


def test_verify_rejects_a_candidate_rarely_detected_while_in_view(tmp_path):
    """A spurious box that fell on a place once is outvoted by the frames that show nothing there."""
    ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, max_view_frames: 10")
    tree.tick()
    for aid in range(2, 12):
        _view(ctx, aid, aid in (4, 9))  # two fresh views in ten frames: below the 50% detection rate
        status = tree.tick()
    assert status == S.FAILURE
    assert ctx.rejections and ctx.rejections[-1][0] == 3 and "2 of 10 frames" in ctx.rejections[-1][1]
    assert 3 in ctx.rejected


def test_verify_rejects_a_candidate_seen_in_none_of_the_first_frames_without_glancing_on(tmp_path):
    """A spurious box is not there again: 0 detections in ``unseen_view_frames`` frames in view
    rejects it at once, not after ``max_view_frames`` (glancing on cost Gibson Newfields/0/1 180
    of its 500 steps); one detection among them keeps the full test running."""
    ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, max_view_frames: 8, unseen_view_frames: 4")
    tree.tick()
    statuses = []
    for aid in range(2, 6):
        _view(ctx, aid, False)
        statuses.append(tree.tick())
    assert statuses == [S.RUNNING] * 3 + [S.FAILURE]
    assert "0 of 4 frames" in ctx.rejections[-1][1] and 3 in ctx.rejected
    ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, max_view_frames: 8, unseen_view_frames: 4")
    tree.tick()
    for aid in range(2, 9):
        _view(ctx, aid, aid == 3)
        assert tree.tick() == S.RUNNING  # 1 of up to 7 frames: still judged on the full 8
    _view(ctx, 9, False)
    assert tree.tick() == S.FAILURE and "1 of 8 frames" in ctx.rejections[-1][1]


def test_verify_does_not_count_frames_with_a_wall_between_camera_and_candidate(tmp_path):
    """Gibson Wainscott/0/2: a real plant behind a corner of a scanned wall was rejected as
    "detected in 0 of 8 frames in view"; a wall on the map (an occupied cell no memory object
    explains) between the camera and the candidate hides it like a memory object does."""
    from .fakes import open_grid

    walled = open_grid()
    walled.state[38:46, 42] = 1  # a wall stub across the line from (4, 4) to the bed at (5, 5)
    for grid, rejected in ((open_grid(), True), (walled, False)):
        ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, max_view_frames: 4, reposition_after: 100")
        tree.tick()
        for aid in range(2, 8):
            ctx.world = world(FACING_BED, [obj(3, "bed", 5.0, 5.0)], grid=grid, anchors=[anchor(aid, FACING_BED)])
            status = tree.tick()
        assert (status == S.FAILURE) == rejected
        assert any("0 of 4 frames" in why for _, why in ctx.rejections) == rejected


def test_verify_counts_a_frame_that_placed_the_candidate_whatever_the_walls_on_the_map(tmp_path):
    """The wall test keeps frames that could not show the candidate from counting as misses; a
    frame that placed a detection on the candidate's node showed it. Gibson Stockman/0/2 deferred
    a toilet placed on its node in 15 frames as "no view cell shows it", a wall cell on the map
    crossing the line to its centre."""
    from .fakes import open_grid

    walled = open_grid()
    walled.state[38:46, 42] = 1  # a wall stub across the line from (4, 4) to the bed at (5, 5)
    ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, reposition_after: 100")
    tree.tick()
    for aid in (2, 3):
        ctx.world = world(FACING_BED, [obj(3, "bed", 5.0, 5.0)], grid=walled, anchors=[anchor(aid, FACING_BED, (3,))])
        status = tree.tick()
    assert status == S.SUCCESS


def test_verify_counts_frames_over_low_clutter_but_not_through_walls(tmp_path):
    """Gibson Allensville/0/0: a sofa seen over an unlabelled 0.8 m table (occupied on the 2D map,
    explained by no memory object) was in view in none of 8 frames that observed it. With obstacle
    heights on the map, a camera sees the candidate's top over low clutter, not through a wall."""
    from .fakes import open_grid

    for top, counted in ((0.3, True), (np.inf, False), (0.0, False)):
        grid = open_grid()
        grid.state[38:46, 42] = 1  # occupied cells across the line from (4, 4) to the bed at (5, 5)
        grid.top = np.zeros(grid.state.shape, dtype=np.float32)
        grid.top[38:46, 42] = top  # 0: no height recorded, a wall as far as anyone knows
        ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, max_view_frames: 4, reposition_after: 100")
        tree.tick()
        for aid in range(2, 8):
            ctx.world = world(FACING_BED, [obj(3, "bed", 5.0, 5.0)], grid=grid, anchors=[anchor(aid, FACING_BED)])
            tree.tick()
        assert any("0 of 4 frames" in why for _, why in ctx.rejections) == counted, top


def test_verify_counts_only_frames_with_the_candidate_in_view(tmp_path):
    away = Pose2D(4.0, 4.0, math.pi)  # the bed is behind the robot
    ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, max_view_frames: 5", away)
    for aid in range(2, 20):
        _view(ctx, aid, False, away)
        assert tree.tick() == S.RUNNING  # not in view: neither confirmed nor rejected


def test_verify_judges_each_anchor_from_its_own_camera_and_ignores_pruning(tmp_path):
    """Frames are the memory's anchors, each judged from its own pose: two anchors made between
    ticks both count, one looking away does not, and a memory version bumped by pruning (no new
    anchor) is no frame. The version-based count read val/28/0's real fridge as 3 of 8."""
    ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, max_view_frames: 3")
    tree.tick()
    away = Pose2D(4.0, 4.0, math.pi)
    # anchor 2 looked away (the robot has turned back by the time the tick looks); 3 saw the bed
    _view(ctx, 3, True, FACING_BED, extra=(anchor(2, away),))
    assert tree.tick() == S.RUNNING
    for version in range(5, 15):  # pruning moves the version: no new anchor, no frame
        ctx.world = world(FACING_BED, [obj(3, "bed", 5.0, 5.0)], anchors=[anchor(3, FACING_BED, (3,))],
                          version=version)
        assert tree.tick() == S.RUNNING
    _view(ctx, 4, True)
    assert tree.tick() == S.SUCCESS


def test_approach_sends_a_free_cell_within_distance_facing_the_target(tmp_path):
    ctx, tree, goal = _approach_bed(tmp_path, Pose2D(1.5, 1.5, 0.0))
    assert goal.kind == "approach"
    dx = max(4.5 - goal.x, 0, goal.x - 5.5)
    dy = max(4.5 - goal.y, 0, goal.y - 5.5)
    assert math.hypot(dx, dy) <= 0.8
    assert abs(goal.yaw - math.atan2(5.0 - goal.y, 5.0 - goal.x)) < 1e-9
    ctx.world = world(Pose2D(goal.x, goal.y, goal.yaw), [obj(3, "bed", 5.0, 5.0)])
    assert tree.tick() == S.SUCCESS


def test_parse_instruction_reads_the_blackboard_and_waits_for_the_task(tmp_path):
    clock = Clock()
    ctx = MissionContext(instruction="", clock=clock)
    tree = MissionTree(_write(tmp_path, "root:\n  ParseInstruction: {instruction: '{goal_text}'}\n"), ctx,
                       blackboard={"goal_text": "find the sofa"})
    assert tree.tick() == S.RUNNING
    assert [m.instruction for m in ctx.outbox if isinstance(m, ParseRequest)] == ["find the sofa"]
    assert tree.tick() == S.RUNNING
    ctx.task = TaskSpec("find the sofa", ("sofa",))
    assert tree.tick() == S.SUCCESS
    tree.stop()


def test_blackboard_value_of_the_wrong_type_names_file_and_line(tmp_path):
    ctx = MissionContext(instruction="", clock=Clock(), decisions=NO_START_LOOK)
    f = _write(tmp_path, "root:\n  Explore:\n    max_idle_s: '{patience}'\n")
    tree = MissionTree(f, ctx, blackboard={"patience": "long"})
    ctx.plan = plan()
    with pytest.raises(BlackboardError, match=f"{f}:3"):
        tree.tick()


def test_missions_do_not_share_blackboards(tmp_path):
    f = _write(tmp_path, "root:\n  ParseInstruction: {}\n")
    a = MissionContext(instruction="", clock=Clock())
    b = MissionContext(instruction="", clock=Clock())
    ta = MissionTree(f, a, blackboard={"instruction": "find the bed"})
    tb = MissionTree(f, b, blackboard={"instruction": "find the tv"})
    ta.tick()
    tb.tick()
    assert a.outbox[0].instruction == "find the bed" and b.outbox[0].instruction == "find the tv"
    ta.stop()
    tb.stop()


def test_stop_requests_the_stop_action_once(tmp_path):
    ctx = _ctx(Clock())
    tree = MissionTree(_write(tmp_path, "root:\n  Stop: {}\n"), ctx)
    assert tree.tick() == S.SUCCESS
    tree.tick()
    assert len([m for m in ctx.outbox if isinstance(m, StopRequest)]) == 1


def test_find_and_return_goes_home_on_a_health_alert():
    from hiconav.messages import HealthAlert

    clock = Clock()
    ctx = _ctx(clock)
    ctx.start_pose = Pose2D(1.0, 1.0, 0.0)
    ctx.plan = plan((8.0, 8.0))
    tree = MissionTree("find_and_return", ctx)
    tree.tick()
    tree.tick()
    explore = _node(tree, "Explore")
    assert explore.status == S.RUNNING
    ctx.alerts.append(HealthAlert("battery", "battery at 10%"))
    tree.tick()
    assert explore.terminations[-1] == S.INVALID
    assert _node(tree, "ReturnToStart").status == S.RUNNING
    tree.stop()


def test_a_retried_explore_fails_at_once_when_the_map_is_explored_out(tmp_path):
    """The idle clock belongs to the mission: the Retry above Explore must not make the robot idle
    (and turn around) for max_idle_s again on every retry once no frontier is left."""
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = plan()
    tree = MissionTree(_write(tmp_path, "root:\n  Retry:\n    num_failures: 50\n    child:\n"
                                        "      Explore: {max_idle_s: 3}\n"), ctx)
    assert tree.tick() == S.RUNNING
    clock.t = 3.5
    _tick_while_running(tree)
    assert tree.root.status == S.FAILURE and clock.t == 3.5  # no simulated time spent idling again


def test_an_unreachable_candidate_is_deferred_by_approach_so_exploration_goes_on(tmp_path):
    """'No reachable approach cell' used to end the mission; now the candidate waits defer_s."""
    import numpy as np

    from .fakes import FakeGrid

    clock = Clock()
    ctx = _ctx(clock)
    state = np.full((100, 100), -1, dtype=np.int8)  # nothing known near the bed
    state[10:30, 10:30] = 0
    grid = FakeGrid(state, np.zeros_like(state, dtype=bool))
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 8.0, 8.0)], grid=grid)
    tree = _confirmed_then(tmp_path, ctx, "Approach: {distance: 0.8, defer_s: 30}")
    assert tree.tick() == S.FAILURE
    assert ctx.excluded(3) and 3 not in ctx.rejected  # deferred, not rejected for good
    assert "approach" in ctx.rejections[-1][1]
    clock.t = 31.0
    assert not ctx.excluded(3)


def _plan_at(stamp: float, *frontiers: tuple[int, tuple[float, float]]):
    """A plan made at ``stamp`` with frontiers (id, viewpoint), in WTRP order."""
    from dataclasses import replace

    import numpy as np
    from hiconav.mapping.frontiers import Frontier

    fs = tuple(Frontier(i, np.array(p), np.array(p), 10) for i, p in frontiers)
    return replace(plan(), plan=type(plan((0.0, 0.0)).plan)(fs[0], tuple(f.id for f in fs)), frontiers=fs,
                   stamp=stamp)


def _reach_first_frontier(tmp_path):
    """Explore over frontiers 0 at (8, 8) and 1 at (1, 8); the robot reaches 0 at t = 5 s."""
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = _plan_at(0.0, (0, (8.0, 8.0)), (1, (1.0, 8.0)))
    tree = MissionTree(_write(tmp_path, "root:\n  Explore: {}\n"), ctx)
    tree.tick()
    first = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    assert first.goal.ref_id == 0
    clock.t = 5.0
    ctx.nav = NavStatus(first.seq, "reached", 0.0)
    return clock, ctx, tree


def test_explore_skips_a_frontier_its_visit_did_not_clear_even_under_a_new_id(tmp_path):
    clock, ctx, tree = _reach_first_frontier(tmp_path)
    # a plan older than the visit does not decide: the frontier may still clear
    ctx.plan = _plan_at(4.0, (7, (8.1, 8.0)), (8, (1.0, 8.0)))
    tree.tick()
    assert ctx.spent_viewpoints == []
    # a plan made just after the visit does not decide either: the robot may still be turning
    ctx.plan = _plan_at(5.2, (7, (8.1, 8.0)), (8, (1.0, 8.0)))
    tree.tick()
    assert ctx.spent_viewpoints == []
    # a plan made spent_after_s after the visit still has a frontier there (renumbered): spent
    clock.t = 6.0
    ctx.plan = _plan_at(5.5, (9, (8.1, 8.0)), (10, (1.0, 8.0)))
    tree.tick()
    assert ctx.spent_viewpoints == [(8.0, 8.0)]
    last = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    assert last.goal.ref_id == 10
    # a retried Explore (a new instance) remembers it through the context
    tree2 = MissionTree(_write(tmp_path, "root:\n  Explore: {}\n"), ctx)
    ctx.plan = _plan_at(7.0, (11, (8.0, 8.2)), (12, (1.0, 8.0)))
    tree2.tick()
    assert [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal.ref_id == 12


def test_explore_does_not_spend_a_viewpoint_whose_frontier_cleared(tmp_path):
    clock, ctx, tree = _reach_first_frontier(tmp_path)
    tree.tick()
    clock.t = 6.0
    ctx.plan = _plan_at(5.6, (3, (9.5, 8.0)), (4, (1.0, 8.0)))  # the frontier moved on, 1.5 m
    tree.tick()
    assert ctx.spent_viewpoints == []
    assert [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal.ref_id == 3


def test_explore_goes_to_a_frontier_viewpoint_facing_the_frontier(tmp_path):
    from dataclasses import replace

    import numpy as np
    from hiconav.mapping.frontiers import Frontier

    clock = Clock()
    ctx = _ctx(clock)
    far = Frontier(0, np.array([8.0, 9.0]), np.array([8.0, 8.0]), 10)  # centroid 1 m north of the viewpoint
    near = Frontier(1, np.array([1.0, 8.05]), np.array([1.0, 8.0]), 10)
    base = plan((0.0, 0.0))
    ctx.plan = replace(base, plan=type(base.plan)(far, (0, 1)), frontiers=(far, near))
    tree = MissionTree(_write(tmp_path, "root:\n  Explore: {}\n"), ctx)
    tree.tick()
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert goal.ref_id == 0 and goal.yaw == pytest.approx(math.pi / 2)
    # a viewpoint on top of its centroid has no facing
    ctx.plan = replace(base, plan=type(base.plan)(near, (1,)), frontiers=(near,))
    tree.tick()
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert goal.ref_id == 1 and goal.yaw is None


def test_explore_looks_around_the_start_once_per_mission_before_any_frontier(tmp_path):
    """start_look_turns quarter turns come first; a preempted and retried Explore finishes them
    (the count is the mission's), then goes to the first frontier; they are never repeated."""
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = plan((8.0, 8.0))
    text = "root:\n  Explore: {start_look_turns: 4}\n"
    tree = MissionTree(_write(tmp_path, text), ctx)
    looks = []
    for turn in range(3):
        tree.tick()
        goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
        assert goal.goal.kind == "look"
        looks.append(goal.goal.yaw)
        ctx.nav = NavStatus(goal.seq, "reached", 0.0)
        ctx.world = world(Pose2D(2.0, 2.0, goal.goal.yaw))
    assert [math.cos(y) for y in looks] == pytest.approx([0.0, -1.0, 0.0], abs=1e-9)
    assert [math.sin(y) for y in looks] == pytest.approx([1.0, 0.0, -1.0], abs=1e-9)
    tree.stop()  # preempted (e.g. by a candidate) during the third quarter turn: it is redone
    tree2 = MissionTree(_write(tmp_path, text), ctx)
    for yaw in (0.0, math.pi / 2):  # the third again, then the fourth
        tree2.tick()
        goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
        assert goal.goal.kind == "look" and goal.goal.yaw == pytest.approx(yaw)
        ctx.nav = NavStatus(goal.seq, "reached", 0.0)
        ctx.world = world(Pose2D(2.0, 2.0, goal.goal.yaw))
    tree2.tick()
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert goal.kind == "frontier" and goal.ref_id == 0
    assert ctx.start_looks == 4
    tree3 = MissionTree(_write(tmp_path, text), ctx)  # a later retry goes straight to frontiers
    tree3.tick()
    assert [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal.kind == "frontier"


def test_look_around_turns_before_a_candidate_is_taken_and_explore_does_not_look_again(tmp_path):
    """A candidate seen in the first frame waits for the start look: the look shows the room all
    round first (the nearest candidate may stand behind the robot, and the map holds no view cell
    yet). The quarter turns are the mission's, so Explore goes to frontiers straight after."""
    ctx = _ctx(Clock(), decisions=DecisionsConfig(explore=ExploreSettings(start_look_turns=2)))
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 8.0, 5.0)])
    ctx.plan = plan((8.0, 8.0))
    tree = MissionTree(_write(tmp_path, "root:\n  Sequence:\n    memory: true\n    children:\n"
                                        "      - LookAround: {}\n      - Selector:\n          children:\n"
                                        "            - TargetConfirmed: {}\n            - Explore: {}\n"), ctx)
    yaws = []
    for _ in range(2):
        assert tree.tick() == S.RUNNING
        goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
        assert goal.goal.kind == "look" and goal.source == "LookAround"
        yaws.append(goal.goal.yaw)
        assert tree.tick() == S.RUNNING  # the turn in flight: no new goal
        assert [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].seq == goal.seq
        ctx.nav = NavStatus(goal.seq, "reached", 0.0)
        ctx.world = world(Pose2D(2.0, 2.0, goal.goal.yaw), [obj(3, "bed", 8.0, 5.0)])
    assert [math.cos(y) for y in yaws] == pytest.approx([0.0, -1.0], abs=1e-9)
    tree.tick()  # the look done: the candidate is taken
    assert ctx.start_looks == 2 and tree.root.children[1].status == S.SUCCESS


def test_approach_cell_prefers_the_front_of_an_objects_middle_over_its_near_end():
    """A painting 1 m long on a wall at x = 5: the plain nearest cell lies off its lower end (a
    grazing view, not a ground-truth view point); with the centre weight the cell faces its middle."""
    import numpy as np
    from hiconav.decisions.geometry import approach_cell

    from .fakes import open_grid

    grid = open_grid()
    grid.state[:, 51:] = 1  # the wall the painting hangs on
    grid.inflated[:, 49:] = True
    lo, hi = np.array([5.0, 4.0, 1.2]), np.array([5.05, 5.0, 1.8])
    robot = np.array([3.0, 2.0])
    plain = approach_cell(grid, lo, hi, robot, 0.8)
    centred = approach_cell(grid, lo, hi, robot, 0.8, centre_weight=1.0)
    assert plain[1] < 4.0  # off the end
    assert abs(centred[1] - 4.5) < 0.45 and centred[0] > 4.1  # in front of the middle, within 0.8 m


def test_approach_cell_judges_walls_at_the_cameras_height_when_told_it():
    """Gibson Leonardo/0/0: the robot stood 0.67 m from a sofa, but an unlabelled 0.8 m cabinet
    at the sofa's end lay on the line to its centre, so every cell there counted as behind a
    wall and it drove 1.2 m to the sofa's middle. With the camera's height (0.88 m) and the
    sofa's top (0.85 m) the cabinet hides nothing; a wall (no height recorded) still does."""
    import numpy as np
    from hiconav.decisions.geometry import approach_cell

    from .fakes import open_grid

    lo, hi = np.array([4.0, 2.0, 0.0]), np.array([5.0, 6.0, 0.85])  # the sofa, 4 m long
    robot = np.array([4.6, 6.7])  # 0.7 m past its end
    for top, stays in ((0.8, True), (0.0, False)):
        grid = open_grid()
        grid.state[61:64, 43:48] = 1  # 0.1-0.4 m past the sofa's end: a cabinet, or a wall
        grid.top = np.zeros(grid.state.shape, dtype=np.float32)
        grid.top[61:64, 43:48] = top
        cell = approach_cell(grid, lo, hi, robot, 0.75, furniture=[], centre_weight=0.9, strict_walls=True,
                             wall_heights=(0.88, 0.85))
        moved = cell is None or float(np.hypot(*(cell - robot))) > 0.3
        assert moved != stays, (top, cell)
        walls = approach_cell(grid, lo, hi, robot, 0.75, furniture=[], centre_weight=0.9, strict_walls=True)
        assert walls is None or float(np.hypot(*(walls - robot))) > 0.3  # without heights: a wall


def test_approach_cell_on_a_settle_ring_is_the_one_nearest_the_object():
    """Gibson: with no free cell within 0.8 m the robot settled on the 1 m ring at the cell nearest
    to itself, 0.96-1.06 m from the box, where the box's error decides success; with the box
    weight it takes the nearest free cell to the object (here 0.85 m out)."""
    import numpy as np
    from hiconav.decisions.geometry import approach_cell

    from .fakes import open_grid

    grid = open_grid()
    lo, hi = np.array([5.0, 5.0, 0.0]), np.array([5.5, 5.5, 0.9])
    # clutter round the object: the map has no free cell within 0.8 m of its box
    rows, cols = np.mgrid[0:100, 0:100]
    x, y = (cols + 0.5) * 0.1, (rows + 0.5) * 0.1
    dist = np.hypot(np.maximum(np.maximum(lo[0] - x, 0), x - hi[0]), np.maximum(np.maximum(lo[1] - y, 0), y - hi[1]))
    grid.inflated[dist <= 0.8] = True
    robot = np.array([2.0, 5.2])
    assert approach_cell(grid, lo, hi, robot, 0.8) is None
    plain = approach_cell(grid, lo, hi, robot, 1.0)
    near = approach_cell(grid, lo, hi, robot, 1.0, box_weight=4.0)
    def d(c):
        return float(np.hypot(max(lo[0] - c[0], 0, c[0] - hi[0]), max(lo[1] - c[1], 0, c[1] - hi[1])))
    assert d(plain) > 0.9  # the ring's edge, toward the robot
    assert d(near) < 0.87


def test_approach_is_not_done_on_passing_within_the_distance_off_the_target(tmp_path):
    """Done at the approach cell, not at the first point within the distance of the footprint."""
    ctx, tree, goal = _approach_bed(tmp_path, Pose2D(1.5, 1.5, 0.0))
    # a point 0.7 m off the bed's side, facing it, 0.8 m from the cell: not there yet
    passing = Pose2D(3.8, 4.9, math.atan2(0.1, 1.2))
    assert math.hypot(passing.x - goal.x, passing.y - goal.y) > 0.3
    ctx.world = world(passing, [obj(3, "bed", 5.0, 5.0)])
    assert tree.tick() == S.RUNNING
    ctx.world = world(Pose2D(goal.x, goal.y, goal.yaw), [obj(3, "bed", 5.0, 5.0)])
    assert tree.tick() == S.SUCCESS


def test_approach_settled_beyond_its_distance_creeps_through_unknown_floor_then_stops(tmp_path):
    """The camera sees no floor within ~1.4 m, so the floor by an object is often unknown and the
    robot settled 0.96 m from a plant's box (Gibson Ranchester/0/1); it creeps toward the box
    through the unknown cells, then faces it and stops."""
    import numpy as np

    from .fakes import open_grid

    grid = open_grid()
    rows, cols = np.mgrid[0:100, 0:100]
    x, y = (cols + 0.5) * 0.1, (rows + 0.5) * 0.1
    gap = np.hypot(np.maximum(np.maximum(4.5 - x, 0), x - 5.5), np.maximum(np.maximum(4.5 - y, 0), y - 5.5))
    grid.state[(gap > 0) & (gap <= 0.85)] = -1  # never seen: no approach cell within 0.8 m
    ctx = _ctx(Clock())
    ctx.world = world(Pose2D(2.0, 5.0, 0.0), [obj(3, "bed", 5.0, 5.0)], grid=grid)
    tree = _confirmed_then(tmp_path, ctx, "Approach: {distance: 0.8}")
    assert tree.tick() == S.RUNNING
    settle = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert not settle.through_unknown and 0.8 < 4.5 - settle.x <= 1.0
    ctx.world = world(Pose2D(settle.x, settle.y, 0.0), [obj(3, "bed", 5.0, 5.0)], grid=grid)
    assert tree.tick() == S.RUNNING  # not done: it creeps first
    creep = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    # straight at the box's nearest point, done within the distance of it (Wainscott/0/0: a point
    # 0.8 m short of the box, 0.05 m from the robot, was "reached" at once, 0.85 m from the box)
    assert creep.goal.through_unknown and creep.goal.straight
    assert creep.goal.x == pytest.approx(4.5) and creep.goal.tolerance == pytest.approx(0.8)
    ctx.world = world(Pose2D(3.75, settle.y, 0.0), [obj(3, "bed", 5.0, 5.0)], grid=grid)
    ctx.nav = NavStatus(creep.seq, "reached", 0.0)
    assert tree.tick() == S.RUNNING  # faces the object where it stands
    assert tree.tick() == S.SUCCESS


def test_approach_reached_short_of_its_ring_creeps_on_instead_of_driving_to_another_cell(tmp_path):
    """The navigator's 0.2 m tolerance stops the robot short of its cell: Gibson Allensville/0/0
    stood 1.02 m from a sofa's box at a cell of the 1 m ring, was not "within" it, and drove
    1.4 m to a second cell. It steps straight toward the box instead, then faces it."""
    ctx = _ctx(Clock())
    ctx.world = world(Pose2D(1.5, 5.0, 0.0), [obj(3, "bed", 5.0, 5.0)])
    tree = _confirmed_then(tmp_path, ctx, "Approach: {distance: 0.8, inner_margin: 0.05}")
    assert tree.tick() == S.RUNNING
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert goal.kind == "approach" and 0.7 <= 4.5 - goal.x <= 0.8  # the bed's box spans 4.5-5.5
    short = Pose2D(goal.x - 0.15, goal.y, 0.0)  # reached, within the tolerance, 0.85+ m off the box
    assert 4.5 - short.x > 0.8
    ctx.world = world(short, [obj(3, "bed", 5.0, 5.0)])
    ctx.nav = NavStatus([m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].seq, "reached", 0.0)
    assert tree.tick() == S.RUNNING
    creep = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    assert creep.goal.straight and creep.goal.x == pytest.approx(4.5) and creep.goal.tolerance == pytest.approx(0.8)
    ctx.world = world(Pose2D(short.x + 0.25, short.y, 0.0), [obj(3, "bed", 5.0, 5.0)])
    ctx.nav = NavStatus(creep.seq, "reached", 0.0)
    assert tree.tick() == S.RUNNING  # faces it
    assert tree.tick() == S.SUCCESS


def test_approach_a_step_beyond_its_ring_steps_straight_in_when_the_way_is_clear(tmp_path):
    """Verification leaves the robot ~1.15 m from the box facing it; the ring cell in front of
    the box's middle lay off the line in and cost a turn and a second step (Gibson: 31 of 89
    successes began the approach inside the success region and drove on). With the way clear it
    steps straight at the box's nearest point, done within the distance, then faces it."""
    ctx = _ctx(Clock())
    ctx.world = world(Pose2D(3.5, 4.7, 0.0), [obj(3, "bed", 5.0, 5.0)])  # 1.0 m off the box (4.5-5.5)
    tree = _confirmed_then(tmp_path, ctx, "Approach: {distance: 0.85, inner_margin: 0.0}")
    assert tree.tick() == S.RUNNING
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    assert goal.goal.straight and goal.goal.through_unknown
    assert (goal.goal.x, goal.goal.y) == pytest.approx((4.5, 4.7)) and goal.goal.tolerance == pytest.approx(0.85)
    assert "stepping in" in _node(tree, "Approach").feedback_message
    ctx.world = world(Pose2D(3.75, 4.7, 0.0), [obj(3, "bed", 5.0, 5.0)])
    ctx.nav = NavStatus(goal.seq, "reached", 0.0)
    assert tree.tick() == S.RUNNING  # faces it
    assert tree.tick() == S.SUCCESS


def test_approach_goes_to_a_ring_cell_when_the_straight_way_in_is_blocked_or_too_long(tmp_path):
    """A wall the map knows on the line in (or an object farther than a step or two beyond the
    ring, or straight_within 0) keeps the ring cells; a straight way in that ends short of the
    ring falls back to them too."""
    from .fakes import open_grid

    def first_goal(pose: Pose2D, grid=None, params: str = "distance: 0.85, inner_margin: 0.0"):
        ctx = _ctx(Clock())
        ctx.world = world(pose, [obj(3, "bed", 5.0, 5.0)], grid=grid)
        tree = _confirmed_then(tmp_path, ctx, f"Approach: {{{params}}}")
        assert tree.tick() == S.RUNNING
        return ctx, tree, [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]

    walled = open_grid()
    walled.state[44:50, 39] = 1  # a wall stub at x = 3.9-4.0 across the line y = 4.7
    walled.inflated = walled.state == 1
    assert not first_goal(Pose2D(3.5, 4.7, 0.0), walled)[2].goal.straight
    assert not first_goal(Pose2D(2.5, 4.7, 0.0))[2].goal.straight  # 2.0 m off: drive to a cell
    assert not first_goal(Pose2D(3.5, 4.7, 0.0), params="distance: 0.85, straight_within: 0.0")[2].goal.straight
    ctx, tree, goal = first_goal(Pose2D(3.5, 4.7, 0.0))
    assert goal.goal.straight
    ctx.nav = NavStatus(goal.seq, "failed", 0.0)  # blocked by what the map does not know, 1.0 m off
    assert tree.tick() == S.RUNNING
    after = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert after is not None and after.kind == "approach" and not after.straight


def test_approach_measures_to_the_objects_points_when_told_to(tmp_path):
    """ProcTHOR val/5/2: at a round plant's diagonal the robot judged itself 0.88 m from the
    plant's box (its corner) while the nearest of the plant's own points was 1.05 m off, and
    stopped 1.06 m from the plant. ``measure: points`` judges the distance by the points (their
    2% quantile): here 1.06 m, so the robot steps straight in toward the nearest point; by the
    box, 0.85 m, it is already within the 0.9 m ring and goes to a ring cell instead."""
    from dataclasses import replace as _replace

    angles = np.linspace(0.0, 2.0 * math.pi, 200, endpoint=False)
    circle = np.stack([5.0 + 0.5 * np.cos(angles), 5.0 + 0.5 * np.sin(angles), np.full(200, 0.4)], axis=1)
    plant = _replace(obj(3, "bed", 5.0, 5.0), points=circle)
    pose = Pose2D(3.9, 3.9, math.pi / 4)

    def first_goal(measure: str):
        ctx = _ctx(Clock())
        ctx.world = world(pose, [plant])
        tree = _confirmed_then(tmp_path, ctx, f"Approach: {{distance: 0.9, inner_margin: 0.0, measure: {measure}, corner_radius: 0.0}}")
        assert tree.tick() == S.RUNNING
        return _node(tree, "Approach"), [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal

    approach, goal = first_goal("points")
    gap, near = approach._gap(approach.read("target"))
    assert gap == pytest.approx(math.hypot(1.1, 1.1) - 0.5, abs=0.03)
    assert goal.straight and math.hypot(goal.x - 5.0, goal.y - 5.0) == pytest.approx(0.5, abs=1e-6)
    approach, goal = first_goal("box")
    assert approach._gap(approach.read("target"))[0] == pytest.approx(math.hypot(0.6, 0.6), abs=1e-9)
    assert not goal.straight and goal.kind == "approach"
    bare = obj(3, "bed", 5.0, 5.0)  # no points (a hand-made node): the box decides
    ctx = _ctx(Clock())
    ctx.world = world(pose, [bare])
    tree = _confirmed_then(tmp_path, ctx, "Approach: {distance: 0.9, measure: points, corner_radius: 0.0}")
    tree.tick()
    approach = _node(tree, "Approach")
    assert approach._gap(approach.read("target"))[0] == pytest.approx(math.hypot(0.6, 0.6), abs=1e-9)


def test_approach_counts_rocking_near_its_cell_as_a_stall(tmp_path):
    """Gibson Woodbine/0/1 (0.9 m ring): the robot rocked 0.2-0.45 m from an approach cell it never
    reached for 480 steps; VerifyTarget's 0.35 m "there, glancing" allowance kept the stall clock
    from running. Approach's cells are goals: after STALL_S without coming 0.25 m nearer it
    tries another cell."""
    ctx, tree, goal = _approach_bed(tmp_path, Pose2D(1.5, 1.5, 0.0))
    clock = ctx.clock
    near = [Pose2D(goal.x - 0.3, goal.y, 0.0), Pose2D(goal.x - 0.25, goal.y - 0.05, 0.0)]
    cells = set()
    for k in range(12):
        clock.t = float(k)
        ctx.world = world(near[k % 2], [obj(3, "bed", 5.0, 5.0)])
        assert tree.tick() == S.RUNNING
        cells.add(tuple(np.round(_node(tree, "Approach")._cell, 3)))
    assert len(cells) >= 2  # gave the first cell up and went for another


def test_label_matches_are_candidates_nearest_first():
    """Gibson Klickitat/0/3: ranked by confidence x observations, a plant seen five times 4 m off
    was verified before a real plant seen once 2.2 m off (5.75 m driven instead of 3.0).
    Verification judges each; the order only decides how far the robot drives to the first."""
    ctx = _ctx(Clock())
    far, near, other = obj(3, "bed", 8.0, 2.0, n_obs=9), obj(5, "bed", 4.5, 2.0, n_obs=1), obj(7, "sofa", 3.0, 2.0)
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [far, near, other])
    assert [c.object_id for c in ctx.candidates()] == [5, 3]
    ctx.world = world(Pose2D(9.0, 2.0, 0.0), [far, near, other])
    assert [c.object_id for c in ctx.candidates()] == [3, 5]


def test_verify_switches_on_the_way_to_a_candidate_that_shows_much_nearer(tmp_path):
    """Gibson Onaga/0/2: on its way to a plant 4.5 m off the robot saw another 3.0 m off and
    drove on (7.1 m; switching, 5.6 m). A candidate ``switch_margin`` nearer is verified
    first, the other neither rejected nor deferred; not once frames are being judged, and not
    for a smaller gain."""
    def run(new_x: float, pose: Pose2D = Pose2D(1.0, 5.0, 0.0), margin: float = 1.0):
        ctx = _ctx(Clock())
        ctx.world = world(pose, [obj(3, "bed", 8.0, 5.0)])
        tree = _confirmed_then(tmp_path, ctx, f"VerifyTarget: {{switch_margin: {margin}}}")
        assert tree.tick() == S.RUNNING
        ctx.world = world(pose, [obj(3, "bed", 8.0, 5.0), obj(5, "bed", new_x, 5.0)])
        assert tree.tick() == S.RUNNING
        return ctx, _node(tree, "VerifyTarget")

    ctx, verify = run(5.0)  # 3.5 m off against 6.5 m
    assert verify._cand.object_id == 5 and verify.read("target").object_id == 5
    assert not ctx.rejections and [c.object_id for c in ctx.candidates()] == [5, 3]
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert goal.x < 4.5  # a view cell of the nearer bed
    _, verify = run(6.0)  # 4.5 m off against 6.5 m: switches
    assert verify._cand.object_id == 5
    _, verify = run(7.3)  # 0.7 m nearer: stays
    assert verify._cand.object_id == 3
    _, verify = run(5.0, margin=0.0)  # never
    assert verify._cand.object_id == 3
    _, verify = run(7.0, pose=Pose2D(6.0, 5.0, 0.0))  # close to the first already: frames count, stays
    assert verify._cand.object_id == 3


def test_verify_switches_between_two_candidates_a_few_times_at_most(tmp_path):
    """Two candidates whose ways pass nearer each other in turn must not trade places for ever:
    after ``MAX_SWITCHES`` the behaviour keeps the one it has."""
    ctx = _ctx(Clock())
    beds = [obj(3, "bed", 8.0, 5.0), obj(5, "bed", 1.0, 5.0)]
    ctx.world = world(Pose2D(3.0, 5.0, 0.0), beds[:1])
    tree = _confirmed_then(tmp_path, ctx, "VerifyTarget: {switch_margin: 1.0}")
    tree.tick()
    verify = _node(tree, "VerifyTarget")
    ids = []
    for x in (2.0, 7.0, 2.0, 7.0, 2.0, 7.0):  # the robot nears one bed, then the other
        ctx.world = world(Pose2D(x, 2.0, 0.0), beds)
        tree.tick()
        ids.append(verify._cand.object_id)
    assert ids[:3] == [5, 3, 5] and set(ids[3:]) == {5}


def test_verify_judges_on_a_candidate_whose_label_flipped_while_it_looks_and_leaves_a_look_alike(tmp_path):
    """A toilet observed twice, once read as a sink, flips its node's vote while the robot stands
    judging it: the fresh frames settle the vote, so the robot judges on; two frames that read it
    as the look-alike and none as the target defer it. With ``flip_reads: 0``, deferred at the flip."""
    def flipped(leaf: str):
        ctx = _ctx(Clock())
        pose = Pose2D(3.6, 5.0, 0.0)  # 0.9 m from the bed's box: frames are judged
        ctx.world = world(pose, [obj(3, "bed", 5.0, 5.0)], anchors=[anchor(1, pose)])
        tree = _confirmed_then(tmp_path, ctx, leaf)
        assert tree.tick() == S.RUNNING
        ctx.world = world(pose, [obj(3, "sofa", 5.0, 5.0)], anchors=[anchor(1, pose)])
        return ctx, tree, tree.tick()

    ctx, tree, status = flipped("VerifyTarget: {glance_deg: 0.0}")
    assert status == S.RUNNING and not ctx.rejections
    pose = Pose2D(3.6, 5.0, 0.0)
    for k in (2, 3):  # two fresh views, both read as a sofa
        ctx.world = world(pose, [obj(3, "sofa", 5.0, 5.0)], anchors=[anchor(i, pose, (3,)) for i in range(1, k + 1)])
        status = tree.tick()
    assert status == S.FAILURE and "label is now 'sofa'" in ctx.rejections[-1][1]
    assert ctx.excluded(3) and 3 not in ctx.rejected  # deferred, not rejected for good
    ctx, _, status = flipped("VerifyTarget: {flip_reads: 0}")
    assert status == S.FAILURE and "label is now 'sofa'" in ctx.rejections[-1][1]


def test_verify_defers_a_candidate_whose_label_flipped_and_takes_it_back_later(tmp_path):
    """A node's label is a vote: a real fridge read as 'cabinet' for a while came back as a
    fridge, but a permanent rejection had already made the robot explore the house out."""
    clock = Clock()
    ctx = _ctx(clock)
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0)])
    tree = _confirmed_then(tmp_path, ctx, "VerifyTarget: {defer_s: 30}")
    assert tree.tick() == S.RUNNING
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "sofa", 5.0, 5.0)])
    assert tree.tick() == S.FAILURE
    assert "label is now 'sofa'" in ctx.rejections[-1][1]
    assert ctx.excluded(3) and 3 not in ctx.rejected  # deferred, not rejected for good
    clock.t = 31.0
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0)])
    assert not ctx.excluded(3)
    assert [c.object_id for c in ctx.candidates()] == [3]


def test_a_label_flip_deferral_lapses_once_the_node_is_seen_again_as_the_target(tmp_path):
    """val/6/1: a real armchair read as 'sofa' for a while was deferred for 30 s of a 50 s
    episode while the detector went on reading it as an armchair; three new observations under
    a target label bring it back at once (and not fewer, and not under another label)."""
    clock = Clock()
    ctx = _ctx(clock)
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0, n_obs=5)])
    tree = _confirmed_then(tmp_path, ctx, "VerifyTarget: {defer_s: 30}")
    assert tree.tick() == S.RUNNING
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "sofa", 5.0, 5.0, n_obs=6)])
    assert tree.tick() == S.FAILURE
    clock.t = 2.0
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "sofa", 5.0, 5.0, n_obs=12)])
    assert ctx.excluded(3)  # seen again, but as a sofa
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0, n_obs=8)])
    assert ctx.excluded(3)  # a bed again, but only two observations since
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0, n_obs=9)])
    assert not ctx.excluded(3) and [c.object_id for c in ctx.candidates()] == [3]


def test_an_unreachable_deferral_does_not_lapse_on_new_observations():
    """Approach defers an unreachable candidate that the robot keeps seeing from where it stands:
    re-qualifying on observations would loop between approach and deferral."""
    clock = Clock()
    ctx = _ctx(clock)
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0, n_obs=5)])
    ctx.reject(3, "approach: no reachable cell", permanent=False, defer_s=30.0)
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0, n_obs=50)])
    assert ctx.excluded(3)


def test_anchor_sees_needs_the_point_in_the_image_and_no_box_in_the_way():
    """A tv 1.9 m up is above the vertical field of view of a camera 0.88 m up and 1 m away; a
    vase behind a chair is hidden; from 3 m away the tv is in view."""
    import numpy as np
    from hiconav.decisions.geometry import anchor_sees

    cam = anchor(1, Pose2D(0.0, 0.0, 0.0), height=0.88)
    assert anchor_sees(cam, np.array([2.0, 0.0, 0.9]))
    assert not anchor_sees(cam, np.array([1.0, 0.0, 1.9]))  # above the image
    assert anchor_sees(anchor(2, Pose2D(-2.0, 0.0, 0.0), height=0.88), np.array([1.0, 0.0, 1.9]))
    assert not anchor_sees(cam, np.array([-2.0, 0.0, 0.9]))  # behind the camera
    chair = (np.array([[0.8, -0.3, 0.0]]), np.array([[1.3, 0.3, 0.94]]))
    assert not anchor_sees(cam, np.array([2.0, 0.0, 0.88]), chair)
    assert anchor_sees(cam, np.array([2.0, 1.0, 0.88]), chair)  # beside the chair
    table = (np.array([[1.5, -0.5, 0.0]]), np.array([[2.5, 0.5, 0.7]]))
    assert anchor_sees(cam, np.array([2.0, 0.0, 0.8]), table)  # on the table: its box does not hide it


def test_verify_does_not_count_hidden_frames_and_moves_to_a_cell_that_sees(tmp_path):
    """From behind a chair the camera cannot show the bed: those frames neither confirm nor
    reject it, and after reposition_after of them the robot goes to another cell, one from
    which the line of sight passes no memory object."""
    clock = Clock()
    ctx = _ctx(clock)
    pose = Pose2D(3.6, 5.0, 0.0)  # west of the bed at (5, 5), a chair between
    chair = obj(9, "chair", 4.15, 5.0)
    chair = type(chair)(9, "chair", chair.center, np.array([4.0, 4.8, 0.0]), np.array([4.3, 5.2, 1.0]))
    objects = [obj(3, "bed", 5.0, 5.0), chair]
    ctx.world = world(pose, objects, anchors=[anchor(1, pose, (3,))])
    tree = _confirmed_then(tmp_path, ctx, "VerifyTarget: {max_view_frames: 3, reposition_after: 4}")
    assert tree.tick() == S.RUNNING
    first = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    ctx.nav = NavStatus(first.seq, "reached", 0.0)
    sent = len(ctx.outbox)
    for aid in range(2, 6):  # four frames from behind the chair (glancing about): not in view
        ctx.world = world(pose, objects, anchors=[anchor(aid, pose)])
        assert tree.tick() == S.RUNNING
        ctx.nav = NavStatus([m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].seq, "reached", 0.0)
    tree.tick()
    goals = [m.goal for m in ctx.outbox[sent:] if isinstance(m, GoalMsg) and m.goal is not None]
    assert ctx.rejections == []  # hidden frames rejected nothing
    moved = [g for g in goals if g.kind == "approach"]
    assert moved, goals
    g = moved[-1]
    from hiconav.decisions.geometry import segments_blocked

    assert not segments_blocked(np.array([[g.x, g.y, 0.4]]), np.array([5.0, 5.0, 0.4]),
                                chair.box_min[None, :] + [0.05, 0.05, 0.0], chair.box_max[None, :] - [0.05, 0.05, 0.0])[0]


def test_explore_turns_look_turns_times_per_spot_for_the_whole_mission(tmp_path):
    """With no frontier to pick, Explore turns in place look_turns times at a spot, counted by
    the mission: new Explore instances (retries) at the same spot do not turn again."""
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = plan()  # no frontier
    looks = 0
    for retry in range(3):
        tree = MissionTree(_write(tmp_path, "root:\n  Explore: {look_turns: 2, max_idle_s: 100}\n"), ctx)
        for _ in range(6):
            clock.t += 1.0
            tree.tick()
            goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)]
            if goal and goal[-1].goal is not None and goal[-1].goal.kind == "look" and \
                    ctx.nav_state(goal[-1].seq) == "pending":
                looks += 1
                ctx.nav = NavStatus(goal[-1].seq, "reached", 0.0)
        tree.stop()
    assert looks == 2 and ctx.looks_here == 2
    ctx.world = world(Pose2D(6.0, 6.0, 0.0))  # elsewhere: two more
    tree = MissionTree(_write(tmp_path, "root:\n  Explore: {look_turns: 2, max_idle_s: 100}\n"), ctx)
    tree.tick()
    assert [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal.kind == "look" and ctx.looks_here == 1


def test_explored_out_explore_brings_deferred_candidates_back_before_failing(tmp_path):
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = plan()
    ctx.reject(3, "label is now 'sofa'", permanent=False, defer_s=30.0)
    tree = MissionTree(_write(tmp_path, "root:\n  Explore: {look_turns: 0, max_idle_s: 2}\n"), ctx)
    assert tree.tick() == S.RUNNING
    clock.t = 3.0
    assert tree.tick() == S.RUNNING  # not FAILURE: the deferred candidate is due now
    assert not ctx.excluded(3)
    clock.t = 6.0
    assert tree.tick() == S.FAILURE  # nothing deferred any more: explored out


def test_verify_judges_from_where_the_robot_stands_when_it_already_sees_the_candidate_close(tmp_path):
    """A robot 0.7 m from the bed with nothing between judges it from there, facing it, though
    the bed was first seen from the north (a view cell on that line would take it 2 m away and
    the approach would bring it back); ``from_here: false`` drives to that line."""
    sent = {}
    for from_here in (True, False):
        ctx = _ctx(Clock())
        pose = Pose2D(3.8, 5.0, 1.0)
        bed = replace(obj(3, "bed", 5.0, 5.0), anchor_ids=(1,))
        ctx.world = world(pose, [bed], anchors=[anchor(1, Pose2D(5.0, 7.5, -1.57), (3,))])
        tree = _confirmed_then(tmp_path, ctx, f"VerifyTarget: {{from_here: {str(from_here).lower()}}}")
        assert tree.tick() == S.RUNNING
        sent[from_here] = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    here = sent[True]
    assert (here.x, here.y) == (3.8, 5.0) and abs(here.yaw) < 1e-9 and here.kind == "approach"
    assert math.hypot(sent[False].x - 3.8, sent[False].y - 5.0) > 1.0


def test_verify_defers_a_candidate_it_gets_no_nearer_to(tmp_path):
    """A robot rocking in a doorway it cannot pass makes no progress toward the view cell: after
    STALL_S the candidate is deferred (the behaviours' timeouts outlast a 500-step episode)."""
    clock = Clock()
    ctx = _ctx(clock)
    ctx.world = world(Pose2D(1.0, 1.0, 0.0), [obj(3, "bed", 8.0, 8.0)])
    tree = _confirmed_then(tmp_path, ctx, "VerifyTarget: {}")
    assert tree.tick() == S.RUNNING
    for k in range(1, 8):
        clock.t = float(k)
        ctx.world = world(Pose2D(1.0 + 0.1 * (k % 2), 1.0, 0.0), [obj(3, "bed", 8.0, 8.0)])
        status = tree.tick()
    assert status == S.FAILURE and "no progress" in ctx.rejections[-1][1] and 3 not in ctx.rejected


def test_approach_goes_to_its_cell_even_when_it_starts_within_the_distance(tmp_path):
    """Approach starting 0.7 m off the bed's side, facing it, still goes to its approach cell
    (it stopped where VerifyTarget had left it, off a painting's end, in val/65/2)."""
    start = Pose2D(3.8, 4.9, math.atan2(0.1, 1.2))
    _, _, goal = _approach_bed(tmp_path, start)
    # to the first ring (0.55 m from the box, 4.5-5.5), 0.15 m on, in line with the bed's middle
    assert goal.kind == "approach" and math.hypot(goal.x - start.x, goal.y - start.y) > 0.1
    assert 4.5 - goal.x <= 0.55 + 0.05


def test_wall_clear_sees_past_known_furniture_but_not_past_walls():
    """The 2D line of sight from an approach cell: occupied cells inside memory objects' boxes
    (a table) are see-through, the rest (a wall) are not."""
    from hiconav.decisions.geometry import wall_clear

    from .fakes import open_grid

    grid = open_grid()
    grid.state[20:80, 50] = 1  # a wall at x = 5.0 m
    grid.state[45:55, 30:35] = 1  # a table at x 3.0-3.5, y 4.5-5.5
    table = (np.array([3.0, 4.5, 0.0]), np.array([3.5, 5.5, 0.7]))
    chair = (np.array([5.6, 4.8, 0.0]), np.array([6.0, 5.2, 0.9]))
    cells = np.array([[2.0, 5.0], [5.5, 6.0], [4.5, 5.0]])
    clear = wall_clear(grid, cells, np.array([5.8, 5.0]), [chair, table])
    assert clear.tolist() == [False, True, False]  # behind the wall; same side; behind the wall
    assert wall_clear(grid, np.array([[2.0, 5.0]]), np.array([4.0, 5.0]), [table]).tolist() == [True]
    assert wall_clear(grid, np.array([[2.0, 5.0]]), np.array([4.0, 5.0]), []).tolist() == [False]
    # with heights: the line from a camera 0.9 m up to a top 0.8 m up passes over a 0.5 m obstacle
    grid.top = np.zeros(grid.state.shape, dtype=np.float32)
    grid.top[grid.state == 1] = 0.5
    assert wall_clear(grid, np.array([[2.0, 5.0]]), np.array([4.0, 5.0]), [], heights=(0.9, 0.8)).tolist() == [True]
    assert wall_clear(grid, np.array([[2.0, 5.0]]), np.array([4.0, 5.0]), [], heights=(0.5, 0.4)).tolist() == [False]


def test_verify_out_of_range_after_the_box_moved_goes_to_a_new_cell_instead_of_glancing(tmp_path):
    """The candidate's box moves as it is seen: at a cell chosen for the old box, now out of
    range, the robot goes to a cell for the current box rather than glance from afar (val/31/2
    glanced 364 steps 1.8 m from a real fridge, counting nothing)."""
    clock = Clock()
    ctx = _ctx(clock)
    pose = FACING_BED
    ctx.world = world(pose, [obj(3, "bed", 5.0, 5.0)], anchors=[anchor(1, pose, (3,))])
    tree = _confirmed_then(tmp_path, ctx, "VerifyTarget: {}")
    assert tree.tick() == S.RUNNING
    ctx.nav = NavStatus([m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].seq, "reached", 0.0)
    tree.tick()  # close: a glance
    assert [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal.kind == "look"
    ctx.nav = NavStatus([m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].seq, "reached", 0.0)
    ctx.world = world(pose, [obj(3, "bed", 7.5, 7.5)], anchors=[anchor(2, pose)])  # the box moved away
    tree.tick()
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert goal.kind == "approach" and math.hypot(goal.x - 7.5, goal.y - 7.5) < 2.0


def _corridor_to_the_bed():
    """A 0.8 m corridor (y 3.6-4.4) below the bed at (5, 5), all of it in the map's inflation margin
    up to x = 5.6 (the robot radius clears it), roomy from there on."""
    from .fakes import FakeGrid

    state = np.zeros((100, 100), dtype=np.int8)
    state[0, :] = state[-1, :] = state[:, 0] = state[:, -1] = 1
    state[:36, :] = 1
    state[44:, :] = 1
    inflated = state == 1
    inflated[36:44, :56] = True
    grid = FakeGrid(state, inflated)
    grid.lethal = state == 1
    return grid


@pytest.mark.parametrize("leaf", ["Approach: {distance: 0.8}", "VerifyTarget: {}"])
def test_from_inside_a_narrow_passage_the_robot_weighs_its_cells_as_roomy_ones(tmp_path, leaf):
    """Gibson Woodbine/0/1: 1.0 m from a chair's box in a 0.4 m corridor, every cell of which lay in
    the map's inflation margin, Approach drove 1.7 m along it to the corridor's end, the one cell
    in range that kept the margin. A robot already in the margin weighs the passage's cells as the
    others (Approach's cells and VerifyTarget's view cells), and stops where it is nearest."""
    ctx = _ctx(Clock())
    ctx.world = world(Pose2D(2.9, 3.8, 0.0), [obj(3, "bed", 5.0, 5.0, n_obs=5)], grid=_corridor_to_the_bed())
    tree = _confirmed_then(tmp_path, ctx, leaf)
    assert tree.tick() == S.RUNNING
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert goal.kind == "approach" and goal.x < 5.0  # not the roomy cells from x = 5.6 on


def test_requalify_observations_zero_keeps_a_label_flip_deferred_for_its_time():
    """mission.requalify_observations = 0 (the setting's off switch) restores plain deferrals."""
    clock = Clock()
    ctx = _ctx(clock, requalify_observations=0)
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0, n_obs=5)])
    ctx.reject(3, "label is now 'sofa'", permanent=False, defer_s=30.0, requalify=True)
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 5.0, 5.0, n_obs=50)])
    assert ctx.excluded(3)
    clock.t = 31.0
    assert not ctx.excluded(3)


def test_explore_pushes_once_into_a_spent_frontier_beside_the_robot(tmp_path):
    """Gibson Tolstoy/0/2: the passage to the toilet opened at the robot's side, below the
    camera's view; its frontier's viewpoint was spent and the mission ended with "no frontier
    left" after 33 of 500 steps. A spent frontier beside the robot is driven into once, through
    unknown floor, before it is skipped; the push ends at its time limit."""
    clock, ctx, tree = _reach_first_frontier(tmp_path)
    ctx.world = world(Pose2D(8.0, 8.0, 0.0))  # at the viewpoint it reached
    tree.tick()
    clock.t = 6.0
    ctx.plan = _plan_at(5.5, (9, (8.3, 8.0)), (10, (1.0, 8.0)))  # still a frontier there
    tree.tick()
    assert ctx.spent_viewpoints == [(8.0, 8.0)]
    push = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert push.ref_id == 9 and push.through_unknown
    assert abs(push.x - 8.9) < 1e-9 and abs(push.y - 8.0) < 1e-9  # push_m beyond the centroid
    clock.t = 10.0
    ctx.plan = _plan_at(9.5, (11, (8.3, 8.0)), (12, (1.0, 8.0)))
    tree.tick()  # the push runs on while the plan renumbers the frontier
    assert [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal == push
    clock.t = 12.5  # past push_s: the push ends, and that frontier is not pushed into again
    tree.tick()
    last = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert last.ref_id == 12 and not last.through_unknown


def test_explore_does_not_push_into_a_spent_frontier_far_from_the_robot(tmp_path):
    clock, ctx, tree = _reach_first_frontier(tmp_path)  # the robot is reported at (2, 2)
    tree.tick()
    clock.t = 6.0
    ctx.plan = _plan_at(5.5, (9, (8.3, 8.0)), (10, (1.0, 8.0)))
    tree.tick()
    last = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal
    assert last.ref_id == 10 and not last.through_unknown


def test_explore_skips_a_frontier_it_comes_no_nearer_to(tmp_path):
    """Gibson Tolstoy/0/3: the map showed a corridor open that the robot does not fit through; it
    rocked at the mouth for all 500 steps. No 0.25 m nearer in stall_s: the next frontier."""
    clock = Clock()
    ctx = _ctx(clock)  # the robot stays at (2, 2)
    ctx.plan = _plan_at(0.0, (0, (8.0, 8.0)), (1, (1.0, 8.0)))
    tree = MissionTree(_write(tmp_path, "root:\n  Explore: {stall_s: 8}\n"), ctx)
    tree.tick()
    clock.t = 0.1
    tree.tick()
    clock.t = 7.0
    tree.tick()
    assert [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal.ref_id == 0
    clock.t = 8.5
    tree.tick()
    assert [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal.ref_id == 1
    assert any("no progress" in e for e in ctx.events)


def _fail_last_goal(ctx) -> object:
    """Report the newest goal request as failed (no path); returns its goal."""
    last = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    ctx.nav = NavStatus(last.seq, "failed", 0.0)
    return last.goal


def test_explore_squeezes_once_toward_each_failed_frontier_before_it_gives_up(tmp_path):
    """Gibson Onaga/0/1: every frontier failed on the map's masks (its grid phase closed the one
    passage) and the mission idled to its end. With nothing left, each failed frontier is tried
    once more as a goal through unknown floor (the navigator's squeeze), then Explore fails."""
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = _plan_at(0.0, (0, (8.0, 8.0)), (1, (1.0, 8.0)))
    tree = MissionTree(_write(tmp_path, "root:\n  Explore: {max_idle_s: 3}\n"), ctx)
    goals = []
    for _ in range(4):  # two ordinary goals, then two squeezes: all fail at once
        tree.tick()
        goals.append(_fail_last_goal(ctx))
        clock.t += 0.1
    assert [(g.ref_id, g.through_unknown) for g in goals] == [(0, False), (1, False), (0, True), (1, True)]
    assert any("squeezing toward frontier #0" in e for e in ctx.events)
    status = S.RUNNING
    while status == S.RUNNING and clock.t < 5.0:
        status = tree.tick()
        clock.t += 0.5
    assert status == S.FAILURE
    assert [m.goal.through_unknown for m in ctx.outbox if isinstance(m, GoalMsg) and m.goal is not None].count(True) == 2


def test_a_retried_explore_does_not_idle_anew_for_frontiers_that_failed_before(tmp_path):
    """Re-picking an unreachable frontier reset the idle clock on every retry: Onaga/0/1 spent
    430 s of clock without a step. A frontier that failed once is no progress when picked again."""
    clock = Clock()
    ctx = _ctx(clock)
    ctx.plan = _plan_at(0.0, (0, (8.0, 8.0)))
    tree = MissionTree(_write(tmp_path, "root:\n  Retry:\n    num_failures: 50\n    child:\n"
                                        "      Explore: {max_idle_s: 3, squeeze: false}\n"), ctx)
    tree.tick()
    _fail_last_goal(ctx)
    status, ticks = S.RUNNING, 0
    while status == S.RUNNING:
        clock.t += 0.1
        status = tree.tick()
        if [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal is not None:
            _fail_last_goal(ctx)
        ticks += 1
        assert ticks < 400
    assert status == S.FAILURE and clock.t < 3.0 + 0.1 * 200  # not 50 x 3 s of idling


def test_verify_gives_a_candidate_observed_often_the_full_frame_count(tmp_path):
    """Gibson Onaga/0/1: a real plant seen 17 times went undetected in 4 frames from 0.8 m and the
    early rejection (meant for spurious boxes, seen once or twice) threw it away."""
    ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, max_view_frames: 8, unseen_view_frames: 4")
    ctx.world = world(FACING_BED, [obj(3, "bed", 5.0, 5.0, n_obs=17)], anchors=[anchor(1, FACING_BED, (3,))])
    tree.tick()
    for aid in range(2, 9):
        ctx.world = world(FACING_BED, [obj(3, "bed", 5.0, 5.0, n_obs=17)], anchors=[anchor(aid, FACING_BED)])
        assert tree.tick() == S.RUNNING  # 0 of up to 7 frames: judged on the full 8
    ctx.world = world(FACING_BED, [obj(3, "bed", 5.0, 5.0, n_obs=17)], anchors=[anchor(9, FACING_BED)])
    assert tree.tick() == S.FAILURE and "0 of 8 frames" in ctx.rejections[-1][1]


@pytest.mark.parametrize("n_obs, confirmed", [(31, True), (3, False)])
def test_verify_accepts_a_low_scored_candidate_observed_many_times(tmp_path, n_obs, confirmed):
    """The oracle scores a small plant low in every frame: seen 31 times at 0.29 it was rejected
    for its score (Gibson Onaga/0/1). ``confident_observations`` observations pass the gate."""
    ctx, tree = _verify_tree(tmp_path, Clock(), "min_fresh_views: 2, min_confidence: 0.3")
    bed = obj(3, "bed", 5.0, 5.0, n_obs=n_obs, conf=0.29)
    ctx.world = world(FACING_BED, [bed], anchors=[anchor(1, FACING_BED, (3,))])
    tree.tick()
    for aid in (2, 3):
        ctx.world = world(FACING_BED, [bed], anchors=[anchor(aid, FACING_BED, (3,))])
        status = tree.tick()
    assert (status == S.SUCCESS) == confirmed
    if not confirmed:
        assert "confidence 0.29" in ctx.rejections[-1][1]



def _unknown_room() -> "object":
    """The open 10 m room with everything beyond x = 3 m still unknown."""
    from .fakes import open_grid

    grid = open_grid()
    grid.state[:, 30:] = -1
    return grid


def _verify_beyond_the_known(tmp_path: Path, x: float, params: str):
    """VerifyTarget (``params``) on a bed at (6, 6) observed 5 times, from (x, 2) in the room known
    only up to x = 3 m: (clock, context, grid, tree)."""
    clock = Clock()
    ctx = _ctx(clock)
    grid = _unknown_room()
    ctx.world = world(Pose2D(x, 2.0, 0.0), [obj(3, "bed", 6.0, 6.0, n_obs=5)], grid=grid)
    return clock, ctx, grid, _confirmed_then(tmp_path, ctx, f"VerifyTarget: {{{params}}}")


def test_a_no_view_point_deferral_lapses_once_the_map_around_the_candidate_grows(tmp_path):
    """Gibson Leonardo/0/2: judged on the first frames' map, a plant 4 m off had no reachable view
    cell, and its 30 s deferral sent the robot 39 m about the house, past the plant. Once the
    known free floor within 2 m of the candidate has grown by remap_area_m2 it is due again (and
    the deferral does not count toward max_deferrals)."""
    clock, ctx, grid, tree = _verify_beyond_the_known(tmp_path, 2.0, "defer_s: 30, max_deferrals: 2, closer_moves: 0, unknown_moves: 0")
    assert tree.tick() == S.FAILURE
    assert ctx.rejections[-1] == (3, "no reachable view point") and ctx.excluded(3)
    clock.t = 1.0
    grid.state[40:45, 40:55] = 0  # 0.75 m^2 more free floor near the bed: not enough
    assert ctx.excluded(3)
    grid.state[45:48, 40:55] = 0  # 1.2 m^2 in all
    assert not ctx.excluded(3)
    assert any("map around it grew by 1.2 m^2" in e for e in ctx.events)
    # a second map deferral is not the max_deferrals-th: the candidate stays deferred, not rejected
    tree = _confirmed_then(tmp_path, ctx, "VerifyTarget: {defer_s: 30, max_deferrals: 2, closer_moves: 0, unknown_moves: 0}")
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 6.0, 6.0, n_obs=5)], grid=grid)
    assert tree.tick() == S.FAILURE
    assert 3 not in ctx.rejected and ctx.remaps[3] == 2


def test_with_no_view_cell_on_the_map_verify_closes_in_on_the_candidate_before_deferring(tmp_path):
    """Gibson Cosmos/0/2: a chair 5.2 m off had no view cell on the young map, and its deferral sent
    the robot exploring elsewhere by the plan's order. VerifyTarget first drives to the known
    free cell nearest the candidate (closer_moves times), which shows the floor around it; only
    when no cell is closer by closer_min_gain does it defer."""
    _, ctx, grid, tree = _verify_beyond_the_known(tmp_path, 1.0, "defer_s: 30, closer_moves: 1")
    assert tree.tick() == S.RUNNING
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    assert goal.goal.kind == "approach" and 2.5 <= goal.goal.x <= 3.0 and goal.goal.y > 4.0  # by the edge of the known
    assert not ctx.rejections and any("closing in" in e for e in ctx.events)
    ctx.world = world(Pose2D(goal.goal.x, goal.goal.y, 0.0), [obj(3, "bed", 6.0, 6.0, n_obs=5)], grid=grid)
    ctx.nav = NavStatus(goal.seq, "reached", 0.0)
    assert tree.tick() == S.FAILURE  # still no view cell, and its one closer move is spent
    assert ctx.rejections[-1] == (3, "no reachable view point")


@pytest.mark.parametrize("unknown_moves, n_obs", [(1, 5), (0, 5), (1, 2)])
def test_with_the_floor_by_the_candidate_cut_off_by_unknown_floor_verify_heads_through_it(tmp_path, unknown_moves,
                                                                                           n_obs):
    """Gibson Forkland/0/0: furniture cut the known floor by a sofa 4 m off from the robot's, and
    its deferral sent the robot 15 m about the house before it came back. With no view cell
    reachable on the known map and no closer cell, VerifyTarget heads for a view cell on the
    floor known by the candidate through unknown floor (``unknown_moves`` times), for a candidate
    observed ``unknown_min_observations`` (3) times or more; a goal that fails there defers it
    as before. A candidate observed once or twice is deferred at once: the trip is a guess, and
    for such candidates it lost more than it won (Gibson Coffeen/0/1, Allensville/0/3)."""
    from .fakes import open_grid

    clock = Clock()
    ctx = _ctx(clock)
    grid = open_grid()
    grid.state[:, 30:40] = -1  # x in [3, 4) m unknown; the floor beyond, by the bed, is known
    ctx.world = world(Pose2D(1.0, 2.0, 0.0), [obj(3, "bed", 6.0, 6.0, n_obs=n_obs)], grid=grid)
    tree = _confirmed_then(tmp_path, ctx, f"VerifyTarget: {{defer_s: 30, closer_moves: 0, unknown_moves: {unknown_moves}}}")
    if unknown_moves == 0 or n_obs < 3:
        assert tree.tick() == S.FAILURE and ctx.rejections[-1] == (3, "no reachable view point")
        return
    assert tree.tick() == S.RUNNING
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    g = goal.goal
    assert g.through_unknown and g.kind == "approach" and g.ref_id == 3 and g.x >= 4.0
    assert math.hypot(max(abs(g.x - 6.0) - 0.5, 0.0), max(abs(g.y - 6.0) - 0.5, 0.0)) <= 1.2  # a view cell
    assert not ctx.rejections and any("through unknown floor" in e for e in ctx.events)
    ctx.nav = NavStatus(goal.seq, "failed", 0.0)
    assert tree.tick() == S.FAILURE  # the way turned out closed, and its one move is spent
    assert ctx.rejections[-1] == (3, "no reachable view point")


def test_map_deferrals_stop_lapsing_after_max_remaps_and_remap_area_zero_disables_them():
    clock = Clock()
    ctx = _ctx(clock, max_remaps=1)
    grid = _unknown_room()
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 6.0, 6.0)], grid=grid)
    ctx.reject(3, "no reachable view point", permanent=False, defer_s=30.0, remap=True)
    grid.state[40:60, 40:55] = 0
    assert not ctx.excluded(3)
    ctx.reject(3, "no reachable view point", permanent=False, defer_s=30.0,
               remap=ctx.remaps.get(3, 0) < ctx.max_remaps)
    grid.state[60:80, 40:55] = 0
    assert ctx.excluded(3)  # the cap reached: this deferral lasts its time
    clock.t = 31.0
    assert not ctx.excluded(3)

    off = _ctx(Clock(), remap_area_m2=0.0)
    grid = _unknown_room()
    off.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 6.0, 6.0)], grid=grid)
    off.reject(3, "no reachable view point", permanent=False, defer_s=30.0, remap=True)
    grid.state[40:80, 40:55] = 0
    assert off.excluded(3)


def test_approach_inner_margin_sets_the_first_ring_and_centre_weight_pulls_to_the_middle(tmp_path):
    """The default mission approaches to 0.75-0.85 m (inner_margin 0.1): a first ring 0.55 m out
    drove ~0.36 m more per success inside the 1 m success region. The bed's box spans 4.5-5.5;
    from (1.5, 5.45) the goal is on the 0.8 m ring's edge, toward the middle (centre_weight 0.9:
    at 1 every cell on the line to the centre ties, and the array order picked one 0.65 m out)
    or level with the robot (centre_weight 0)."""
    def first_goal(params: str):
        ctx = _ctx(Clock())
        ctx.world = world(Pose2D(1.5, 5.45, 0.0), [obj(3, "bed", 5.0, 5.0)])
        tree = _confirmed_then(tmp_path, ctx, f"Approach: {{{params}}}")
        assert tree.tick() == S.RUNNING
        return [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1].goal

    goal = first_goal("distance: 0.9, inner_margin: 0.1")
    assert 4.5 - goal.x == pytest.approx(0.8, abs=0.06) and goal.y < 5.45
    flat = first_goal("distance: 0.9, inner_margin: 0.1, centre_weight: 0.0")
    assert 4.5 - flat.x == pytest.approx(0.8, abs=0.06) and flat.y > 5.3
    tied = first_goal("distance: 0.9, inner_margin: 0.1, centre_weight: 1.0")
    assert 4.5 - tied.x < 0.7  # the tie: deeper than the ring's edge
    deep = first_goal("distance: 0.9, inner_margin: 0.5")
    assert 4.5 - deep.x == pytest.approx(0.4, abs=0.06)


LOCATE_THEN_STOP = """
root:
  Sequence:
    memory: true
    children:
      - Retry:
          num_failures: 50
          child:
            Sequence:
              memory: true
              children:
                - Selector:
                    memory: false
                    children:
                      - TargetConfirmed: {}
                      - Explore: {max_idle_s: 3}
                - VerifyTarget: {}
                - Approach: {distance: 0.8}
      - Stop: {}
"""


def _explored_out_with_a_bed_out_of_reach(tmp_path, reason_out_of_reach: bool, **decisions):
    """A bed at (8, 8) on floor the map does not know, set aside (for good) as the robot at (2, 2)
    found no view point of it; no frontier left."""
    import numpy as np

    from .fakes import FakeGrid

    clock = Clock()
    ctx = _ctx(clock, decisions=DecisionsConfig(explore=ExploreSettings(start_look_turns=0, **decisions)))
    state = np.full((100, 100), -1, dtype=np.int8)
    state[10:30, 10:30] = 0  # the robot's corner, 1-3 m
    grid = FakeGrid(state, np.zeros_like(state, dtype=bool))
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 8.0, 8.0, n_obs=6)], grid=grid)
    ctx.plan = plan()
    ctx.reject(3, "no reachable view point" if reason_out_of_reach else "detected in 0 of 4 frames in view",
               out_of_reach=reason_out_of_reach)
    return clock, ctx, MissionTree(_write(tmp_path, LOCATE_THEN_STOP), ctx), grid


def test_explored_out_the_mission_stops_by_the_candidate_it_set_aside_only_as_out_of_reach(tmp_path):
    """Explored out, ending fails for certain: a candidate set aside only because no view point
    could be reached is taken back once, taken as it is, and the robot stops as near it as the
    map allows (here: nowhere nearer, so where it stands, facing it)."""
    clock, ctx, tree, grid = _explored_out_with_a_bed_out_of_reach(tmp_path, True)
    assert tree.tick() == S.RUNNING and ctx.last_resort is None
    clock.t = 3.5
    assert tree.tick() == S.RUNNING and ctx.last_resort == 3
    assert any("last resort: #3" in e for e in ctx.events)
    assert ctx.candidates()[0].source == "last-resort"
    # no cell on the rings out to last_resort_m (the bed's floor is unknown): a creep through the
    # unknown floor toward it, then a turn to face it where the creep ended
    for _ in range(5):
        tree.tick()
    goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    assert goal.goal.ref_id == 3
    if goal.goal.straight:  # the creep: blocked at once
        ctx.nav = NavStatus(goal.seq, "failed", 0.0)
        tree.tick()
        goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    assert goal.goal.kind == "look"
    ctx.world = world(Pose2D(2.0, 2.0, math.pi / 4), [obj(3, "bed", 8.0, 8.0, n_obs=6)], grid=grid)
    ctx.nav = NavStatus(goal.seq, "reached", 0.0)
    assert tree.tick() == S.SUCCESS
    assert any(isinstance(m, StopRequest) for m in ctx.outbox)


def test_explored_out_a_candidate_judged_wrong_is_no_last_resort_and_the_setting_turns_it_off(tmp_path):
    for out_of_reach, on in ((False, True), (True, False)):
        clock, ctx, tree, _ = _explored_out_with_a_bed_out_of_reach(tmp_path, out_of_reach, last_resort=on)
        assert tree.tick() == S.RUNNING
        clock.t = 3.5
        _tick_while_running(tree)
        assert tree.root.status == S.FAILURE and ctx.last_resort is None
        assert not any(isinstance(m, StopRequest) for m in ctx.outbox)


def test_a_later_rejection_on_evidence_clears_out_of_reach_and_a_last_resort_is_taken_once():
    ctx = _ctx(Clock())
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "bed", 8.0, 8.0, n_obs=6), obj(4, "bed", 6.0, 2.0, n_obs=2)])
    ctx.reject(3, "no reachable view point", out_of_reach=True)
    ctx.reject(4, "approach: no reachable approach cell", permanent=False, out_of_reach=True)
    assert ctx.stranded
    ctx.reject(3, "detected in 0 of 4 frames in view")
    assert set(ctx.out_of_reach) == {4}
    cand = ctx.take_last_resort()
    assert cand.object_id == 4 and cand.source == "last-resort" and not ctx.excluded(4)
    assert ctx.take_last_resort() is None and not ctx.stranded  # once per mission
    # rejected again (the approach timed out): it is no candidate any more
    ctx.reject(4, "approach: timed out", permanent=True)
    assert ctx.last_resort is None and ctx.excluded(4) and not ctx.candidates()


def test_explore_turns_beside_an_undecided_described_instance_once_then_explores_on(tmp_path):
    """A described-instance search that comes upon an armchair 0.5 m off, which the reasoning layer
    has not ruled out, turns in place beside it (linger_turns quarter turns, once per node)
    before following the plan again; an armchair ruled out, or a plain object goal, does not."""
    described = TaskSpec("the armchair next to the floor lamp", ("armchair",), ("floor_lamp",),
                         relations=(("armchair", "next to", "floor_lamp"),))
    for ruled_out, task, lingers in ((frozenset(), described, True), (frozenset({3}), described, False),
                                     (frozenset(), TaskSpec("find the armchair", ("armchair",)), False)):
        clock = Clock()
        ctx = _ctx(clock)
        ctx.task, ctx.ruled_out = task, ruled_out
        ctx.world = world(Pose2D(2.0, 2.0, 0.0), [obj(3, "armchair", 3.0, 2.0)])
        ctx.plan = plan((8.0, 8.0))
        tree = MissionTree(_write(tmp_path, "root:\n  Explore: {linger_turns: 2}\n"), ctx)
        kinds = []
        for _ in range(4):
            clock.t += 0.5
            tree.tick()
            goal = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
            kinds.append(goal.goal.kind)
            ctx.nav = NavStatus(goal.seq, "reached", 0.0)
        assert (kinds[:2] == ["look", "look"] and kinds[2] != "look") is lingers, kinds
        assert (3 in ctx.lingered) is lingers


def test_explore_standing_idle_judges_its_reached_viewpoint_on_the_plan_of_its_newest_frame(tmp_path):
    """A robot whose frames come only with its actions gets no newer plan while it waits: Explore
    judged the visit "spent" never, failed idle, and a retried Explore re-picked the same viewpoint
    until the task clock ran out. Now the plan of its newest frame judges it."""
    clock = Clock()
    ctx = _ctx(clock, decisions=DecisionsConfig(explore=ExploreSettings(start_look_turns=0, look_turns=0)))
    ctx.world = world(Pose2D(2.0, 2.0, 0.0), seq=7)
    ctx.plan = replace(_plan_at(0.0, (0, (3.0, 2.0))), snapshot_seq=6)
    tree = MissionTree(_write(tmp_path, "root:\n  Explore: {}\n"), ctx)
    tree.tick()
    first = [m for m in ctx.outbox if isinstance(m, GoalMsg)][-1]
    clock.t = 5.0
    ctx.nav = NavStatus(first.seq, "reached", 0.0)
    ctx.world = world(Pose2D(3.0, 2.0, 0.0), seq=8)
    ctx.plan = replace(_plan_at(4.9, (0, (3.0, 2.0))), snapshot_seq=8)  # made from the arrival frame
    tree.tick()
    assert ctx.spent_viewpoints == []  # too soon after the visit
    clock.t = 6.0  # no frame since: the plan is as new as any will be until the robot acts
    tree.tick()
    assert ctx.spent_viewpoints == [(3.0, 2.0)]
    # a newer frame that the plan has not caught up with: judged on the next plan, not this one
    clock2 = Clock()
    ctx2 = _ctx(clock2, decisions=DecisionsConfig(explore=ExploreSettings(start_look_turns=0, look_turns=0)))
    ctx2.plan = replace(_plan_at(0.0, (0, (3.0, 2.0))), snapshot_seq=0)
    tree2 = MissionTree(_write(tmp_path, "root:\n  Explore: {}\n"), ctx2)
    tree2.tick()
    clock2.t = 5.0
    ctx2.nav = NavStatus([m for m in ctx2.outbox if isinstance(m, GoalMsg)][-1].seq, "reached", 0.0)
    ctx2.world = world(Pose2D(3.0, 2.0, 0.0), seq=9)
    ctx2.plan = replace(_plan_at(4.9, (0, (3.0, 2.0))), snapshot_seq=8)
    tree2.tick()
    clock2.t = 6.0
    tree2.tick()
    assert ctx2.spent_viewpoints == []
