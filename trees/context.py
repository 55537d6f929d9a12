"""MissionContext: what the mission tree's behaviours read and the requests they make.

The Mission actor owns one ``MissionContext``. It writes the latest actor results into it
(task, world snapshot, exploration plan, target hypotheses, navigation status) before each tick,
and after the tick it turns the context's outbox (goal requests, parse requests, stop) into
messages for the other actors. Behaviours therefore *poll* results and *post* requests: they never
block a tick and never talk to actors directly. No threads, no pykka here.

Candidates: a target hypothesis from the reasoning layer (or, as a labelled fallback, a memory
object whose label is one of the task's targets) resolved to a memory object node with a 3D box;
the mission rejects a candidate that fails verification so that exploration resumes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hiconav.decisions import last_resort as resort
from hiconav.decisions.config import DecisionsConfig
from hiconav.decisions.verification import HYPOTHESIS
from hiconav.geometry import footprint_distance
from hiconav.messages import ExploredOut, GoalMsg, KeyframeRequest, NavStatus, ParseRequest, StopRequest
from hiconav.reasoning.grounding import target_relations
from hiconav.types import Goal, Pose2D, TaskSpec


@dataclass(frozen=True)
class Candidate:
    """A target candidate: a memory object node believed to be the target.

    center / box_min / box_max: (3,) world metres. ``source``: "hypothesis" (reasoning layer) or
    "memory-label" (fallback: the detector's label matched a target).
    """

    object_id: int
    label: str
    center: np.ndarray
    box_min: np.ndarray
    box_max: np.ndarray
    confidence: float
    n_obs: int
    source: str


def _box_iou_2d(a: np.ndarray, b: np.ndarray) -> float:
    ix = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    iy = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = ix * iy
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return float(inter / union) if union > 0 else 0.0


@dataclass
class MissionContext:
    """Mission state shared by the behaviours of one tree (owned by the Mission actor alone)."""

    instruction: str
    clock: Callable[[], float]
    namespace: str = "/mission"
    success_distance: float = 1.0
    robot_radius: float = 0.18
    use_memory_labels: bool = True
    # the reasoning layer verifies subgraphs: for a described instance (relations on the target)
    # only its verdict proposes candidates; without it (the no_reasoning ablation) labels do
    reasoning: bool = True
    # decisions.*: the thresholds the behaviours and the decision modules read
    decisions: DecisionsConfig = field(default_factory=DecisionsConfig)
    # the clock's seconds per second of robot time: ``decisions`` is on the clock already
    # (``DecisionsConfig.in_clock``); a duration a tree sets for one node is scaled on reading
    time_scale: float = 1.0
    # the behaviour class whose tick runs now (``MissionBehaviour.tick``): the source of the goals
    # it sends, so that the records can say which decision each action served
    acting: str = ""
    verify: bool = True  # False: VerifyTarget accepts the candidate as is (the 'no_verify' ablation)
    task: TaskSpec | None = None
    world: Any = None  # WorldSnapshot
    plan: Any = None  # PlanMsg
    hypotheses: list[Any] = field(default_factory=list)  # TargetHypothesis, newest last
    nav: NavStatus | None = None
    rejected: set[int] = field(default_factory=set)  # object ids that failed verification for good
    deferred: dict[int, float] = field(default_factory=dict)  # object id -> clock time it may be tried again
    # object id -> its observation count when deferred: a deferred candidate that the detector has
    # since seen ``requalify_observations`` more times under a target label is due at once
    deferred_obs: dict[int, int] = field(default_factory=dict)
    requalify_observations: int = 3  # 0: never (a deferral lasts its time)
    # object id -> (window min xy, window max xy, known-free m^2 in it when deferred): a candidate
    # deferred for want of a reachable cell on the map is due again once the map around it has
    # grown by ``remap_area_m2`` (``reject(remap=True)``)
    deferred_map: dict[int, tuple[np.ndarray, np.ndarray, float]] = field(default_factory=dict)
    remap_area_m2: float = 1.0  # 0: never (a deferral lasts its time)
    remap_margin_m: float = 2.0  # the window is the candidate's footprint grown by this
    remaps: dict[int, int] = field(default_factory=dict)  # object id -> map deferrals so far
    max_remaps: int = 3  # map deferrals per candidate; later ones last their time
    rejections: list[tuple[int, str]] = field(default_factory=list)  # every rejection/deferral, in order
    # object id -> the reason, for candidates whose latest rejection or deferral was only for want
    # of a reachable view point or approach cell (``reject(out_of_reach=True)``): what an
    # explored-out search may take back as its last resort (``hiconav.decisions.last_resort``)
    out_of_reach: dict[int, str] = field(default_factory=dict)
    # the candidate taken back as the last resort (None: none yet) and whether one was taken
    last_resort: int | None = None
    last_resort_taken: bool = False
    start_pose: Pose2D | None = None
    outbox: list[Any] = field(default_factory=list)
    keyframes_until: float | None = None  # clock time the newest KeyframeRequest covers
    goal_seq: int = 0
    active_goal: Goal | None = None
    stop_requested: bool = False
    events: list[str] = field(default_factory=list)
    alerts: list[Any] = field(default_factory=list)  # HealthAlert messages from monitor actors
    # clock time a frontier to explore was last known; shared by every Explore instance, so a retried
    # Explore does not wait its idle time again once the map has been explored out
    last_frontier_time: float | None = None
    # frontier viewpoints (x, y) the robot reached while their frontier stayed: the camera cannot
    # see that frontier from there (floor below its field of view, walls nearer than its minimum
    # depth), so going back would only repeat the visit; shared by every Explore instance
    spent_viewpoints: list[tuple[float, float]] = field(default_factory=list)
    # centroids of spent frontiers Explore drove into (``push_through``): one push per spot
    pushed_frontiers: list[tuple[float, float]] = field(default_factory=list)
    # frontier ids whose goal failed (no path, or no progress): picking one again is no progress
    # for the idle clock, so a retried Explore that only finds those fails instead of idling anew
    failed_frontiers: set[int] = field(default_factory=set)
    # centroids of failed frontiers Explore tried once more on the squeeze mask (``squeeze``)
    squeezed_frontiers: list[tuple[float, float]] = field(default_factory=list)
    # times an explored-out search asked the reasoning layer for its best unresolved candidate
    unresolved_asks: int = 0
    # quarter turns in place done at the mission's start (Explore's start_look_turns); shared by
    # every Explore instance, so the look-around happens once per mission
    start_looks: int = 0
    # where Explore last turned in place for want of a frontier, and how many quarter turns it
    # made there (look_turns at most per spot, for the whole mission)
    look_spot: tuple[float, float] | None = None
    looks_here: int = 0
    # the target-category nodes the reasoning layer rules out (RuledOut, latest wins) and those
    # Explore has lingered by (``decisions.linger``)
    ruled_out: frozenset[int] = frozenset()
    # the offers the reasoning layer took back for good (RuledOut.withdrawn): no longer candidates
    withdrawn: frozenset[int] = frozenset()
    lingered: set[int] = field(default_factory=set)

    # -- time and pose -------------------------------------------------------------------------
    def now(self) -> float:
        return float(self.clock())

    @property
    def pose(self) -> Pose2D | None:
        return None if self.world is None else self.world.pose

    @property
    def memory(self) -> Any:
        return None if self.world is None else self.world.memory

    @property
    def grid(self) -> Any:
        return None if self.world is None else self.world.grid

    # -- requests (turned into messages by the Mission actor after the tick) ---------------------
    def request_task(self, instruction: str) -> None:
        self.outbox.append(ParseRequest(instruction, self.now()))

    def report_explored_out(self) -> None:
        """Tell the reasoning layer that the search has no frontier left (``ExploredOut``)."""
        self.unresolved_asks += 1
        self.outbox.append(ExploredOut(self.now()))

    def request_keyframes(self, seconds: float, every_s: float = 0.0) -> None:
        """Ask the memory layer to make the frames of the next ``seconds`` anchors, one at least every
        ``every_s`` (``KeyframeRequest``); a request still covering that long is not repeated."""
        until = self.now() + seconds
        if self.keyframes_until is not None and self.keyframes_until >= until - seconds / 2.0:
            return
        self.keyframes_until = until
        self.outbox.append(KeyframeRequest(until, every_s, self.now()))

    def send_goal(self, goal: Goal | None) -> int:
        """Ask the control layer to go to ``goal`` (None cancels); returns the request's seq. The
        request names the behaviour ticking now (``acting``) as its source."""
        self.goal_seq += 1
        self.active_goal = goal
        self.outbox.append(GoalMsg(self.goal_seq, goal, self.now(), self.acting))
        return self.goal_seq

    def request_stop(self, reason: str) -> None:
        self.stop_requested = True
        self.outbox.append(StopRequest(reason, self.now()))

    def nav_state(self, seq: int) -> str:
        """State of goal request ``seq``: "pending" until control acknowledges it."""
        if self.nav is None or self.nav.goal_seq != seq:
            return "pending"
        return self.nav.state

    def excluded(self, object_id: int) -> bool:
        """True while a candidate is rejected or deferred.

        A deferral made with ``requalify`` lapses early once the node has gained
        ``requalify_observations`` observations and carries a target label again: a label that
        flipped once should not keep a real object waiting while the detector goes on reading it
        as the target. Only label flips requalify: an unreachable or unconfirmed
        candidate is observed again at once from where the robot stands. The last resort
        (``take_last_resort``) is not excluded."""
        if object_id == self.last_resort:
            return False
        if object_id in self.rejected:
            return True
        if self.deferred.get(object_id, -1.0) <= self.now():
            return False
        window = self.deferred_map.get(object_id)
        if window is not None and self.remap_area_m2 > 0:
            grown = self.free_area_m2(window[0], window[1]) - window[2]
            if grown >= self.remap_area_m2:
                self.log(f"deferral of #{object_id} lapsed: the map around it grew by {grown:.1f} m^2")
                del self.deferred[object_id]
                del self.deferred_map[object_id]
                return False
        base = self.deferred_obs.get(object_id)
        if base is None or self.task is None or not self.requalify_observations:
            return True
        obj = self.object(object_id)
        if obj is not None and obj.label in self.task.targets and int(obj.n_obs) >= base + self.requalify_observations:
            self.log(f"deferral of #{object_id} lapsed: {int(obj.n_obs) - base} new observations as {obj.label!r}")
            del self.deferred[object_id]
            return False
        return True

    def reject(self, object_id: int, reason: str, *, permanent: bool = True, defer_s: float = 30.0,
               requalify: bool = False, remap: bool = False, out_of_reach: bool = False) -> None:
        """Verification failed: exclude the candidate for good, or for ``defer_s`` clock seconds
        (with ``requalify``, or until it is observed again as a target; with ``remap``, while
        ``can_remap``, or until the map around it has grown: see ``excluded``). ``out_of_reach``:
        the reason is only that no view point or approach cell could be reached (the last
        resort may take it back); any other reason clears that."""
        if object_id == self.last_resort:
            self.last_resort = None
        if out_of_reach:
            self.out_of_reach[object_id] = reason
        else:
            self.out_of_reach.pop(object_id, None)
        if permanent:
            self.rejected.add(object_id)
        else:
            self.deferred[object_id] = self.now() + defer_s
            obj = self.object(object_id) if requalify else None
            if obj is not None:
                self.deferred_obs[object_id] = int(obj.n_obs)
            else:
                self.deferred_obs.pop(object_id, None)
            obj = self.object(object_id) if remap and self.can_remap(object_id) else None
            if obj is not None and self.grid is not None:
                lo = np.asarray(obj.box_min, dtype=np.float64)[:2] - self.remap_margin_m
                hi = np.asarray(obj.box_max, dtype=np.float64)[:2] + self.remap_margin_m
                self.deferred_map[object_id] = (lo, hi, self.free_area_m2(lo, hi))
                self.remaps[object_id] = self.remaps.get(object_id, 0) + 1
            else:
                self.deferred_map.pop(object_id, None)
        self.rejections.append((object_id, reason))
        self.log(f"{'rejected' if permanent else 'deferred'} #{object_id}: {reason}")

    def can_remap(self, object_id: int) -> bool:
        """A deferral of ``object_id`` may still lapse on map growth (fewer than ``max_remaps`` did)."""
        return self.remaps.get(object_id, 0) < self.max_remaps

    def free_area_m2(self, lo: np.ndarray, hi: np.ndarray) -> float:
        """Known-free floor (m^2) of the current grid inside the world window [lo, hi] (xy)."""
        grid = self.grid
        if grid is None:
            return 0.0
        state, res = np.asarray(grid.state), float(grid.resolution)
        origin = np.asarray(grid.origin, dtype=np.float64)
        c0, r0 = np.floor((np.asarray(lo, dtype=np.float64) - origin) / res).astype(int)
        c1, r1 = np.floor((np.asarray(hi, dtype=np.float64) - origin) / res).astype(int) + 1
        r0, c0, r1, c1 = max(r0, 0), max(c0, 0), min(r1, state.shape[0]), min(c1, state.shape[1])
        if r0 >= r1 or c0 >= c1:
            return 0.0
        return float(np.count_nonzero(state[r0:r1, c0:c1] == 0)) * res ** 2

    def log(self, text: str) -> None:
        self.events.append(f"{self.now():.2f} {text}")

    # -- candidates ------------------------------------------------------------------------------
    def candidates(self) -> list[Candidate]:
        """Target candidates, best first: hypotheses (newest first) then label matches (fallback),
        the nearest to the robot first (by evidence, confidence x observations, before a pose)."""
        memory = self.memory
        if memory is None or self.task is None:
            return []
        objects = {o.id: o for o in memory.objects}
        out: list[Candidate] = []
        seen: set[int] = set()
        if self.last_resort is not None and self.last_resort in objects:
            seen.add(self.last_resort)
            node = objects[self.last_resort]
            out.append(self.candidate_of(node, resort.SOURCE, float(node.confidence)))
        for hyp in reversed(self.hypotheses):
            oid = self._resolve(hyp, memory, objects)
            if oid is None or oid in seen or self.excluded(oid) or oid in self.withdrawn:
                continue
            seen.add(oid)
            out.append(self.candidate_of(objects[oid], HYPOTHESIS, float(getattr(hyp, "confidence", 0.0))))
        if self.use_memory_labels and not (self.reasoning and self.described):
            targets = set(self.task.targets)
            matches = [o for o in memory.objects if o.label in targets and not self.excluded(o.id)
                       and o.id not in seen]
            if self.pose is not None:
                # nearest first: verification decides whether a label match is the target, and the
                # way to a far one and back is what a wrong order costs; ranked by evidence
                # (confidence x observations), a far, often-seen match went before a near one seen
                # once, both real (evidence first, then distance, gained less on Gibson)
                matches.sort(key=lambda o: (self.distance_to_box(np.asarray(o.box_min), np.asarray(o.box_max)), o.id))
            else:
                matches.sort(key=lambda o: (-o.confidence * o.n_obs, o.id))
            out += [self.candidate_of(o, "memory-label", float(o.confidence)) for o in matches]
        return out

    def take_last_resort(self) -> Candidate | None:
        """Take back the best candidate set aside only as out of reach as the mission's last
        resort, once (``hiconav.decisions.last_resort.pick``: the reasoning layer's first, then
        the best seen); None when there is none."""
        memory = self.memory
        if memory is None or self.last_resort_taken:
            return None
        objects = {o.id: o for o in memory.objects}
        confirmed = {oid for hyp in self.hypotheses if (oid := self._resolve(hyp, memory, objects)) is not None}
        node = resort.pick(memory.objects, self.out_of_reach, confirmed)
        if node is None:
            return None
        self.last_resort, self.last_resort_taken = int(node.id), True
        self.log(f"last resort: #{node.id} ({node.label}), set aside as {self.out_of_reach[int(node.id)]!r}")
        return self.candidate_of(node, resort.SOURCE, float(node.confidence))

    @property
    def stranded(self) -> bool:
        """A candidate set aside only as out of reach is still in memory and no last resort was taken."""
        memory = self.memory
        return (bool(self.out_of_reach) and not self.last_resort_taken and memory is not None
                and any(int(o.id) in self.out_of_reach for o in memory.objects))

    @property
    def described(self) -> bool:
        """The instruction singles out one instance by relations on the target ("the armchair next
        to the floor lamp"): a label match then proposes nothing, the reasoning layer decides."""
        return self.task is not None and bool(target_relations(self.task.relations, self.task.targets))

    def _resolve(self, hyp: Any, memory: Any, objects: dict[int, Any]) -> int | None:
        oid = getattr(hyp, "object_id", None)
        if oid is not None and oid in objects:
            return int(oid)
        try:
            anchor = memory.anchor(hyp.anchor_id)
        except (KeyError, LookupError, AttributeError):
            return None
        if anchor is None or len(anchor.object_ids) == 0:
            return None
        bbox = np.asarray(hyp.bbox, dtype=np.float64)
        best, best_iou = None, 0.1
        for oid_i, box in zip(anchor.object_ids, np.asarray(anchor.boxes)):
            iou = _box_iou_2d(bbox, np.asarray(box, dtype=np.float64))
            if iou > best_iou and oid_i in objects:
                best, best_iou = int(oid_i), iou
        return best

    @staticmethod
    def candidate_of(obj: Any, source: str, confidence: float) -> Candidate:
        """A ``Candidate`` for the memory object node ``obj``."""
        return Candidate(int(obj.id), str(obj.label), np.asarray(obj.center, dtype=np.float64),
                         np.asarray(obj.box_min, dtype=np.float64), np.asarray(obj.box_max, dtype=np.float64),
                         confidence, int(obj.n_obs), source)

    def object(self, object_id: int) -> Any:
        memory = self.memory
        if memory is None:
            return None
        for o in memory.objects:
            if o.id == object_id:
                return o
        return None

    def distance_to_box(self, box_min: np.ndarray, box_max: np.ndarray, xy: np.ndarray | None = None) -> float:
        """Planar distance (m) from ``xy`` (default: the robot) to an object's footprint."""
        if xy is None:
            pose = self.pose
            if pose is None:
                return math.inf
            xy = np.array([pose.x, pose.y])
        return footprint_distance(box_min, box_max, xy)
