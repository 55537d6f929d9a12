"""One verification in progress: what it has seen so far and what it does next.

A verification walks up to a candidate, judges the frames it makes there and ends in a
verdict. Between the first goal and the verdict it keeps a little state: the frames judged so
far (``confirmation.Tally``), the view cells set aside, the closer and through-unknown moves
made, whether the goal in flight is a closer cell, how many glances it made. ``Verification``
holds that state and answers, from plain inputs, what to do next: the frames' judgement
(``Judgement``), the next ``viewing.ViewMove``, the heading of a glance, the goal of a closer or
through-unknown move with its log and feedback texts (``CellGoal``); ``nearer_switch`` names a
nearer candidate to verify first, and ``posting`` how a verdict is posted (for good, on map
growth).

Pure: grid snapshots, memory objects and anchors, plain numbers and a ``VerifySettings``
section in; frozen decisions out (the state object changes only through its own methods).
Nothing here reads the mission context, sends a goal, ticks a tree or talks to an actor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import partial
from typing import Any, Callable, Iterable, TypeVar

import numpy as np

from hiconav.decisions.cells import camera_of, furniture_boxes, wall_heights
from hiconav.decisions.config import VerifySettings
from hiconav.decisions.confirmation import (Tally, Verdict, confirmed_node, deferred, evidence_verdict, flipped_verdict,
                                            for_good, frames_since, judge_frames, label_flipped, label_verdict,
                                            recent_close, restart_unseen, same_object, support_ids, target_labels,
                                            timeout_verdict)
from hiconav.decisions.geometry import facing
from hiconav.decisions.viewing import (ViewMove, blockers, close_distance, fallback_cell, nearer_candidate, next_view_move,
                                      sight, stall_matters, views_from_here)
from hiconav.types import Goal, wrap_angle

#: goal tolerances (m): a closer cell, a view cell through unknown floor, a glance in place
CLOSER_TOLERANCE, UNKNOWN_TOLERANCE, GLANCE_TOLERANCE = 0.3, 0.2, 0.5
#: the source of a candidate the reasoning layer put forward (``Candidate.source``)
HYPOTHESIS = "hypothesis"

C = TypeVar("C")


@dataclass(frozen=True)
class Judgement:
    """The verdict the frames judged so far give (``verdict``); for a confirmed one, ``node``:
    the memory node of the supporting object that more fresh views observed than the candidate
    (None: the candidate is the object found), ``log``: the text saying so ("" with none), and
    ``feedback``: the behaviour's feedback text."""

    verdict: Verdict
    node: Any = None
    log: str = ""
    feedback: str = ""

    @property
    def confirmed(self) -> bool:
        return self.verdict.outcome == "confirmed"


@dataclass(frozen=True)
class CellGoal:
    """A closer or through-unknown move: go to ``cell`` (2,) world within ``tolerance`` m,
    ``through_unknown`` or on known floor; ``log``: the mission's log text; ``feedback``: the
    behaviour's feedback text."""

    cell: np.ndarray
    tolerance: float
    through_unknown: bool
    log: str
    feedback: str


@dataclass(frozen=True)
class Switch:
    """Verify ``candidate`` first, a nearer one: ``log`` and ``feedback`` say so."""

    candidate: Any
    log: str
    feedback: str


@dataclass(frozen=True)
class Posting:
    """How a verdict is posted (``MissionContext.reject``'s flags): excluded for good
    (``permanent``), due again once observed as a target again (``requalify``) or once the map
    around the candidate has grown (``remap``)."""

    permanent: bool
    requalify: bool
    remap: bool

    def flags(self) -> dict[str, bool]:
        return {"permanent": self.permanent, "requalify": self.requalify, "remap": self.remap}


class Verification:
    """The state of the verification of one candidate that started at clock time ``start``.

    ``excluded``: view cells (2,) world tried and set aside; ``close``: the robot is within the
    close distance of the candidate (this tick); ``last_anchor``: the newest memory anchor
    already judged; ``tally``: the frames judged; ``glances``, ``closer_moves``,
    ``unknown_moves``: the moves of each kind made; ``closing``: the goal in flight is a closer
    cell, not a view cell."""

    def __init__(self, start: float) -> None:
        self.start = start
        self.excluded: list[np.ndarray] = []
        self.close = False
        self.last_anchor: int | None = None
        self.tally = Tally()
        self.glances = self.closer_moves = self.unknown_moves = 0
        self.closing = False
        self.start_stamp: float | None = None  # sensor time of the newest frame at the first judge
        self.flipped_to: str | None = None  # the look-alike the node's vote reads, judged on (``read_label``)

    @property
    def judging(self) -> bool:
        """Frames are judged: the robot is close, or a frame showed the candidate."""
        return self.close or bool(self.tally.in_view)

    def read_label(self, settings: VerifySettings, task_targets: Iterable[str] | None, current: Any,
                   chosen: str) -> tuple[Verdict | None, Any]:
        """The verdict of the label the candidate's node reads now (``current``: the candidate as
        the memory holds it, chosen as ``chosen``), and the candidate to judge: a node whose vote
        flipped to a look-alike is deferred (``confirmation.label_verdict``), unless frames of it
        are being judged (``judging``, with ``flip_reads`` set): then it is judged on as the label
        it was chosen for, and ``judge`` defers it once ``flip_reads`` fresh views read it as the
        look-alike and none as a target (``confirmation.flipped_verdict``)."""
        source, label = getattr(current, "source", None), str(current.label)
        verdict = label_verdict(task_targets, label, source, self.judging and settings.flip_reads > 0)
        judged_on = verdict is None and label_flipped(task_targets, label, source)
        self.flipped_to = label if judged_on else None
        return verdict, (replace(current, label=chosen) if judged_on else current)

    def judge(self, settings: VerifySettings, gap: float, ring: float, memory: Any, grid: Any, cand: Any,
              task_targets: Iterable[str] | None, label: str, described: bool = False) -> Judgement | None:
        """Whether the robot, ``gap`` m from the candidate's box, is close (``viewing.close_distance``
        for the view ring ``ring``); if so, judge the memory's anchors newer than the last judged
        (``confirmation.judge_frames``, against the ``memory`` snapshot's objects and the map
        ``grid``) for the candidate ``cand`` (its current box and observations; read as ``label``
        when it was chosen), and give the verdict of the frames so far (``evidence_verdict``);
        None: judge on. A confirmed candidate hands on to the supporting node the fresh views
        observed more often (``confirmation.confirmed_node``); for a ``described`` instance only
        when that node is the same object seen again (``confirmation.same_object``): the
        reasoning layer chose the candidate by its relations, and a neighbour of the same label
        whose box touches it (chairs around a table) is another instance, not checked.

        The frames of a candidate the reasoning layer put forward (source "hypothesis") taken
        within ``recent_view_s`` before the verification began from within the view ring count
        as well (``confirmation.recent_close``): the reasoning layer verified it on its images
        once already, and a robot that came upon it on its way has the views a view cell would
        give. A candidate taken for its label alone ("memory-label") is judged on frames after
        the start only: the frame that made a spurious box would count as its first view. Frames
        from the wider close distance are not taken: from there a look-alike is read as the
        target about as often as not."""
        if self.start_stamp is None:
            # frames carry their sensor's stamps, and a stepped clock keeps another time (a 0.1 s
            # tick per action of 0.5 s): a window over frames is measured in the frames' own time,
            # from the newest frame the memory held when the verification began
            self.start_stamp = float(getattr(memory, "stamp", self.start))
        self.close = gap <= close_distance(settings, ring)
        if not self.close:
            return None
        anchors, objects = tuple(getattr(memory, "anchors", ()) or ()), memory.objects
        earlier = None if settings.recent_view_s <= 0.0 or getattr(cand, "source", None) != HYPOTHESIS else partial(
            recent_close, since=self.start_stamp - settings.recent_view_s, box_min=cand.box_min,
            box_max=cand.box_max, close=ring)
        frames, self.last_anchor = frames_since(anchors, self.last_anchor, earlier)
        targets, support, hiding = evidence_inputs(settings, memory, task_targets, cand)
        if frames:
            self.tally = judge_frames(self.tally, frames, objects=objects, grid=grid, center=cand.center,
                                      box_min=cand.box_min, box_max=cand.box_max, support=support, hiding=hiding,
                                      targets=targets, near=settings.near_view_distance)
        verdict = evidence_verdict(settings, self.tally, label=label, n_obs=cand.n_obs, objects=objects,
                                   support=support)
        if verdict is None and self.flipped_to is not None:
            verdict = flipped_verdict(settings, self.tally, self.flipped_to)
        if verdict is None or verdict.outcome != "confirmed":
            return None if verdict is None else Judgement(verdict)
        found = confirmed_node(self.tally, cand.object_id)
        node = None if found is None else next((o for o in objects if o.id == found[0]), None)
        if node is not None and described and not same_object(node.box_min, node.box_max, cand.box_min, cand.box_max):
            node = None
        said = f"confirmed {cand.label} #{cand.object_id}: {verdict.reason}"
        if node is None:
            return Judgement(verdict, feedback=said)
        return Judgement(verdict, node, f"#{cand.object_id} confirmed by views of #{found[0]} ({found[1]} of them): "
                                        f"going to #{found[0]}", said)

    def next_move(self, settings: VerifySettings, *, elapsed: float, sent: bool, state: str, cell: np.ndarray | None,
                  mapped: bool, stalled: Callable[[], bool]) -> ViewMove:
        """The next move (``viewing.next_view_move``), with the state it changes applied, or the
        timeout's deferral (``confirmation.timeout_verdict``: ``elapsed`` clock s since the start):
        ``sent`` (a goal was sent), ``state`` (its navigation state), ``cell`` (the cell last sent,
        or None), ``mapped`` (a map and the robot's pose are known: without them no closer cell,
        way through unknown floor or map deferral goes), ``stalled`` (reads the stall clock, only
        where ``viewing.stall_matters``: reading it restarts it)."""
        if (late := timeout_verdict(settings, elapsed)) is not None:
            return ViewMove(reason=late.reason)
        move = next_view_move(settings, close=self.close, sent=sent, state=state, unseen=self.tally.unseen,
                              excluded=len(self.excluded), has_cell=cell is not None, closing=self.closing,
                              stalled=stall_matters(self.close, sent, state) and stalled())
        if move.exclude_cell:
            self.excluded.append(cell)
        self.tally = restart_unseen(self.tally) if move.reset_unseen else self.tally
        self.closing = self.closing and not move.stop_closing
        return move if mapped else replace(move, tries=tuple(k for k in move.tries if k in ("view", "glance")))

    def glance(self, pose: Any, cand: Any, glance_deg: float) -> Goal:
        """The goal of the next glance from where the robot stands (``pose``: x, y world):
        ``glance_deg`` left, then right, and so on, of facing the candidate ``cand``."""
        face = facing(np.array([pose.x, pose.y]), cand.center)
        offset = math.radians((glance_deg, -glance_deg)[self.glances % 2])
        self.glances += 1
        return Goal(pose.x, pose.y, wrap_angle(face + offset), GLANCE_TOLERANCE, "look", cand.object_id)

    def fallback(self, kind: str, settings: VerifySettings, grid: Any, memory: Any, cand: Any, robot_xy: np.ndarray,
                 gap: float, ring: float, task_targets: Iterable[str] | None, label: str) -> CellGoal | None:
        """The goal of a "closer" or "unknown" move (any other ``kind``: None) toward the candidate ``cand`` (read as ``label``
        when it was chosen; ``viewing.fallback_cell`` with the moves made so far, the cells set
        aside, the ``memory`` snapshot's furniture, wall heights and, through unknown floor, the
        boxes that may hide it), counted as made; None when it cannot go. ``gap``: the robot's
        distance (m) to the box; ``ring``: the view ring."""
        closer, object_id = kind == "closer", cand.object_id
        view = None if closer else sight_of(settings, memory, task_targets, cand)
        cell = fallback_cell(kind, settings, grid, cand.box_min, cand.box_max, robot_xy, gap=gap, ring=ring,
                             excluded=self.excluded, n_obs=cand.n_obs,
                             moves=self.closer_moves if closer else self.unknown_moves,
                             furniture=furniture_boxes(memory, object_id),
                             heights=wall_heights(memory, float(np.asarray(cand.box_max)[2])), view=view)
        if cell is None:
            return None
        self.closer_moves, self.unknown_moves = self.closer_moves + closer, self.unknown_moves + (not closer)
        self.closing = self.closing or closer
        where = f"({cell[0]:.2f}, {cell[1]:.2f})"
        if closer:
            return CellGoal(cell, CLOSER_TOLERANCE, False,
                            f"no view cell of #{object_id} on the map yet: closing in to {where}, {gap:.1f} m from "
                            f"it now", f"closing in on {label} #{object_id}")
        return CellGoal(cell, UNKNOWN_TOLERANCE, True,
                        f"no view cell of #{object_id} reachable on the known map: heading for {where} through "
                        f"unknown floor", f"heading for {label} #{object_id} through unknown floor")


def evidence_inputs(settings: VerifySettings, memory: Any, task_targets: Iterable[str] | None,
                    cand: Any) -> tuple[set[str], set[int], tuple[np.ndarray, np.ndarray] | None]:
    """What the frames of the candidate ``cand`` are judged against, among the ``memory``
    snapshot's objects: the target labels (the task's and its own), the nodes that support it
    (its own and ``confirmation.support_ids``, ``support_margin``) and the boxes that may hide it
    (``viewing.blockers``: none of those)."""
    objects = memory.objects
    targets = target_labels(task_targets, cand.label)
    # the candidate's own node supports it whatever its vote reads now: a vote flipped to a
    # look-alike while the robot judges it is settled by the labels the fresh views read
    support = support_ids(objects, targets, cand.box_min, cand.box_max, settings.support_margin) | {
        int(cand.object_id)}
    return targets, support, blockers(objects, cand.box_min, cand.box_max, support, settings)


def hiding(settings: VerifySettings, memory: Any, task_targets: Iterable[str] | None,
           cand: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """The boxes that may hide the candidate ``cand`` (``evidence_inputs``)."""
    return evidence_inputs(settings, memory, task_targets, cand)[2]


def sight_of(settings: VerifySettings, memory: Any, task_targets: Iterable[str] | None,
             cand: Any) -> tuple[np.ndarray, float, np.ndarray, np.ndarray] | None:
    """``approach_cell``'s ``sight`` argument for the candidate ``cand`` (``viewing.sight``, with
    the ``memory`` snapshot's camera and the boxes that may hide the candidate)."""
    return sight(cand.center, camera_of(memory), hiding(settings, memory, task_targets, cand))


def view_here(settings: VerifySettings, pose: Any, grid: Any, cand: Any, ring: float, gap: float,
              camera: tuple[float, float] | None, rules: dict, excluded: Iterable[np.ndarray] = ()) -> np.ndarray | None:
    """The robot's own place (world xy) as the view cell of the candidate ``cand``, ``gap`` m from
    its footprint, when ``from_here`` is set and ``viewing.views_from_here`` holds there (within
    the view ``ring``, in sight past the boxes that may hide it and past walls). ``rules``: the
    view cell search's ``sight``, ``furniture`` and ``wall_heights`` (``cell_near``'s keywords),
    read as that search reads them; else None."""
    if not settings.from_here or pose is None or grid is None:
        return None
    here = np.array([float(pose.x), float(pose.y)])
    explained = [(np.asarray(cand.box_min), np.asarray(cand.box_max)), *(rules.get("furniture") or ())]
    ok = views_from_here(settings, here, gap, ring, np.asarray(cand.center, dtype=np.float64), camera,
                         rules.get("sight"), grid, explained, rules.get("wall_heights"), excluded)
    return here if ok else None


def node_fields(node: Any) -> tuple[str, np.ndarray, np.ndarray, np.ndarray, float, int]:
    """A memory object ``node``'s label, centre (3,) world float64, box min and max (3,) world (as
    stored), confidence and observations: a candidate's fields as the memory has them now (the
    box grows as it is seen)."""
    return (str(node.label), np.asarray(node.center, dtype=np.float64), np.asarray(node.box_min),
            np.asarray(node.box_max), float(node.confidence), int(node.n_obs))


def view_feedback(label: str, object_id: int, another: bool) -> str:
    """The feedback of a view cell sent: "" for the first, a text for another."""
    return f"verifying {label} #{object_id} from another cell" if another else ""


def move_verdict(move: ViewMove, said: str | None) -> Verdict | None:
    """The deferral a ``ViewMove`` ends in: its ``reason``; or, when none of its tries went
    (``said``: the feedback of the one that went, None: none) and the last was "remap", no
    reachable view point until the map around the candidate grows; else None."""
    if move.reason is not None:
        return deferred(move.reason)
    return deferred("no reachable view point", remap=True) if said is None and "remap" in move.tries else None


def nearer_switch(settings: VerifySettings, here: float, others: Iterable[tuple[float, C]], object_id: int) -> Switch | None:
    """The switch to a candidate nearer the robot than the one under way (``object_id``, ``here``
    m off; ``others``: (distance m, candidate) pairs, ``viewing.nearer_candidate``), or None."""
    nearer = nearer_candidate(here, others, settings)
    if nearer is None:
        return None
    return Switch(nearer, f"#{nearer.object_id} is {settings.switch_margin:.1f} m or more nearer than #{object_id}: "
                          f"verifying it first", f"verifying {nearer.label} #{nearer.object_id} first")


def posting(settings: VerifySettings, verdict: Verdict, object_id: int, rejections: Iterable[tuple[int, Any]],
            remaps: int, can_remap: bool) -> Posting:
    """How ``verdict`` on ``object_id`` is posted, given the mission's ``rejections`` so far
    ((id, reason) pairs), its map deferrals of it (``remaps``) and whether another may lapse on
    map growth (``can_remap``): a map deferral only while ``can_remap``; for good as
    ``confirmation.for_good`` says, this deferral counted."""
    remap = verdict.remap and not verdict.permanent and can_remap
    count = sum(1 for i, _ in rejections if i == object_id) - remaps + 1
    return Posting(for_good(settings, verdict.permanent, remap, count), verdict.requalify, remap)


__all__ = ["CLOSER_TOLERANCE", "CellGoal", "GLANCE_TOLERANCE", "HYPOTHESIS", "Judgement", "Posting", "Switch", "UNKNOWN_TOLERANCE",
           "Verification", "evidence_inputs", "hiding", "move_verdict", "nearer_switch", "node_fields",
           "posting", "sight_of", "view_feedback", "view_here"]
