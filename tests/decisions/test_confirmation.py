"""The target confirmation policy (hiconav.decisions.confirmation) on hand-built memory nodes and
anchors: which nodes support a candidate, which frames count, and the verdicts the tally gives."""

from __future__ import annotations

from functools import partial

import numpy as np

from hiconav.decisions import confirmation as conf
from hiconav.decisions.config import VerifySettings
from hiconav.types import Pose2D, camera_pose_from_base

from .fakes import Anchor, Node

S = VerifySettings(min_fresh_views=2, max_view_frames=8, unseen_view_frames=4)
CENTRE = np.array([5.0, 5.0, 0.4])
LO, HI = CENTRE - [0.5, 0.5, 0.4], CENTRE + [0.5, 0.5, 0.4]


def node(oid: int, label: str, x: float, y: float, confidence: float = 0.9, n_obs: int = 1) -> Node:
    c = np.array([x, y, 0.4])
    return Node(oid, label, c - [0.5, 0.5, 0.4], c + [0.5, 0.5, 0.4], confidence, n_obs)


def facing_bed(aid: int, x: float = 3.5, object_ids: tuple = (), labels_seen: tuple = ()) -> Anchor:
    """A camera 0.4 m up at (x, 5) looking east at the candidate at (5, 5)."""
    return Anchor(aid, camera_pose_from_base(Pose2D(x, 5.0, 0.0), 0.4), object_ids, labels_seen)


def judge(frames, objects, support, near=0.6, hiding=None) -> conf.Tally:
    return conf.judge_frames(conf.Tally(), frames, objects=objects, grid=None, center=CENTRE, box_min=LO, box_max=HI,
                             support=support, hiding=hiding, targets={"bed"}, near=near)


def test_target_labelled_nodes_overlapping_the_candidate_support_it_others_do_not():
    objects = [node(1, "bed", 5.0, 5.0), node(2, "bed", 5.9, 5.0), node(3, "bed", 7.0, 5.0), node(4, "sofa", 5.0, 5.2)]
    assert conf.support_ids(objects, {"bed"}, LO, HI, 0.15) == {1, 2}
    assert conf.support_confidence([node(1, "bed", 5, 5, 0.2), node(2, "bed", 5, 5, 0.6)], {1, 2}) == 0.6
    assert conf.support_confidence(objects, set()) == 0.0
    assert conf.support_observations([node(1, "bed", 5, 5, n_obs=3), node(2, "bed", 5, 5, n_obs=4)], {1, 2}) == 7


def test_the_target_labels_are_the_tasks_and_the_candidates_own():
    assert conf.target_labels(["bed", "couch"], "sofa") == {"bed", "couch", "sofa"}
    assert conf.target_labels(None, "sofa") == {"sofa"}


def test_frames_from_before_the_robot_came_close_do_not_count():
    anchors = (facing_bed(3), facing_bed(5))
    assert conf.frames_since(anchors, None) == ([], 5)
    assert conf.frames_since(anchors, 5) == ([], 5)
    assert conf.frames_since((), 5) == ([], 5)
    later = anchors + (facing_bed(7), facing_bed(6))
    frames, last = conf.frames_since(later, 5)
    assert [a.id for a in frames] == [6, 7] and last == 7


def test_recent_frames_from_near_the_candidate_count_when_the_robot_comes_close():
    def at(aid: int, x: float, stamp: float) -> Anchor:
        return Anchor(aid, camera_pose_from_base(Pose2D(x, 5.0, 0.0), 0.4), stamp=stamp)

    anchors = (at(1, 3.5, 1.0), at(2, 0.5, 4.0), at(3, 3.0, 5.0), at(4, 3.8, 6.0))
    keep = partial(conf.recent_close, since=3.0, box_min=LO, box_max=HI, close=2.0)
    frames, last = conf.frames_since(anchors, None, keep)
    # 1 is too old, 2 stood 4 m from the box; 3 (1.5 m) and 4 (0.7 m) count, oldest first
    assert [a.id for a in frames] == [3, 4] and last == 4
    assert conf.frames_since(anchors, 4, keep) == ([], 4)  # only when the robot first comes close
    assert conf.frames_since(anchors, None) == ([], 4)
    assert not conf.recent_close(at(5, 3.5, 2.9), since=3.0, box_min=LO, box_max=HI, close=2.0)


def test_a_frame_that_observed_a_supporting_node_is_a_fresh_view():
    objects = [node(1, "bed", 5.0, 5.0)]
    tally = judge([facing_bed(1, object_ids=(1,), labels_seen=("bed",)), facing_bed(2)], objects, {1})
    assert (tally.in_view, tally.fresh, tally.target_reads, tally.unseen) == (2, 1, 1, 0)
    assert tally.fresh_by == ((1, 1),)


def test_a_frame_reads_the_candidate_by_the_label_it_placed_on_it_not_by_its_neighbours():
    objects = [node(1, "bed", 5.0, 5.0), node(2, "sofa", 5.0, 6.2)]
    beside = Anchor(1, facing_bed(1).T_world_cam, (1, 2), ("sofa", "bed"), object_labels=(("sofa",), ("bed",)))
    assert conf.read_labels(beside, {1}) == {"sofa"}
    tally = judge([beside], objects, {1})
    assert (tally.fresh, tally.target_reads) == (1, 0)
    on_it = Anchor(2, facing_bed(1).T_world_cam, (1, 2), ("sofa", "bed"), object_labels=(("bed",), ("sofa",)))
    assert (judge([on_it], objects, {1}).target_reads) == 1
    # a view that does not record which label went where reads every label it saw
    assert conf.read_labels(facing_bed(3, object_ids=(1,), labels_seen=("bed",)), {1}) == {"bed"}


def test_a_frame_whose_camera_looks_away_is_unseen_not_a_miss():
    away = Anchor(1, camera_pose_from_base(Pose2D(3.5, 5.0, np.pi), 0.4))
    tally = judge([away], [node(1, "bed", 5.0, 5.0)], {1})
    assert (tally.in_view, tally.unseen) == (0, 1)


def test_a_frame_with_a_box_between_camera_and_candidate_is_unseen():
    chair = (np.array([[4.0, 4.8, 0.0]]), np.array([[4.2, 5.2, 1.0]]))
    tally = judge([facing_bed(1)], [node(1, "bed", 5.0, 5.0)], {1}, hiding=chair)
    assert (tally.in_view, tally.unseen) == (0, 1)


def test_a_detection_too_near_for_depth_counts_as_a_fresh_view_only_that_near():
    objects = [node(1, "bed", 5.0, 5.0)]
    close = facing_bed(1, x=4.1, labels_seen=("bed",))  # 0.4 m from the box, no node placed
    assert conf.detected_too_near(close, LO, HI, {1: "bed"}, {"bed"}, 0.6)
    assert not conf.detected_too_near(close, LO, HI, {1: "bed"}, {"bed"}, 0.0)
    assert not conf.detected_too_near(facing_bed(2, x=3.0, labels_seen=("bed",)), LO, HI, {1: "bed"}, {"bed"}, 0.6)
    tally = judge([close], objects, {1})
    assert (tally.in_view, tally.fresh, tally.target_reads) == (1, 1, 1)


def test_a_detection_placed_on_another_target_node_explains_the_label_instead():
    placed = facing_bed(1, x=4.1, object_ids=(9,), labels_seen=("bed",))
    assert not conf.detected_too_near(placed, LO, HI, {1: "bed", 9: "bed"}, {"bed"}, 0.6)


def test_enough_fresh_views_read_as_the_target_and_scored_well_confirm():
    tally = conf.Tally(in_view=3, fresh=2, target_reads=2)
    objects = [node(1, "bed", 5.0, 5.0, confidence=0.8)]
    verdict = conf.evidence_verdict(S, tally, label="bed", n_obs=5, objects=objects, support={1})
    assert verdict == conf.Verdict("confirmed", "2 fresh views in 3 frames")


def test_a_confirmed_candidate_scored_low_is_deferred_unless_observed_often():
    tally = conf.Tally(in_view=2, fresh=2, target_reads=2)
    low = [node(1, "bed", 5.0, 5.0, confidence=0.2, n_obs=3)]
    verdict = conf.evidence_verdict(S, tally, label="bed", n_obs=3, objects=low, support={1})
    assert verdict == conf.deferred("confidence 0.20 below 0.3") and not verdict.permanent
    often = [node(1, "bed", 5.0, 5.0, confidence=0.2, n_obs=S.confident_observations)]
    assert conf.evidence_verdict(S, tally, label="bed", n_obs=3, objects=often, support={1}).outcome == "confirmed"


def test_too_few_fresh_views_judge_on():
    tally = conf.Tally(in_view=3, fresh=1, target_reads=1)
    assert conf.evidence_verdict(S, tally, label="bed", n_obs=5, objects=[], support=set()) is None


def test_seen_but_read_as_something_else_as_often_as_not_is_deferred_until_observed_as_the_target():
    tally = conf.Tally(in_view=8, fresh=6, target_reads=3)
    verdict = conf.evidence_verdict(S, tally, label="bed", n_obs=5, objects=[], support=set())
    assert verdict == conf.Verdict("deferred", "read as 'bed' in 3 of 6 fresh views", requalify=True)


def test_rarely_detected_in_max_view_frames_frames_is_rejected_for_good():
    tally = conf.Tally(in_view=8, fresh=1, target_reads=1)
    verdict = conf.evidence_verdict(S, tally, label="bed", n_obs=5, objects=[], support=set())
    assert verdict == conf.Verdict("rejected", "detected in 1 of 8 frames in view") and verdict.permanent


def test_never_detected_in_the_first_frames_rejects_only_a_candidate_observed_a_few_times():
    tally = conf.Tally(in_view=4)
    few = conf.evidence_verdict(S, tally, label="bed", n_obs=S.unseen_max_observations, objects=[], support=set())
    assert few == conf.Verdict("rejected", "detected in 0 of 4 frames in view")
    many = conf.evidence_verdict(S, tally, label="bed", n_obs=S.unseen_max_observations + 1, objects=[], support=set())
    assert many is None


def test_the_node_its_fresh_views_observed_more_than_the_candidate_is_the_object_found():
    assert conf.confirmed_node(conf.Tally(fresh_by=((1, 2), (4, 3), (5, 3))), 1) == (4, 3)
    assert conf.confirmed_node(conf.Tally(fresh_by=((1, 3), (4, 3))), 1) is None
    assert conf.confirmed_node(conf.Tally(), 1) is None


def test_a_label_candidate_whose_label_flipped_is_deferred_to_requalify():
    assert conf.label_verdict(["bed"], "sofa", "memory-label") == conf.Verdict("deferred", "label is now 'sofa'",
                                                                               requalify=True)
    assert conf.label_verdict(["bed"], "sofa", "hypothesis") is None
    assert conf.label_verdict(["bed"], "bed", "memory-label") is None
    assert conf.label_verdict(None, "sofa", "memory-label") is None


def test_a_flipped_label_is_no_verdict_while_the_robot_judges_the_candidate():
    # a toilet observed twice, once read as a sink: the frames the robot stands there for settle it
    assert conf.label_verdict(["toilet"], "sink", "memory-label", judging=True) is None
    assert conf.label_verdict(["toilet"], "sink", "memory-label", judging=False) is not None
    assert conf.label_flipped(["toilet"], "sink", "memory-label")
    assert not conf.label_flipped(["toilet"], "toilet", "memory-label")
    assert not conf.label_flipped(["toilet"], "sink", "hypothesis")


def test_a_flipped_candidate_the_fresh_views_read_as_the_look_alike_is_deferred_after_two():
    assert conf.flipped_verdict(S, conf.Tally(in_view=3, fresh=1, target_reads=0), "sink") is None  # one read
    left = conf.flipped_verdict(S, conf.Tally(in_view=3, fresh=2, target_reads=0), "sink")
    assert left is not None and left.outcome == "deferred" and left.requalify and "'sink'" in left.reason
    # one frame read it as the target: the vote may come back, judge on (evidence_verdict decides)
    assert conf.flipped_verdict(S, conf.Tally(in_view=4, fresh=3, target_reads=1), "sink") is None
    assert conf.flipped_verdict(VerifySettings(flip_reads=0), conf.Tally(fresh=5), "sink") is None


def test_no_verdict_before_the_timeout_defers():
    assert conf.timeout_verdict(S, S.timeout_s) is None
    assert conf.timeout_verdict(S, S.timeout_s + 0.1) == conf.deferred("no fresh views before the timeout")


def test_the_max_deferrals_th_deferral_is_for_good_but_a_map_deferral_never_is():
    assert conf.for_good(S, True, False, 1)
    assert not conf.for_good(S, False, False, S.max_deferrals - 1)
    assert conf.for_good(S, False, False, S.max_deferrals)
    assert not conf.for_good(S, False, True, S.max_deferrals + 5)


def test_a_new_cell_counts_the_frames_that_could_not_show_it_afresh():
    assert conf.restart_unseen(conf.Tally(in_view=2, unseen=5)) == conf.Tally(in_view=2)


def test_two_boxes_are_one_object_when_either_footprint_holds_the_others_centre():
    lo, hi = np.array([0.0, 0.0, 0.0]), np.array([1.0, 1.0, 1.0])
    assert conf.same_object(lo, hi, lo + 0.4, hi + 0.4)  # overlapping by more than half
    assert conf.same_object(lo, hi, np.array([0.4, 0.4, 0.0]), np.array([0.6, 0.6, 0.5]))  # a sliver inside
    assert not conf.same_object(lo, hi, lo + [1.05, 0.0, 0.0], hi + [1.05, 0.0, 0.0])  # side by side
    assert not conf.same_object(lo, hi, lo + 0.8, hi + 0.8)  # corners overlapping


def test_an_offer_the_reasoning_layer_since_ruled_out_is_withdrawn():
    from hiconav.decisions.confirmation import withdrawn

    assert withdrawn("hypothesis", 14, frozenset({14, 3}))
    assert not withdrawn("hypothesis", 14, frozenset({3}))  # a verdict that holds again puts it back
    assert not withdrawn("memory-label", 14, frozenset({14}))  # only the reasoning layer's own offers
