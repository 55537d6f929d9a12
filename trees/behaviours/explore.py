"""Explore: follow the exploration plan's WTRP order of frontiers (the mission's search).

A thin poller of ``hiconav.decisions.frontiers``: each tick it reads the context (the plan, the
pose, the state of the goal in flight, the mission's record of exploration), asks the
``FrontierFollower`` what to do, and posts it (goal, cancel, log lines). Thresholds come from
``decisions.explore``. Nothing here decides, blocks or talks to an actor.
"""

from __future__ import annotations

from hiconav.decisions import linger
from hiconav.decisions.frontiers import (ExploreLedger, FrontierFollower, FrontierGoal, PlanView, look_goal,
                                        start_look_step)
from hiconav.decisions.viewing import DONE
from hiconav.trees.behaviours.base import MissionBehaviour, Status
from hiconav.trees.registry import register_behaviour
from hiconav.types import Goal


@register_behaviour()
class Explore(MissionBehaviour):
    """Follow the exploration plan: go to the first frontier of the WTRP order, re-planned as the
    map grows; FAILURE when no frontier is left for ``max_idle_s``.

    The decisions are ``FrontierFollower``'s (``hiconav.decisions.frontiers``): viewpoints facing
    their frontier, spent viewpoints skipped, a push into a spent frontier beside the robot, a
    squeeze toward failed frontiers, the look-around turns, the idle clock, the last resort of an
    explored-out search (``hiconav.decisions.last_resort``). What must outlive one
    activation lives in the mission context (the idle clock ``last_frontier_time``, the start's
    and each spot's look counts, the spent / pushed / failed / squeezed spots), so a retried
    Explore goes on where a preempted one stopped, and one retried over an explored-out map
    fails at once instead of idling (and turning) again; what this activation visited is the
    follower's and starts anew with each ``initialise``."""

    SETTINGS = "explore"

    def initialise(self) -> None:
        self._seq: int | None = None
        if self.context.last_frontier_time is None:
            self.context.last_frontier_time = self.context.now()
        self._follower = FrontierFollower()
        self._lingering: int | None = None  # the node Explore turns beside (``decisions.linger``)

    def update(self) -> Status:
        ctx = self.context
        if self._linger():
            return Status.RUNNING
        ledger = ExploreLedger(ctx.last_frontier_time, ctx.start_looks, ctx.look_spot, ctx.looks_here,
                               ctx.spent_viewpoints, ctx.pushed_frontiers, ctx.failed_frontiers,
                               ctx.squeezed_frontiers, self._asks_left(), int(ctx.stranded))
        state = None if self._seq is None else ctx.nav_state(self._seq)
        plan = PlanView.of(ctx.plan, None if ctx.world is None else ctx.world.seq)
        step = self._follower.step(state, ctx.pose, ctx.now(), plan, ledger, ctx.deferred, self.settings)
        ctx.last_frontier_time, ctx.start_looks = ledger.last_frontier_time, ledger.start_looks
        ctx.look_spot, ctx.looks_here = ledger.look_spot, ledger.looks_here
        for text in step.log:
            ctx.log(text)
        if step.ended:
            self._seq = None
        if step.cancel:
            ctx.send_goal(None)
            self._seq = None
        if step.goal is not None:
            self._seq = ctx.send_goal(_goal(step.goal))
        if step.release_deferred:
            ctx.deferred.clear()
        if step.ask_unresolved:
            ctx.report_explored_out()
        if step.last_resort:
            ctx.take_last_resort()  # the next tick's TargetConfirmed takes it up
        self.feedback_message = step.feedback
        return Status.FAILURE if step.status == "failure" else Status.RUNNING

    def _linger(self) -> bool:
        """Turn in place beside an undecided instance of a described target's category come upon
        close by (``linger.undecided_near``), ``linger_turns`` quarter turns once per instance, then
        explore on afresh: True while turning."""
        ctx, s, pose = self.context, self.settings, self.context.pose
        if self._lingering is not None:
            if ctx.nav_state(self._seq) not in DONE:
                return True
            self._turns += 1
            if self._turns < s.linger_turns:
                self._seq = ctx.send_goal(_goal(look_goal(pose)))
                return True
            self._lingering, self._seq, self._follower = None, None, FrontierFollower()
            return False
        if (s.linger_turns <= 0 or pose is None or ctx.memory is None or not (ctx.reasoning and ctx.described)
                or ctx.start_looks < s.start_look_turns):
            return False
        oid = linger.undecided_near(ctx.memory.objects, ctx.task.targets, (pose.x, pose.y), s.linger_m,
                                    ctx.ruled_out, ctx.lingered, ctx.excluded)
        if oid is None:
            return False
        ctx.lingered.add(oid)
        ctx.log(f"Explore: turning beside undecided #{oid}")
        self._lingering, self._turns, ctx.last_frontier_time = oid, 0, ctx.now()
        self._seq = ctx.send_goal(_goal(look_goal(pose)))
        self.feedback_message = f"looking around #{oid}"
        return True

    def _asks_left(self) -> int:
        """Asks for an unresolved candidate left: only a described instance that the reasoning
        layer decides has them."""
        ctx = self.context
        if not (ctx.reasoning and ctx.described):
            return 0
        return max(int(self.settings.unresolved_asks) - ctx.unresolved_asks, 0)

    def cleanup(self, new_status: Status) -> None:
        if getattr(self, "_seq", None) is not None and self.ctx is not None:
            self.ctx.send_goal(None)
            self._seq = None


@register_behaviour()
class LookAround(MissionBehaviour):
    """Turn in place a quarter turn at a time until the mission's start look is done
    (``explore.start_look_turns``; ``frontiers.start_look_step``), then SUCCESS. The turns count
    in ``MissionContext.start_looks``, which Explore reads: it does not look again.

    Before the search, it shows the start room all round before a candidate is chosen: a
    candidate seen in the first frames would be judged against a map with no view cell of it
    yet, and the nearest one may stand behind the robot."""

    SETTINGS = "explore"

    def initialise(self) -> None:
        self._seq: int | None = None

    def update(self) -> Status:
        ctx = self.context
        state = None if self._seq is None else ctx.nav_state(self._seq)
        ctx.start_looks, goal, done = start_look_step(state, ctx.pose, ctx.start_looks, self.settings)
        if state in DONE:
            self._seq = None
        if done:
            self.feedback_message = "looked around the start"
            return Status.SUCCESS
        if goal is not None:
            self._seq = ctx.send_goal(_goal(goal))
        self.feedback_message = f"looking around the start ({ctx.start_looks}/{self.param('start_look_turns')})"
        return Status.RUNNING


def _goal(goal: FrontierGoal) -> Goal:
    """The control layer's goal for a frontier-following goal (a look is a "look" goal)."""
    if goal.kind == "look":
        return Goal(goal.x, goal.y, goal.yaw, goal.tolerance, "look")
    return Goal(goal.x, goal.y, goal.yaw, goal.tolerance, "frontier", goal.frontier,
                through_unknown=goal.through_unknown)
