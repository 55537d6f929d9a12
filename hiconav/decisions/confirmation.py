"""The target confirmation policy: what evidence confirms, defers or rejects a candidate.

A real object is detected in most frames that show it; a spurious box lands at a random place in
a random frame, so one that happened to fall on the candidate's place is outvoted by the frames
that show nothing there. This module judges each new memory anchor (keyframe) made while the
robot is close (could its camera show the candidate? did it observe a target-labelled node at the
candidate's place, a fresh view? did it read a target label?), keeps the tally, and turns it into
a verdict (``Verdict``: confirmed, deferred or rejected, with its reason and flags), names the
supporting node the fresh views observed most, and decides whether a deferral is for good.

Pure: memory objects and anchors, a grid snapshot, plain numbers and a ``VerifySettings``
section in; frozen tallies and verdicts out. Nothing here reads the mission context, sends a
goal, ticks a tree or talks to an actor.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Callable, Iterable, Sequence

import numpy as np

from hiconav.decisions.config import VerifySettings
from hiconav.decisions.geometry import anchor_sees, wall_clear
from hiconav.decisions.viewing import box_distance
from hiconav.geometry import centre_in_footprint


def target_labels(task_targets: Iterable[str] | None, label: str) -> set[str]:
    """The task's target labels and the candidate's own ``label``."""
    return set(task_targets or ()) | {label}


def support_ids(objects: Iterable[Any], labels: set[str], box_min: np.ndarray, box_max: np.ndarray,
                margin: float) -> set[int]:
    """Ids of the memory ``objects`` labelled one of ``labels`` whose footprint overlaps the
    candidate's (box (3,) world) grown by ``margin`` m: the nodes that support it.

    Counting every same-label node within a radius lets spurious boxes cast while the robot
    stares at a false candidate confirm it; an overlapping box is the same object seen again."""
    lo, hi = np.asarray(box_min)[:2] - margin, np.asarray(box_max)[:2] + margin
    return {int(o.id) for o in objects if o.label in labels
            and np.all(np.asarray(o.box_min)[:2] <= hi) and np.all(np.asarray(o.box_max)[:2] >= lo)}


def support_confidence(objects: Iterable[Any], ids: set[int]) -> float:
    """Best confidence among the supporting nodes ``ids`` (0 with none)."""
    return max((float(o.confidence) for o in objects if int(o.id) in ids), default=0.0)


def support_observations(objects: Iterable[Any], ids: set[int]) -> int:
    """Observations of the supporting nodes ``ids``, summed."""
    return sum(int(o.n_obs) for o in objects if int(o.id) in ids)


def detected_too_near(anchor: Any, box_min: np.ndarray, box_max: np.ndarray, labels: dict[int, str],
                      targets: set[str], near: float) -> bool:
    """True when ``anchor`` (which detected one of ``targets``) placed no target label on a node
    (``labels``: node id -> label) and its camera stood within ``near`` m of the candidate's box
    (3,) world (``near`` 0: never).

    A depth camera reads nothing nearer than its minimum range, so a detection of an object that
    close has no 3D points and lands on no node; counted as a frame that missed the candidate, it
    rejects a real object the robot stands next to. Within that range nothing else can be what
    the detector saw: a detection placed elsewhere explains its label instead."""
    if near <= 0.0 or any(labels.get(int(i)) in targets for i in anchor.object_ids):
        return False
    return camera_gap(anchor, box_min, box_max) <= near


def camera_gap(anchor: Any, box_min: np.ndarray, box_max: np.ndarray) -> float:
    """How far (m, in plan) ``anchor``'s camera stood from the candidate's box (3,) world."""
    return box_distance(box_min, box_max, np.asarray(anchor.T_world_cam, dtype=np.float64)[:2, 3])


def frames_since(anchors: Sequence[Any], last: int | None,
                 earlier: Callable[[Any], bool] | None = None) -> tuple[list[Any], int | None]:
    """The anchors newer than ``last`` (the newest anchor already judged), oldest first, and the
    new ``last``. With ``last`` None (the robot just came close) only those ``earlier`` accepts
    (none without it), and the newest anchor becomes ``last``.

    Anchors, not the memory's version, are the frames: the version also moves when anchor
    pruning removes keyframes, and those "frames" show nothing."""
    if not anchors:
        return [], last
    newest = max(int(a.id) for a in anchors)
    if last is None:
        kept = [] if earlier is None else [a for a in anchors if earlier(a)]
        return sorted(kept, key=lambda a: int(a.id)), newest
    fresh = [a for a in anchors if int(a.id) > last]
    if not fresh:
        return [], last
    return sorted(fresh, key=lambda a: int(a.id)), newest


@dataclass(frozen=True)
class Tally:
    """The frames judged so far for one candidate.

    in_view: frames whose camera could show the candidate; fresh: those that observed it (or
    detected its label too near for depth); target_reads: fresh views that read a target label;
    unseen: frames, since the last change of view cell, whose camera could not show it;
    fresh_by: (supporting node id, fresh views that observed it), in order of first sight.
    """

    in_view: int = 0
    fresh: int = 0
    target_reads: int = 0
    unseen: int = 0
    fresh_by: tuple[tuple[int, int], ...] = ()


def recent_close(anchor: Any, *, since: float, box_min: np.ndarray, box_max: np.ndarray, close: float) -> bool:
    """Whether ``anchor`` is a frame taken before a verification began that it may count: stamped
    ``since`` or later (sensor time: the stamp of the newest frame when it began, less
    ``recent_view_s``), its camera within ``close`` m (the view ring) of the candidate's box (3,)
    world.

    A robot that drove up to a candidate saw it from where a view cell would stand before the
    verification began (a search that comes upon it on its way); judging only the frames after
    that start sends it off to a view cell for views it already has, and back."""
    return float(anchor.stamp) >= since and camera_gap(anchor, box_min, box_max) <= close


def read_labels(anchor: Any, observed: set[int]) -> set[str]:
    """The labels a frame read the candidate as: those of the detections it placed on the
    ``observed`` supporting nodes; with none placed, or from a view that does not record which
    label went where (``object_labels`` empty), every label the frame saw.

    A look-alike beside a target (a sink by a toilet, an armchair by a sofa) is observed in the
    same frames as the target; read by every label of the frame, it counted as read as the
    target, and the frames of a bathroom confirmed the sink."""
    ids = tuple(getattr(anchor, "object_ids", ()))
    per_object = tuple(getattr(anchor, "object_labels", ()))
    if observed and len(per_object) == len(ids):
        return {lab for i, labs in zip(ids, per_object) if int(i) in observed for lab in labs}
    return set(getattr(anchor, "labels_seen", ()))


def judge_frames(tally: Tally, frames: Sequence[Any], *, objects: Sequence[Any], grid: Any, center: np.ndarray,
                 box_min: np.ndarray, box_max: np.ndarray, support: set[int],
                 hiding: tuple[np.ndarray, np.ndarray] | None, targets: set[str], near: float) -> Tally:
    """``tally`` with the new anchors ``frames`` (oldest first) judged for the candidate (centre
    and box (3,) world; ``support``: its supporting node ids; ``hiding``: the blockers' boxes,
    ``viewing.blockers``; ``targets``: the target labels; ``near``: ``near_view_distance``).

    A frame shows the candidate when its camera could (its centre inside the image, no memory
    box on the line of sight, ``anchor_sees``, and no wall on the map between them: an occupied
    cell no memory object explains, on the line to the candidate's top, its highest part being
    what shows over low furniture), or when it placed a detection on a supporting node in 3D,
    whatever the map's walls and the memory's boxes suggest: the tests keep frames that could
    not show it from counting as misses, not frames that saw it from counting as views."""
    if not frames:
        return tally
    if grid is not None:
        cams = np.array([np.asarray(a.T_world_cam, dtype=np.float64)[:3, 3] for a in frames])
        known = [(np.asarray(o.box_min), np.asarray(o.box_max)) for o in objects]
        walls_clear = wall_clear(grid, cams[:, :2], np.asarray(center, dtype=np.float64)[:2], known,
                                 heights=(cams[:, 2], float(np.asarray(box_max)[2])))
    else:
        walls_clear = np.ones(len(frames), dtype=bool)
    labels = {int(o.id): o.label for o in objects}
    in_view, fresh, reads, unseen = tally.in_view, tally.fresh, tally.target_reads, tally.unseen
    fresh_by = dict(tally.fresh_by)
    for a, clear in zip(frames, walls_clear):
        observed = support.intersection(int(i) for i in a.object_ids)
        if observed or (clear and anchor_sees(a, center, hiding)):
            in_view += 1
            for i in observed:
                fresh_by[i] = fresh_by.get(i, 0) + 1
            read = bool(targets.intersection(read_labels(a, observed)))
            fresh_view = bool(observed) or (read and detected_too_near(a, box_min, box_max, labels, targets, near))
            fresh += int(fresh_view)
            reads += int(fresh_view and read)
        else:
            unseen += 1
    return Tally(in_view, fresh, reads, unseen, tuple(fresh_by.items()))


@dataclass(frozen=True)
class Verdict:
    """The end of a verification: ``outcome`` "confirmed", "deferred" or "rejected" (for good),
    ``reason`` (the text the mission logs), ``requalify`` (due again once observed as a target
    again), ``remap`` (due again once the map around it has grown)."""

    outcome: str
    reason: str = ""
    requalify: bool = False
    remap: bool = False

    @property
    def permanent(self) -> bool:
        return self.outcome == "rejected"

    @property
    def feedback(self) -> str:
        """The feedback text of a rejection or deferral: "rejected: <reason>" or "deferred: <reason>"."""
        return f"{'rejected' if self.permanent else 'deferred'}: {self.reason}"


def deferred(reason: str, requalify: bool = False, remap: bool = False) -> Verdict:
    """A deferral with its ``reason``."""
    return Verdict("deferred", reason, requalify, remap)


def label_verdict(task_targets: Iterable[str] | None, label: str, source: str, judging: bool = False
                  ) -> Verdict | None:
    """Deferred (requalify) when a candidate taken for its label (``source`` "memory-label") now
    carries a ``label`` that is not a target, unless frames of it are being judged
    (``judging``); else None.

    Deferred, not rejected: a node's label is a vote over its observations and flips back and
    forth between confusable labels, so a real object read as a look-alike for a while comes
    back. While the robot stands judging it, the fresh frames are that vote's next ballots: a
    node observed twice, once read as a look-alike (a toilet as a sink, a plant as a vase), flips
    on one frame, and the frames the robot came for settle it (``evidence_verdict`` confirms only
    what most fresh views read as a target, and defers what they read otherwise)."""
    if judging or not label_flipped(task_targets, label, source):
        return None
    return deferred(f"label is now {label!r}", requalify=True)


def label_flipped(task_targets: Iterable[str] | None, label: str, source: str) -> bool:
    """Whether a candidate taken for its label (``source`` "memory-label") now carries a node
    ``label`` that is not one of the ``task_targets``: its node's vote flipped to a look-alike.
    ``label_verdict`` defers it; while judging, it is judged on as the label it was chosen for
    (``Verification.read_label``)."""
    return task_targets is not None and label not in task_targets and source == "memory-label"


def flipped_verdict(settings: VerifySettings, tally: Tally, label: str) -> Verdict | None:
    """For a candidate judged on after its node's vote flipped to ``label``, a look-alike
    (``label_flipped``, judged on): deferred (requalify) once ``flip_reads`` fresh views (``tally``)
    read it as something other than a target and none as a target; else None (judge on).

    The vote flips both ways: a real target read once as a look-alike comes back in the next
    frames, and a look-alike first read as the target keeps reading as what it is; two such
    frames are enough to leave it, not the ``max_view_frames`` a target-labelled node gets."""
    if settings.flip_reads <= 0 or tally.target_reads > 0:
        return None
    others = tally.fresh - tally.target_reads
    if others < settings.flip_reads:
        return None
    return deferred(f"label is now {label!r}, as {others} fresh views read it", requalify=True)


def withdrawn(source: str, object_id: int, taken_back: Iterable[int]) -> bool:
    """True when a candidate the reasoning layer offered (``source`` "hypothesis") is among the
    offers it has since taken back (``taken_back``: ``RuledOut.withdrawn``).

    An instance offered undecided, for want of a clearer one after the marginal patience, goes
    on being judged while the robot drives to it, on the nodes mapped since; when a verdict on
    it fails, the robot that stopped at it anyway stopped at an instance the description rules
    out (``hiconav.reasoning.unresolved.withdrawn_offers`` decides which offers are taken back)."""
    return source == "hypothesis" and int(object_id) in set(taken_back)


def timeout_verdict(settings: VerifySettings, elapsed: float) -> Verdict | None:
    """Deferred when ``elapsed`` clock seconds have passed since the verification started
    without a verdict (``timeout_s``); else None."""
    return deferred("no fresh views before the timeout") if elapsed > settings.timeout_s else None


def evidence_verdict(settings: VerifySettings, tally: Tally, *, label: str, n_obs: int, objects: Sequence[Any],
                     support: set[int]) -> Verdict | None:
    """The verdict the frames judged so far (``tally``) give a candidate read as ``label``,
    observed ``n_obs`` times, supported by the nodes ``support`` among ``objects``; None: judge on.

    - Confirmed: at least ``min_fresh_views`` fresh views, at least ``min_detection_rate`` of
      the frames in view, most of them read as a target (a node's label is a vote over all its
      observations: a look-alike read twice as the target in the first frames keeps its label
      while frames that read it otherwise would confirm it), and the supporting nodes score
      ``min_confidence`` or were observed ``confident_observations`` times (detectors score
      small objects low in every frame: many observations are evidence the score is not).
    - Deferred: confirmed but scored low (the views were fresh); or there, but read as
      something else as often as not by ``max_view_frames`` frames (requalify: due again once
      observed as the target again).
    - Rejected for good: ``max_view_frames`` frames in view without enough fresh views; or,
      for an object observed at most ``unseen_max_observations`` times, none in the first
      ``unseen_view_frames`` (a sequential test: a real object is missed in 4 frames in a row
      about 1% of the time, a spurious box is almost never seen twice; objects observed more
      often get the full count, as a real one seen many times may be a sliver of a box)."""
    fresh, frames = tally.fresh, tally.in_view
    seen = fresh >= settings.min_fresh_views and fresh >= settings.min_detection_rate * frames
    read = tally.target_reads > fresh - tally.target_reads
    if seen and read:
        conf = support_confidence(objects, support)
        observations = support_observations(objects, support)
        if conf >= settings.min_confidence or observations >= settings.confident_observations:
            return Verdict("confirmed", f"{fresh} fresh views in {frames} frames")
        return deferred(f"confidence {conf:.2f} below {settings.min_confidence}")
    if seen and frames >= settings.max_view_frames:
        return deferred(f"read as {label!r} in {tally.target_reads} of {fresh} fresh views", requalify=True)
    unseen = fresh == 0 and frames >= settings.unseen_view_frames and int(n_obs) <= settings.unseen_max_observations
    if frames >= settings.max_view_frames or unseen:
        return Verdict("rejected", f"detected in {fresh} of {frames} frames in view")
    return None


def confirmed_node(tally: Tally, candidate_id: int) -> tuple[int, int] | None:
    """The supporting node (id, fresh views) that more fresh views observed than the candidate
    itself (the first of equals), or None: the candidate is the object found.

    Fresh views count every target-labelled node overlapping the candidate's box; when the
    detector saw another node there more often, that node is the object found (a look-alike
    whose box touches the target's is confirmed by views of the target)."""
    best = max(tally.fresh_by, key=lambda kv: kv[1], default=None)
    if best is None or best[1] <= dict(tally.fresh_by).get(int(candidate_id), 0):
        return None
    return best


def same_object(a_min: np.ndarray, a_max: np.ndarray, b_min: np.ndarray, b_max: np.ndarray) -> bool:
    """Whether two nodes' boxes ((3,) world each) are one object seen twice rather than two side
    by side: the footprint of either holds the other's centre."""
    return centre_in_footprint(a_min, a_max, b_min, b_max) or centre_in_footprint(b_min, b_max, a_min, a_max)


def for_good(settings: VerifySettings, permanent: bool, remap: bool, deferrals: int) -> bool:
    """Whether a verdict excludes the candidate for good: rejected, or deferred for the
    ``max_deferrals``-th time (``deferrals``: this one included; map deferrals, ``remap``, do not
    count and never are)."""
    return permanent or (not remap and deferrals >= settings.max_deferrals)


def restart_unseen(tally: Tally) -> Tally:
    """``tally`` with the frames that could not show the candidate counted afresh (a new cell)."""
    return replace(tally, unseen=0)


__all__ = ["Tally", "Verdict", "camera_gap", "confirmed_node", "deferred", "detected_too_near", "evidence_verdict", "for_good",
           "flipped_verdict", "frames_since", "judge_frames", "label_flipped", "label_verdict", "read_labels", "recent_close", "restart_unseen", "same_object", "support_confidence",
           "support_ids", "support_observations", "target_labels", "timeout_verdict"]
