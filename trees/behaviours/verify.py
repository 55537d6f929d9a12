"""VerifyTarget: go where the candidate shows and confirm it with fresh views.

A thin poller: it reads the context's memory, grid and navigation status, asks the view planner
(``hiconav.decisions.viewing``) where to stand and what to do next and the confirmation policy
(``hiconav.decisions.confirmation``) what the frames say, and posts the goals (view cell,
glance, closer cell, through unknown floor) and verdicts (reject, defer) they decide, with the
thresholds of ``decisions.verify``. Nothing here blocks, talks to an actor or decides a rule.
"""

from __future__ import annotations

import numpy as np

from hiconav.decisions import confirmation as conf
from hiconav.decisions import last_resort as resort
from hiconav.decisions import verification as verif
from hiconav.decisions import viewing as view
from hiconav.trees.behaviours.base import Status
from hiconav.trees.behaviours.goto import _GoToObject
from hiconav.trees.context import Candidate
from hiconav.trees.registry import register_behaviour


@register_behaviour()
class VerifyTarget(_GoToObject):
    """Go within ``verify_distance`` of the candidate, facing it, and confirm it with fresh views,
    glancing ``glance_deg`` left and right of it; while it judges, the memory makes a frame an
    anchor every ``keyframe_every_s`` (``MissionContext.request_keyframes``). The state and
    the next steps are ``verification.Verification``'s; a verdict rejects or defers the candidate
    (``MissionContext.reject``); a confirmed one, or a ``last_resort`` as it is, is the target."""

    SETTINGS, WRITES, READS = "verify", ("target",), ()

    def initialise(self) -> None:
        self._switches = 0  # switches to a nearer candidate since the tree started this behaviour
        self._take(self.read("target"))

    def _take(self, cand: Candidate | None) -> None:
        """Start judging ``cand``: every count and goal starts afresh."""
        self._seq, self._cand, self._v = None, cand, verif.Verification(self.context.now())
        self._excluded = self._v.excluded  # the view cells _GoToObject._send must not send again
        if self._cand is not None and self.context.verify:
            self._send(self._cand, self._ring(self._cand))

    # -- the hooks of _GoToObject and the inputs of the core ---------------------------------------
    def _sight(self, cand: Candidate) -> tuple[np.ndarray, float, np.ndarray, np.ndarray] | None:
        return verif.sight_of(self.settings, self.context.memory, self._targets(), cand)

    def _preferred_xy(self, cand: Candidate, distance: float) -> np.ndarray | None:
        return view.seen_from_node(cand.center, self.context.memory, self.context.object(cand.object_id), distance)

    def _here(self, cand: Candidate, distance: float, rules: dict) -> np.ndarray | None:
        ctx = self.context
        return verif.view_here(self.settings, ctx.pose, ctx.grid, cand, distance,
                               ctx.distance_to_box(cand.box_min, cand.box_max), self._camera(), rules, self._excluded)

    def _ring(self, cand: Candidate) -> float:
        return view.view_ring(self.settings, float(np.asarray(cand.center)[2]), self._camera())

    def _targets(self) -> list[str] | None:
        return self.context.task.targets if self.context.task is not None else None

    def _reject(self, verdict: conf.Verdict) -> Status:
        """Post a rejection or deferral (``verdict``) of the candidate; FAILURE."""
        if self._cand is not None:
            ctx, oid = self.context, self._cand.object_id
            post = verif.posting(self.settings, verdict, oid, ctx.rejections, ctx.remaps.get(oid, 0), ctx.can_remap(oid))
            ctx.reject(oid, verdict.reason, defer_s=self.param("defer_s"), out_of_reach=verdict.remap, **post.flags())
        self.feedback_message = verdict.feedback
        return Status.FAILURE

    def _switch(self, obj: object, cand: Candidate) -> Status | None:
        """Verify first a candidate nearer the robot than ``cand`` (memory node ``obj``): RUNNING; or None."""
        ctx = self.context
        if not view.may_switch(self.settings, self._switches, self._v.judging):
            return None
        here = ctx.distance_to_box(np.asarray(obj.box_min), np.asarray(obj.box_max))
        others = [(ctx.distance_to_box(c.box_min, c.box_max), c) for c in ctx.candidates() if c.object_id != cand.object_id]
        if (switch := verif.nearer_switch(self.settings, here, others, cand.object_id)) is None:
            return None
        ctx.log(switch.log)
        self.write("target", switch.candidate)
        self._switches += 1
        self._take(switch.candidate)  # the other candidate stays a candidate: it is neither rejected nor deferred
        self.feedback_message = switch.feedback
        return Status.RUNNING

    def _try(self, kind: str, current: Candidate, another: bool) -> str | None:
        """Send the goal of a ``ViewMove`` try: its feedback, or None when it cannot go ("remap")."""
        ctx, cand, pose = self.context, self._cand, self.context.pose
        if kind == "view":
            sent = self._send(current, self._ring(current))
            return verif.view_feedback(cand.label, cand.object_id, another) if sent else None
        if kind == "glance":
            self._seq = ctx.send_goal(self._v.glance(pose, current, self.param("glance_deg")))
            return ""
        goal = self._v.fallback(kind, self.settings, ctx.grid, ctx.memory, current, np.array([pose.x, pose.y]),
                                ctx.distance_to_box(current.box_min, current.box_max), self._ring(current),
                                self._targets(), cand.label)
        if goal is not None:
            self._go_to_cell(current, goal.cell, goal.tolerance, through_unknown=goal.through_unknown)
            ctx.log(goal.log)
        return None if goal is None else goal.feedback

    def update(self) -> Status:
        ctx, cand = self.context, self._cand
        if self._lost(cand, "no target to verify"):
            return Status.FAILURE
        if not ctx.verify or cand.source == resort.SOURCE:  # a last resort had no view point
            self.feedback_message = ("verification disabled: candidate accepted as is" if not ctx.verify else
                                     f"last resort: {cand.label} #{cand.object_id} taken as it is")
            return Status.SUCCESS
        if (obj := ctx.object(cand.object_id)) is None:
            return self._reject(conf.Verdict("rejected", "object node disappeared from memory"))
        if (switched := self._switch(obj, cand)) is not None:
            return switched
        current = Candidate(cand.object_id, *verif.node_fields(obj), cand.source)
        flipped, current = self._v.read_label(self.settings, self._targets(), current, cand.label)
        if flipped is not None:
            return self._reject(flipped)
        gap, ring = ctx.distance_to_box(current.box_min, current.box_max), self._ring(current)
        judged = self._v.judge(self.settings, gap, ring, ctx.memory, ctx.grid, current, self._targets(), cand.label,
                               ctx.described)
        if self._v.judging:
            ctx.request_keyframes(self.param("keyframe_window_s"), self.param("keyframe_every_s"))
        if judged is not None and not judged.confirmed:
            return self._reject(judged.verdict)
        if judged is not None:
            if judged.node is not None:
                ctx.log(judged.log)
            self.write("target", current if judged.node is None else
                       ctx.candidate_of(judged.node, current.source, float(judged.node.confidence)))
            self.feedback_message = judged.feedback
            return Status.SUCCESS
        state = "pending" if self._seq is None else ctx.nav_state(self._seq)
        move = self._v.next_move(self.settings, elapsed=ctx.now() - self._v.start, sent=self._seq is not None,
                                 state=state, cell=getattr(self, "_cell", None),
                                 mapped=ctx.grid is not None and ctx.pose is not None, stalled=self._stalled)
        said = None if move.reason is not None else next(
            (t for t in (self._try(k, current, move.another_cell) for k in move.tries) if t is not None), None)
        if (ended := verif.move_verdict(move, said)) is not None:
            return self._reject(ended)
        self.feedback_message = said or f"verifying {cand.label} #{cand.object_id}"
        return Status.RUNNING
