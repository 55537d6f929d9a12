"""The mission's small behaviours: ParseInstruction, TargetConfirmed, ReturnToStart, Stop, HealthOk.

Explore, VerifyTarget and Approach live in ``explore.py``, ``verify.py`` and ``approach.py``. Each
behaviour polls the ``MissionContext`` (results the actors delivered) and posts requests to it
(goals, parse and stop requests) that the Mission actor turns into messages: ``initialise()``
starts the work, ``update()`` checks progress and returns at once, ``terminate()`` cancels what
was started (including when a higher-priority branch preempts it). Nothing here blocks, sleeps or
talks to an actor directly; thresholds come from the ``decisions.*`` settings.
"""

from __future__ import annotations

from hiconav.trees.behaviours.base import MissionBehaviour, Status
from hiconav.trees.registry import Param, register_behaviour
from hiconav.types import Goal


@register_behaviour()
class ParseInstruction(MissionBehaviour):
    """Decompose the instruction into target/related objects (reasoning layer); writes ``task``."""

    PARAMS = {"instruction": Param(str, "{instruction}", doc="the instruction, or {key}")}
    SETTINGS = "parse"
    WRITES = ("task",)

    def initialise(self) -> None:
        self._start = self.context.now()
        instruction = self.param("instruction")
        if self.context.task is None or self.context.task.instruction != instruction:
            self.context.task = None
            self.context.instruction = instruction
            self.context.request_task(instruction)

    def update(self) -> Status:
        task = self.context.task
        if task is not None:
            self.write("task", task)
            self.feedback_message = f"targets {list(task.targets)} related {list(task.related)}"
            return Status.SUCCESS
        if self.context.now() - self._start > self.param("timeout_s"):
            self.feedback_message = "no task from the reasoning layer"
            return Status.FAILURE
        return Status.RUNNING


@register_behaviour()
class TargetConfirmed(MissionBehaviour):
    """Condition: a target candidate (hypothesis or memory match) exists; writes ``target``."""

    SETTINGS = "target"
    WRITES = ("target",)

    def update(self) -> Status:
        for cand in self.context.candidates():
            if cand.confidence >= self.param("min_confidence") and cand.n_obs >= self.param("min_observations"):
                self.write("target", cand)
                self.feedback_message = f"{cand.label} #{cand.object_id} ({cand.source})"
                return Status.SUCCESS
        self.feedback_message = "no candidate"
        return Status.FAILURE



@register_behaviour()
class ReturnToStart(MissionBehaviour):
    """Go back to the pose where the mission started (second-mission example)."""

    SETTINGS = "return_home"

    def initialise(self) -> None:
        self._start = self.context.now()
        start = self.context.start_pose
        self._seq = None
        if start is not None:
            self._seq = self.context.send_goal(Goal(start.x, start.y, None, self.param("tolerance"), "return"))

    def update(self) -> Status:
        ctx = self.context
        if self._seq is None:
            return Status.FAILURE
        pose = ctx.pose
        start = ctx.start_pose
        if pose is not None and start is not None and pose.distance_to(start) <= self.param("tolerance"):
            return Status.SUCCESS
        if ctx.nav_state(self._seq) == "failed" or ctx.now() - self._start > self.param("timeout_s"):
            return Status.FAILURE
        return Status.RUNNING

    def cleanup(self, new_status: Status) -> None:
        if getattr(self, "_seq", None) is not None and self.ctx is not None and new_status == Status.INVALID:
            self.ctx.send_goal(None)


@register_behaviour()
class Stop(MissionBehaviour):
    """End the episode: ask the control layer for the STOP action."""

    PARAMS = {"reason": Param(str, "mission complete")}

    def update(self) -> Status:
        if not self.context.stop_requested:
            self.context.request_stop(self.param("reason"))
        return Status.SUCCESS


@register_behaviour()
class HealthOk(MissionBehaviour):
    """Condition: no health alert (e.g. a low battery) has been reported to the mission."""

    PARAMS = {"alert": Param(str, "", doc="only this alert kind ('' = any)")}

    def update(self) -> Status:
        alerts = self.context.alerts
        kind = self.param("alert")
        bad = [a for a in alerts if not kind or a.kind == kind]
        self.feedback_message = bad[-1].text if bad else "ok"
        return Status.FAILURE if bad else Status.SUCCESS


__all__ = ["HealthOk", "ParseInstruction", "ReturnToStart", "Stop", "TargetConfirmed"]
