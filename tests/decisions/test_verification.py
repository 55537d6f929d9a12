"""One verification in progress (hiconav.decisions.verification) on hand-built memory snapshots,
anchors and grids: when frames are judged, what a confirmation names, the next move and the
state it changes, glances, closer and through-unknown goals with their texts, the switch to a
nearer candidate and how a verdict is posted."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiconav.decisions import verification as verif
from hiconav.decisions.confirmation import Verdict, deferred
from hiconav.decisions.config import VerifySettings
from hiconav.decisions.viewing import ViewMove, close_distance
from hiconav.types import Pose2D, camera_pose_from_base

from .fakes import Grid, Anchor, Memory

S = VerifySettings(min_fresh_views=2, max_view_frames=8, unseen_view_frames=4)
CENTRE = np.array([5.0, 5.0, 0.4])
LO, HI = CENTRE - [0.5, 0.5, 0.4], CENTRE + [0.5, 0.5, 0.4]
RING = S.verify_distance - S.view_margin


@dataclass(frozen=True)
class Node:
    id: int
    label: str
    center: np.ndarray
    box_min: np.ndarray
    box_max: np.ndarray
    confidence: float = 0.9
    n_obs: int = 1
    anchor_ids: tuple = ()


@dataclass(frozen=True)
class Cand:
    object_id: int
    label: str
    center: np.ndarray
    box_min: np.ndarray
    box_max: np.ndarray
    n_obs: int = 1
    source: str = "memory-label"


@dataclass(frozen=True)
class Pose:
    x: float
    y: float


def node(oid: int, label: str, x: float, y: float, confidence: float = 0.9, n_obs: int = 1) -> Node:
    c = np.array([x, y, 0.4])
    return Node(oid, label, c, c - [0.5, 0.5, 0.4], c + [0.5, 0.5, 0.4], confidence, n_obs)


def facing_bed(aid: int, object_ids: tuple = (), labels_seen: tuple = ()) -> Anchor:
    """A camera 0.4 m up at (3.5, 5) looking east at the candidate at (5, 5)."""
    return Anchor(aid, camera_pose_from_base(Pose2D(3.5, 5.0, 0.0), 0.4), object_ids, labels_seen)


def room() -> Grid:
    """A 10 m x 10 m free room at 0.1 m, walls on its border."""
    state = np.zeros((100, 100), dtype=np.int8)
    state[0, :] = state[-1, :] = state[:, 0] = state[:, -1] = 1
    return Grid(state, state == 1)


BED = Cand(1, "bed", CENTRE, LO, HI)


def judge(v: verif.Verification, memory: Memory, gap: float = 1.0) -> verif.Judgement | None:
    return v.judge(S, gap, RING, memory, None, BED, ["bed"], "bed")


def test_frames_are_judged_only_within_the_close_distance_and_only_those_made_after_coming_close():
    v = verif.Verification(0.0)
    memory = Memory([node(1, "bed", 5, 5)], [facing_bed(10, (1,), ("bed",))])
    assert judge(v, memory, gap=close_distance(S, RING) + 0.1) is None and not v.close and v.last_anchor is None
    assert judge(v, memory) is None and v.close and v.last_anchor == 10 and v.tally.in_view == 0
    assert v.judging


def test_frames_taken_close_just_before_the_verification_of_a_hypothesis_began_count_with_recent_view_s():
    """A robot that drove up to a candidate the reasoning layer put forward saw it from as near as a
    view cell would stand: those frames confirm it at once, where without them it drove off to a
    view cell for two more. A candidate taken for its label alone gets no such frames: the frame
    that made a spurious box would be its first view."""
    def seen(aid: int, stamp: float, x: float = 3.5) -> Anchor:
        return Anchor(aid, camera_pose_from_base(Pose2D(x, 5.0, 0.0), 0.4), (1,), ("bed",), stamp=stamp)

    memory = Memory([node(1, "bed", 5, 5)], [seen(9, 2.0), seen(10, 8.5), seen(11, 9.5)])
    recent = S.model_copy(update={"recent_view_s": 2.0})
    hypothesis = Cand(1, "bed", CENTRE, LO, HI, source=verif.HYPOTHESIS)
    v = verif.Verification(10.0)
    judged = v.judge(recent, 1.0, RING, memory, None, hypothesis, ["bed"], "bed")
    assert judged is not None and judged.confirmed and v.tally.in_view == 2  # anchor 9 is too old
    v = verif.Verification(10.0)
    assert v.judge(recent, 1.0, RING, memory, None, BED, ["bed"], "bed") is None and v.tally.in_view == 0
    v = verif.Verification(10.0)
    none = S.model_copy(update={"recent_view_s": 0.0})
    assert v.judge(none, 1.0, RING, memory, None, hypothesis, ["bed"], "bed") is None  # only frames after the start
    # beyond the view ring (1.3 m from the box), though within the close distance: not a view cell's frame
    assert RING < 1.3 < close_distance(S, RING)
    far = Memory([node(1, "bed", 5, 5)], [seen(10, 8.5, x=3.2), seen(11, 9.5, x=3.2)])
    v = verif.Verification(10.0)
    assert v.judge(recent, 1.0, RING, far, None, hypothesis, ["bed"], "bed") is None and v.tally.in_view == 0


def test_the_window_of_earlier_frames_is_measured_in_the_frames_own_time_not_the_clock():
    """A stepped clock ticks 0.1 s per action while the frames' stamps advance 0.5 s: a window
    over frames, measured from the clock's start, took in nearly every frame of the mission. It
    runs back from the newest frame's stamp when the verification began."""
    def seen(aid: int, stamp: float) -> Anchor:
        return Anchor(aid, camera_pose_from_base(Pose2D(3.5, 5.0, 0.0), 0.4), (1,), ("bed",), stamp=stamp)

    @dataclass
    class Stamped(Memory):
        stamp: float = 0.0

    memory = Stamped([node(1, "bed", 5, 5)], [seen(9, 50.0), seen(10, 97.0)], stamp=100.0)
    recent = S.model_copy(update={"recent_view_s": 5.0})
    hypothesis = Cand(1, "bed", CENTRE, LO, HI, source=verif.HYPOTHESIS)
    v = verif.Verification(20.0)  # the clock's time: 200 ticks, the frames' 100 s
    assert v.judge(recent, 1.0, RING, memory, None, hypothesis, ["bed"], "bed") is None
    assert v.start_stamp == 100.0 and v.tally.in_view == 1 and v.tally.fresh == 1  # anchor 9 is 50 s old
    wide = S.model_copy(update={"recent_view_s": 60.0})
    v = verif.Verification(20.0)
    judged = v.judge(wide, 1.0, RING, memory, None, hypothesis, ["bed"], "bed")
    assert judged is not None and judged.confirmed and v.tally.in_view == 2


def test_fresh_views_of_the_candidate_confirm_it_and_name_no_other_node():
    v = verif.Verification(0.0)
    memory = Memory([node(1, "bed", 5, 5)], [facing_bed(10)])
    judge(v, memory)
    memory.anchors += [facing_bed(11, (1,), ("bed",)), facing_bed(12, (1,), ("bed",))]
    judged = judge(v, memory)
    assert judged is not None and judged.confirmed and judged.node is None and judged.log == ""
    assert judged.feedback == "confirmed bed #1: 2 fresh views in 2 frames"


def test_a_supporting_node_the_fresh_views_observed_more_often_is_the_object_found():
    v = verif.Verification(0.0)
    other = node(8, "bed", 5.3, 5.0)
    memory = Memory([node(1, "bed", 5, 5), other], [facing_bed(10)])
    judge(v, memory)
    memory.anchors += [facing_bed(11, (1, 8), ("bed",)), facing_bed(12, (8,), ("bed",))]
    judged = judge(v, memory)
    assert judged is not None and judged.confirmed and judged.node is other
    assert judged.log == "#1 confirmed by views of #8 (2 of them): going to #8"


def test_a_described_instance_hands_on_only_to_the_same_object_seen_again_not_to_a_touching_neighbour():
    """Chairs around a table: the neighbour whose box touches the candidate's (within the support
    margin) is another instance, whose relations the reasoning layer never checked."""
    for other_x, described, handed in ((6.05, True, False), (6.05, False, True), (5.3, True, True)):
        v = verif.Verification(0.0)
        other = node(8, "bed", other_x, 5.0)
        memory = Memory([node(1, "bed", 5, 5), other], [facing_bed(10)])
        v.judge(S, 1.0, RING, memory, None, BED, ["bed"], "bed", described)
        memory.anchors += [facing_bed(11, (1, 8), ("bed",)), facing_bed(12, (8,), ("bed",))]
        judged = v.judge(S, 1.0, RING, memory, None, BED, ["bed"], "bed", described)
        assert judged is not None and judged.confirmed and (judged.node is other) == handed, (other_x, described)


def test_frames_in_view_without_detections_reject_the_candidate():
    v = verif.Verification(0.0)
    memory = Memory([node(1, "bed", 5, 5)], [facing_bed(10)])
    judge(v, memory)
    memory.anchors += [facing_bed(i) for i in range(11, 15)]
    judged = judge(v, memory)
    assert judged is not None and not judged.confirmed and judged.verdict.permanent
    assert judged.verdict.feedback == "rejected: detected in 0 of 4 frames in view"


def test_the_timeout_defers_before_any_move():
    v = verif.Verification(0.0)
    move = v.next_move(S, elapsed=S.timeout_s + 1.0, sent=False, state="pending", cell=None, mapped=True,
                       stalled=lambda: True)
    assert move == ViewMove(reason="no fresh views before the timeout")
    assert verif.move_verdict(move, None) == deferred("no fresh views before the timeout")


def test_the_stall_clock_is_read_only_when_it_decides_the_move():
    v, reads = verif.Verification(0.0), []
    v.close = True
    move = v.next_move(S, elapsed=0.0, sent=True, state="reached", cell=np.array([3.5, 5.0]), mapped=True,
                       stalled=lambda: reads.append(1) or False)
    assert move.tries == ("glance",) and reads == []


def test_a_failed_view_cell_is_set_aside_and_the_closer_cell_flag_cleared():
    v = verif.Verification(0.0)
    v.closing = False
    cell = np.array([3.5, 5.0])
    move = v.next_move(S, elapsed=0.0, sent=True, state="failed", cell=cell, mapped=True, stalled=lambda: False)
    assert move.tries == ("view", "closer", "unknown", "remap") and v.excluded == [cell]
    v.closing = True
    v.next_move(S, elapsed=0.0, sent=True, state="failed", cell=cell, mapped=True, stalled=lambda: False)
    assert not v.closing and len(v.excluded) == 1  # a closer cell is not a view cell: not set aside


def test_without_a_map_or_pose_only_view_cells_and_glances_are_tried():
    v = verif.Verification(0.0)
    move = v.next_move(S, elapsed=0.0, sent=False, state="pending", cell=None, mapped=False, stalled=lambda: False)
    assert move.tries == ("view",)
    assert verif.move_verdict(move, None) is None


def test_a_remap_deferral_follows_only_when_no_earlier_try_went():
    move = ViewMove(tries=("view", "closer", "unknown", "remap"))
    assert verif.move_verdict(move, None) == deferred("no reachable view point", remap=True)
    assert verif.move_verdict(move, "closing in on bed #1") is None
    assert verif.move_verdict(ViewMove(reason="no view cell shows it"), None) == deferred("no view cell shows it")


def test_a_new_view_cell_counts_the_frames_that_could_not_show_the_candidate_afresh():
    v = verif.Verification(0.0)
    v.close, v.tally = True, verif.Tally(unseen=S.reposition_after)
    cell = np.array([3.5, 5.0])
    move = v.next_move(S, elapsed=0.0, sent=True, state="reached", cell=cell, mapped=True, stalled=lambda: False)
    assert move.tries == ("view", "glance") and move.another_cell and v.tally.unseen == 0 and v.excluded == [cell]
    assert verif.view_feedback("bed", 1, True) == "verifying bed #1 from another cell"
    assert verif.view_feedback("bed", 1, False) == ""


def test_glances_alternate_left_and_right_of_facing_the_candidate():
    v = verif.Verification(0.0)
    left, right = v.glance(Pose(3.0, 5.0), BED, 35.0), v.glance(Pose(3.0, 5.0), BED, 35.0)
    assert math.isclose(left.yaw, math.radians(35.0)) and math.isclose(right.yaw, -math.radians(35.0))
    assert (left.x, left.y, left.tolerance, left.kind, left.ref_id) == (3.0, 5.0, verif.GLANCE_TOLERANCE, "look", 1)
    assert v.glances == 2


def test_a_closer_move_toward_a_far_candidate_goes_on_known_floor_and_says_so():
    v, memory = verif.Verification(0.0), Memory([node(1, "bed", 5, 5)])
    goal = v.fallback("closer", S, room(), memory, BED, np.array([1.0, 5.0]), 3.5, RING, ["bed"], "bed")
    assert goal is not None and not goal.through_unknown and goal.tolerance == verif.CLOSER_TOLERANCE
    assert float(np.hypot(*(goal.cell - [5.0, 5.0]))) < 3.5
    where = f"({goal.cell[0]:.2f}, {goal.cell[1]:.2f})"
    assert goal.log == f"no view cell of #1 on the map yet: closing in to {where}, 3.5 m from it now"
    assert goal.feedback == "closing in on bed #1" and v.closer_moves == 1 and v.closing


def test_closer_moves_run_out_and_other_kinds_send_nothing():
    v, memory = verif.Verification(0.0), Memory([node(1, "bed", 5, 5)])
    v.closer_moves = S.closer_moves
    assert v.fallback("closer", S, room(), memory, BED, np.array([1.0, 5.0]), 3.5, RING, ["bed"], "bed") is None
    assert v.fallback("remap", S, room(), memory, BED, np.array([1.0, 5.0]), 3.5, RING, ["bed"], "bed") is None
    assert not v.closing


def test_a_way_through_unknown_floor_is_only_for_a_candidate_observed_often_enough():
    v, memory = verif.Verification(0.0), Memory([node(1, "bed", 5, 5)])
    seen_once = Cand(1, "bed", CENTRE, LO, HI, n_obs=1)
    assert v.fallback("unknown", S, room(), memory, seen_once, np.array([1.0, 5.0]), 3.5, RING, ["bed"], "bed") is None
    seen_often = Cand(1, "bed", CENTRE, LO, HI, n_obs=S.unknown_min_observations)
    goal = v.fallback("unknown", S, room(), memory, seen_often, np.array([1.0, 5.0]), 3.5, RING, ["bed"], "bed")
    assert goal is not None and goal.through_unknown and goal.tolerance == verif.UNKNOWN_TOLERANCE
    assert goal.feedback == "heading for bed #1 through unknown floor" and v.unknown_moves == 1


def test_a_much_nearer_candidate_is_verified_first_and_the_switch_says_why():
    near, far = Cand(2, "bed", CENTRE, LO, HI), Cand(3, "bed", CENTRE, LO, HI)
    switch = verif.nearer_switch(S, 4.0, [(2.5, far), (1.0, near)], 1)
    assert switch is not None and switch.candidate is near
    assert switch.log == "#2 is 1.0 m or more nearer than #1: verifying it first"
    assert switch.feedback == "verifying bed #2 first"
    assert verif.nearer_switch(S, 1.5, [(1.0, near)], 1) is None


def test_a_deferral_is_for_good_at_the_last_allowed_one_and_a_map_deferral_only_while_remaps_remain():
    once = [(1, "deferred")] * (S.max_deferrals - 1)
    assert verif.posting(S, deferred("x"), 1, once, 0, True).permanent
    assert not verif.posting(S, deferred("x"), 1, [], 0, True).permanent
    remap = verif.posting(S, deferred("x", remap=True), 1, once, 0, True)
    assert remap.remap and not remap.permanent
    assert not verif.posting(S, deferred("x", remap=True), 1, [], 0, False).remap
    assert verif.posting(S, Verdict("rejected", "x"), 1, [], 0, True).flags() == \
        {"permanent": True, "requalify": False, "remap": False}


def test_a_candidate_takes_the_memory_nodes_current_fields():
    label, center, lo, hi, confidence, n_obs = verif.node_fields(node(1, "bed", 5, 5, 0.7, 4))
    assert (label, confidence, n_obs) == ("bed", 0.7, 4) and center.dtype == np.float64
    assert np.array_equal(lo, LO) and np.array_equal(hi, HI)


def test_a_flipped_vote_defers_a_candidate_unless_frames_of_it_are_judged_then_judged_as_chosen():
    flipped = Cand(1, "sofa", CENTRE, LO, HI)  # a bed whose node's vote now reads "sofa"
    v = verif.Verification(0.0)
    verdict, cand = v.read_label(S, ["bed"], flipped, "bed")
    assert verdict is not None and verdict.requalify and cand is flipped and v.flipped_to is None
    v.close = True  # the robot stands judging it
    verdict, cand = v.read_label(S, ["bed"], flipped, "bed")
    assert verdict is None and cand.label == "bed" and v.flipped_to == "sofa"
    # two fresh views that read it as the sofa it now is: deferred
    sofa = [Anchor(10 + k, camera_pose_from_base(Pose2D(3.5, 5.0, 0.0), 0.4), (1,), ("sofa",)) for k in range(3)]
    memory = Memory([node(1, "sofa", 5, 5)], sofa[:1])
    assert v.judge(S, 1.0, RING, memory, None, cand, ["bed"], "bed") is None  # the newest anchor starts the count
    judged = v.judge(S, 1.0, RING, Memory(memory.objects, sofa), None, cand, ["bed"], "bed")
    assert judged is not None and judged.verdict.requalify and "label is now 'sofa'" in judged.verdict.reason
    v = verif.Verification(0.0)
    v.close = True
    assert v.read_label(S.model_copy(update={"flip_reads": 0}), ["bed"], flipped, "bed")[0] is not None


def test_the_candidates_own_node_supports_it_whatever_its_vote_reads_now():
    # a bed read once as a sofa flipped the node's vote: frames that observe the node are still its views
    memory = Memory([node(1, "sofa", 5, 5), node(3, "sofa", 3.0, 5.0)])
    targets, support, _ = verif.evidence_inputs(S, memory, ["bed"], BED)
    assert targets == {"bed"} and support == {1}


def test_nothing_hides_a_candidate_but_other_objects_off_its_footprint():
    memory = Memory([node(1, "bed", 5, 5), node(2, "bed", 5.6, 5.0), node(3, "sofa", 3.0, 5.0)])
    targets, support, hiding = verif.evidence_inputs(S, memory, ["bed"], BED)
    assert targets == {"bed"} and support == {1, 2}
    assert hiding is not None and len(hiding[0]) == 1 and np.allclose(hiding[0][0][:2], [2.55, 4.55])
    assert verif.sight_of(S, memory, ["bed"], BED) is None  # no camera known: any cell sees it
