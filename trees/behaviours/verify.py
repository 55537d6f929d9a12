"""VerifyTarget: go where the candidate shows and confirm it with fresh views.

A thin poller: it reads the context's memory, grid and navigation status, asks the view planner
(``hiconav.decisions.viewing``) where to stand and what to do next and the confirmation policy
(``hiconav.decisions.confirmation``) what the frames say, and posts the goals (view cell,
glance, closer cell, through unknown floor) and verdicts (reject, defer) they decide, with the
thresholds of ``decisions.verify``. Nothing here blocks, talks to an actor or decides a rule.
"""

from __future__ import annotations

import math

import numpy as np

from hiconav.decisions import confirmation as conf
from hiconav.decisions import viewing as view
from hiconav.decisions.geometry import facing as _facing
from hiconav.trees.behaviours.base import Status
from hiconav.trees.behaviours.goto import _GoToObject
from hiconav.trees.context import Candidate
from hiconav.trees.registry import register_behaviour
from hiconav.types import Goal, wrap_angle

#: goal tolerances (m): a closer cell, a view cell through unknown floor, a glance in place
CLOSER_TOLERANCE, UNKNOWN_TOLERANCE, GLANCE_TOLERANCE = 0.3, 0.2, 0.5


@register_behaviour()
class VerifyTarget(_GoToObject):
    """Go within ``verify_distance`` of the candidate, facing it, and confirm it with fresh views
    (``confirmation``), glancing ``glance_deg`` left and right of it so that each glance makes an
    anchor; view, closer and through-unknown cells and the next move come from ``viewing``. A
    verdict rejects or defers the candidate (``MissionContext.reject``), so exploration resumes;
    a confirmed one is written as the target (the supporting node its fresh views saw most)."""

    SETTINGS = "verify"
    WRITES = ("target",)
    READS = ()

    def initialise(self) -> None:
        self._switches = 0  # switches to a nearer candidate since the tree started this behaviour
        self._take(self.read("target"))

    def _take(self, cand: Candidate | None) -> None:
        """Start judging ``cand``: every count and goal starts afresh."""
        self._start, self._seq, self._cand = self.context.now(), None, cand
        self._excluded: list[np.ndarray] = []  # view cells tried and set aside
        self._close = False  # the robot is within the close distance of the candidate (this tick)
        self._last_anchor: int | None = None  # the newest memory anchor already judged
        self._tally = conf.Tally()
        self._glance = self._closer_moves = self._unknown_moves = 0
        self._closing = False  # the goal in flight is a closer cell, not a view cell
        if self._cand is not None and self.context.verify:
            self._send(self._cand, self._ring(self._cand))

    # -- the hooks of _GoToObject and the inputs of the core ---------------------------------------
    def _stall_near(self) -> float:
        return self.param("stall_near")

    def _prefer_weight(self) -> float:
        return self.param("view_ray_weight")

    def _ring(self, cand: Candidate) -> float:
        return view.view_ring(self.settings, float(np.asarray(cand.center)[2]), self._camera())

    def _targets(self, label: str) -> set[str]:
        return conf.target_labels(self.context.task.targets if self.context.task is not None else None, label)

    def _support(self, cand: Candidate) -> set[int]:
        return conf.support_ids(self.context.memory.objects, self._targets(cand.label), cand.box_min, cand.box_max,
                                self.param("support_margin"))

    def _blockers(self, cand: Candidate, support: set[int] | None = None) -> tuple[np.ndarray, np.ndarray] | None:
        skip = (self._support(cand) if support is None else support) | {int(cand.object_id)}
        return view.blockers(self.context.memory.objects, cand.box_min, cand.box_max, skip, self.settings)

    def _sight(self, cand: Candidate) -> tuple[np.ndarray, float, np.ndarray, np.ndarray] | None:
        return view.sight(cand.center, self._camera(), self._blockers(cand))

    def _preferred_xy(self, cand: Candidate, distance: float) -> np.ndarray | None:
        memory, obj = self.context.memory, self.context.object(cand.object_id)
        ids = set(int(i) for i in getattr(obj, "anchor_ids", ()) or ())
        if memory is None or not ids:
            return None
        return view.seen_from(cand.center, getattr(memory, "anchors", ()) or (), ids, distance)

    # -- polling ---------------------------------------------------------------------------------
    def _reject(self, verdict: conf.Verdict) -> Status:
        """Post a rejection or deferral (``verdict``) of the candidate; FAILURE."""
        if self._cand is not None:
            ctx, oid = self.context, self._cand.object_id
            remap = verdict.remap and not verdict.permanent and ctx.can_remap(oid)  # up to max_remaps
            count = sum(1 for i, _ in ctx.rejections if i == oid) - ctx.remaps.get(oid, 0) + 1
            ctx.reject(oid, verdict.reason, permanent=conf.for_good(self.settings, verdict.permanent, remap, count),
                       defer_s=self.param("defer_s"), requalify=verdict.requalify, remap=remap)
        self.feedback_message = f"{'rejected' if verdict.permanent else 'deferred'}: {verdict.reason}"
        return Status.FAILURE

    def _switch(self, obj: object, cand: Candidate) -> Candidate | None:
        """A candidate nearer the robot than ``cand`` (memory node ``obj``) to verify first, or None."""
        ctx = self.context
        if not view.may_switch(self.settings, self._switches, self._close or bool(self._tally.in_view)):
            return None
        here = ctx.distance_to_box(np.asarray(obj.box_min), np.asarray(obj.box_max))
        others = [c for c in ctx.candidates() if c.object_id != cand.object_id]
        return view.nearer_candidate(here, ((ctx.distance_to_box(c.box_min, c.box_max), c) for c in others),
                                     self.settings)

    def _judge(self, current: Candidate, obj: object) -> Status | None:
        """Judge the new frames of ``current`` (close to it); its verdict's status, or None."""
        ctx, memory = self.context, self.context.memory
        frames, self._last_anchor = conf.frames_since(tuple(getattr(memory, "anchors", ()) or ()), self._last_anchor)
        support = self._support(current)
        if frames:
            self._tally = conf.judge_frames(self._tally, frames, objects=memory.objects, grid=ctx.grid,
                                            center=current.center, box_min=current.box_min, box_max=current.box_max,
                                            support=support, hiding=self._blockers(current, support),
                                            targets=self._targets(current.label), near=self.param("near_view_distance"))
        verdict = conf.evidence_verdict(self.settings, self._tally, label=self._cand.label, n_obs=int(obj.n_obs),
                                        objects=memory.objects, support=support)
        if verdict is None or verdict.outcome != "confirmed":
            return None if verdict is None else self._reject(verdict)
        found, node = conf.confirmed_node(self._tally, current.object_id), None
        if found is not None and (node := ctx.object(found[0])) is not None:
            ctx.log(f"#{current.object_id} confirmed by views of #{found[0]} ({found[1]} of them): going to #{found[0]}")
        self.write("target", current if node is None else ctx.candidate_of(node, current.source, float(node.confidence)))
        self.feedback_message = f"confirmed {obj.label} #{obj.id}: {verdict.reason}"
        return Status.SUCCESS

    def _try(self, kind: str, current: Candidate, another: bool) -> str | None:
        """Send the goal of a ``ViewMove`` try (``another``: another view cell): its feedback ("" for
        the plain one), or None when it cannot go."""
        ctx, cand, pose = self.context, self._cand, self.context.pose
        if kind == "view":
            if not self._send(current, self._ring(current)):
                return None
            return f"verifying {cand.label} #{cand.object_id} from another cell" if another else ""
        if kind == "glance":
            face, glance = _facing(np.array([pose.x, pose.y]), current.center), self.param("glance_deg")
            offset = math.radians((glance, -glance)[self._glance % 2])
            self._glance += 1
            self._seq = ctx.send_goal(Goal(pose.x, pose.y, wrap_angle(face + offset), GLANCE_TOLERANCE, "look",
                                           cand.object_id))
            return ""
        if ctx.grid is None or pose is None:
            return None
        if kind == "remap":
            return kind
        closer, robot = kind == "closer", np.array([pose.x, pose.y])
        gap = ctx.distance_to_box(current.box_min, current.box_max)
        cell = view.fallback_cell(kind, self.settings, ctx.grid, current.box_min, current.box_max, robot, gap=gap,
                                  ring=self._ring(current), excluded=self._excluded, n_obs=current.n_obs,
                                  moves=self._closer_moves if closer else self._unknown_moves,
                                  furniture=self._furniture(current), heights=self._wall_heights(current),
                                  view=None if closer else self._sight(current))
        if cell is None:
            return None
        self._closer_moves, self._unknown_moves = self._closer_moves + closer, self._unknown_moves + (not closer)
        self._closing = self._closing or closer
        self._go_to_cell(current, cell, CLOSER_TOLERANCE if closer else UNKNOWN_TOLERANCE, through_unknown=not closer)
        where = f"({cell[0]:.2f}, {cell[1]:.2f})"
        ctx.log(f"no view cell of #{cand.object_id} on the map yet: closing in to {where}, {gap:.1f} m from it now"
                if closer else f"no view cell of #{cand.object_id} reachable on the known map: heading for {where} "
                f"through unknown floor")
        return f"closing in on {cand.label} #{cand.object_id}" if closer else \
            f"heading for {cand.label} #{cand.object_id} through unknown floor"

    def update(self) -> Status:
        ctx, cand = self.context, self._cand
        if cand is None:
            self.feedback_message = "no target to verify"
            return Status.FAILURE
        if not ctx.verify:
            self.feedback_message = "verification disabled: candidate accepted as is"
            return Status.SUCCESS
        obj = ctx.object(cand.object_id)
        if obj is None:
            return self._reject(conf.Verdict("rejected", "object node disappeared from memory"))
        nearer = self._switch(obj, cand)
        if nearer is not None:
            ctx.log(f"#{nearer.object_id} is {self.param('switch_margin'):.1f} m or more nearer than #{cand.object_id}: "
                    f"verifying it first")
            self.write("target", nearer)
            self._switches += 1
            self._take(nearer)  # the other candidate stays a candidate: it is neither rejected nor deferred
            self.feedback_message = f"verifying {nearer.label} #{nearer.object_id} first"
            return Status.RUNNING
        current = Candidate(cand.object_id, str(obj.label), np.asarray(obj.center, dtype=np.float64),
                            np.asarray(obj.box_min), np.asarray(obj.box_max), float(obj.confidence), int(obj.n_obs),
                            cand.source)
        flipped = conf.label_verdict(ctx.task.targets if ctx.task is not None else None, obj.label, cand.source)
        if flipped is not None:
            return self._reject(flipped)
        # judged every tick, for the current box: the box grows as it is seen
        self._close = ctx.distance_to_box(current.box_min, current.box_max) <= \
            view.close_distance(self.settings, self._ring(current))
        if self._close and (judged := self._judge(current, obj)) is not None:
            return judged
        late = conf.timeout_verdict(self.settings, ctx.now() - self._start)
        if late is not None:
            return self._reject(late)
        sent = self._seq is not None
        state = "pending" if not sent else ctx.nav_state(self._seq)
        move = view.next_view_move(self.settings, close=self._close, sent=sent, state=state, unseen=self._tally.unseen,
                                   excluded=len(self._excluded), has_cell=getattr(self, "_cell", None) is not None,
                                   closing=self._closing,
                                   stalled=view.stall_matters(self._close, sent, state) and self._stalled())
        if move.reason is not None:
            return self._reject(conf.deferred(move.reason))
        if move.exclude_cell:
            self._excluded.append(self._cell)
        self._tally = conf.restart_unseen(self._tally) if move.reset_unseen else self._tally
        self._closing = self._closing and not move.stop_closing
        said = next((t for t in (self._try(k, current, move.another_cell) for k in move.tries) if t is not None), "")
        if said == "remap":
            return self._reject(conf.deferred("no reachable view point", remap=True))
        self.feedback_message = said or f"verifying {cand.label} #{cand.object_id}"
        return Status.RUNNING
