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
from hiconav.decisions import verification as verif
from hiconav.decisions import viewing as view
from hiconav.trees.behaviours.base import Status
from hiconav.trees.behaviours.goto import _GoToObject
from hiconav.trees.context import Candidate
from hiconav.trees.registry import register_behaviour


@register_behaviour()
class VerifyTarget(_GoToObject):
    """Go within ``verify_distance`` of the candidate, facing it, and confirm it with fresh views,
    glancing ``glance_deg`` left and right of it so that each glance makes an anchor. The state of
    the verification and its next move are ``verification.Verification``'s; a verdict rejects or
    defers the candidate (``MissionContext.reject``); a confirmed one is written as the target."""

    SETTINGS = "verify"
    WRITES = ("target",)
    READS = ()

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
    def _stall_near(self) -> float:
        return self.param("stall_near")

    def _prefer_weight(self) -> float:
        return self.param("view_ray_weight")

    def _sight(self, cand: Candidate) -> tuple[np.ndarray, float, np.ndarray, np.ndarray] | None:
        return view.sight(cand.center, self._camera(), verif.hiding(self.settings, self.context.memory,
                                                                    self._targets(), cand))

    def _preferred_xy(self, cand: Candidate, distance: float) -> np.ndarray | None:
        return view.seen_from_node(cand.center, self.context.memory, self.context.object(cand.object_id), distance)

    def _ring(self, cand: Candidate) -> float:
        return view.view_ring(self.settings, float(np.asarray(cand.center)[2]), self._camera())

    def _targets(self) -> list[str] | None:
        return self.context.task.targets if self.context.task is not None else None

    # -- polling ---------------------------------------------------------------------------------
    def _reject(self, verdict: conf.Verdict) -> Status:
        """Post a rejection or deferral (``verdict``) of the candidate; FAILURE."""
        if self._cand is not None:
            ctx, oid = self.context, self._cand.object_id
            post = verif.posting(self.settings, verdict, oid, ctx.rejections, ctx.remaps.get(oid, 0), ctx.can_remap(oid))
            ctx.reject(oid, verdict.reason, permanent=post.permanent, defer_s=self.param("defer_s"),
                       requalify=verdict.requalify, remap=post.remap)
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

    def _judge(self, current: Candidate, obj: object) -> Status | None:
        """Judge the new frames of ``current`` (close to it); its verdict's status, or None."""
        ctx = self.context
        judged = self._v.judge(self.settings, ctx.memory, ctx.grid, current, self._targets(), self._cand.label)
        if judged is None or judged.verdict.outcome != "confirmed":
            return None if judged is None else self._reject(judged.verdict)
        if (node := None if judged.found is None else ctx.object(judged.found)) is not None:
            ctx.log(judged.log)
        self.write("target", current if node is None else ctx.candidate_of(node, current.source, float(node.confidence)))
        self.feedback_message = f"confirmed {obj.label} #{obj.id}: {judged.verdict.reason}"
        return Status.SUCCESS

    def _try(self, kind: str, current: Candidate, another: bool) -> str | None:
        """Send the goal of a ``ViewMove`` try: its feedback, or None when it cannot go."""
        ctx, cand, pose = self.context, self._cand, self.context.pose
        if kind == "view":
            sent = self._send(current, self._ring(current))
            return verif.view_feedback(cand.label, cand.object_id, another) if sent else None
        if kind == "glance":
            self._seq = ctx.send_goal(self._v.glance(pose, current, self.param("glance_deg")))
            return ""
        if ctx.grid is None or pose is None or kind == "remap":
            return None if ctx.grid is None or pose is None else kind
        goal = self._v.fallback(kind, self.settings, ctx.grid, current, np.array([pose.x, pose.y]),
                                gap=ctx.distance_to_box(current.box_min, current.box_max), ring=self._ring(current),
                                furniture=self._furniture(current), heights=self._wall_heights(current),
                                view=self._sight(current), label=cand.label)
        if goal is not None:
            self._go_to_cell(current, goal.cell, goal.tolerance, through_unknown=goal.through_unknown)
            ctx.log(goal.log)
        return None if goal is None else goal.feedback

    def update(self) -> Status:
        ctx, cand = self.context, self._cand
        if cand is None:
            self.feedback_message = "no target to verify"
            return Status.FAILURE
        if not ctx.verify:
            self.feedback_message = "verification disabled: candidate accepted as is"
            return Status.SUCCESS
        if (obj := ctx.object(cand.object_id)) is None:
            return self._reject(conf.Verdict("rejected", "object node disappeared from memory"))
        if (switched := self._switch(obj, cand)) is not None:
            return switched
        current = Candidate(cand.object_id, *verif.node_fields(obj), cand.source)
        if (flipped := conf.label_verdict(self._targets(), obj.label, cand.source)) is not None:
            return self._reject(flipped)
        # judged every tick, for the current box: the box grows as it is seen
        gap = ctx.distance_to_box(current.box_min, current.box_max)
        self._v.close = gap <= view.close_distance(self.settings, self._ring(current))
        if self._v.close and (judged := self._judge(current, obj)) is not None:
            return judged
        if (late := conf.timeout_verdict(self.settings, ctx.now() - self._v.start)) is not None:
            return self._reject(late)
        state = "pending" if self._seq is None else ctx.nav_state(self._seq)
        move = self._v.next_move(self.settings, sent=self._seq is not None, state=state,
                                 cell=getattr(self, "_cell", None), stalled=self._stalled)
        said = None if move.reason else next((t for t in (self._try(k, current, move.another_cell)
                                                          for k in move.tries) if t is not None), "")
        if (ended := verif.move_verdict(move, said)) is not None:
            return self._reject(ended)
        self.feedback_message = said or f"verifying {cand.label} #{cand.object_id}"
        return Status.RUNNING
