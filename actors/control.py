"""ControlActor: A* + local planner toward the mission's goal; commands to the driver.

Owns one ``Navigator``. Goals arrive as ``GoalMsg`` (None cancels); world snapshots are
latest-wins. One command per new snapshot (so a discrete action is never issued twice for the same
pose); progress goes back to the mission as ``NavStatus`` ("active" | "reached" | "failed").
``StopRequest`` sends the STOP action. With ``hold_while_reasoning`` (the sync_reasoning ablation) it
sends nothing while a reasoning call is in flight (``ReasoningBusy``): the robot stands still until
the reply, as a navigator that blocks on its VLM does. It never chooses goals.
"""

from __future__ import annotations

from typing import Any

from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor

from hiconav.messages import CommandMsg, GoalMsg, NavStatus, ReasoningBusy, StopRequest, WorldSnapshot
from hiconav.types import DiscreteAction


class ControlActor(NodeActor):
    """pykka actor of the control layer."""


class ControlNode(Node):
    name = "control"
    event_driven = True  # per-frame chain: see Node.event_driven
    actor_class = ControlActor

    def __init__(self, navigator: Any, *, rate_hz: float = 10.0, mode: str = "discrete",
                 velocity_dt: float = 0.1, hold_while_reasoning: bool = False) -> None:
        super().__init__(rate_hz)
        if mode not in ("discrete", "velocity"):
            raise ValueError(f"control mode must be 'discrete' or 'velocity', got {mode!r}")
        self.navigator = navigator
        self.mode = mode
        self.velocity_dt = velocity_dt
        self.goal_seq = 0
        self.state = "idle"
        self._snapshot: WorldSnapshot | None = None
        self._fresh = False
        self._stop: StopRequest | None = None
        self._cmd_seq = 0
        # discrete actions commanded, per source of the goal they served (``GoalMsg.source``, the
        # behaviour that sent it): {"Explore": {"turns": 120, "forward": 150}, ...}
        self.actions: dict[str, dict[str, int]] = {}
        self._source = ""
        self.hold_while_reasoning = hold_while_reasoning
        self.hold_until = 0.0
        self.held_ticks = 0
        self.on(ReasoningBusy, lambda m, now: setattr(self, "hold_until", max(self.hold_until, m.until)))
        self.on(WorldSnapshot, self._on_snapshot)
        self.on(GoalMsg, self._on_goal)
        self.on(StopRequest, lambda m, now: setattr(self, "_stop", m))

    def _on_snapshot(self, msg: WorldSnapshot, now: float) -> None:
        if self._fresh:
            self.stats.dropped["WorldSnapshot"] = self.stats.dropped.get("WorldSnapshot", 0) + 1
        self._snapshot, self._fresh = msg, True

    def _on_goal(self, msg: GoalMsg, now: float) -> None:
        self.navigator.set_goal(msg.goal)
        self.goal_seq = msg.seq
        self._source = msg.source
        self._set_state("idle" if msg.goal is None else "active", now)
        self._fresh = True  # act on the newest snapshot even if the robot has not moved

    def _count(self, action: DiscreteAction) -> None:
        """Tally a commanded discrete action under its goal's source: a turn in place (left or
        right), a forward step, or another action (looking up or down)."""
        tally = self.actions.setdefault(self._source or "unnamed", {"turns": 0, "forward": 0, "other": 0})
        kind = ("turns" if action in (DiscreteAction.TURN_LEFT, DiscreteAction.TURN_RIGHT) else
                "forward" if action == DiscreteAction.MOVE_FORWARD else "other")
        tally[kind] += 1

    def _set_state(self, state: str, now: float) -> None:
        if state != self.state or state == "active":
            self.emit("mission", NavStatus(self.goal_seq, state, now))
        self.state = state

    def _command(self, now: float, **kw: Any) -> None:
        self._cmd_seq += 1
        self.emit("driver", CommandMsg(self._cmd_seq, now, source=self._source or "", **kw))

    def tick(self, now: float) -> None:
        if self._stop is not None:
            self._command(now, action=DiscreteAction.STOP)
            self._stop = None
            self._fresh = False
            return
        if not self._fresh or self._snapshot is None or self.state != "active":
            return
        if self.hold_while_reasoning and now < self.hold_until - 1e-9:
            self.held_ticks += 1  # keeps the snapshot fresh: act on it once the reply is in
            return
        self._fresh = False
        snap = self._snapshot
        if self.mode == "discrete":
            action = self.navigator.step(snap.grid, snap.pose)
            if self.navigator.reached:
                self._set_state("reached", now)
            elif action == DiscreteAction.STOP:  # nothing to do: no path
                self._set_state("failed", now)
            else:
                self._command(now, action=action)
                self._count(action)
        else:
            cmd = self.navigator.step_velocity(snap.grid, snap.pose, self.velocity_dt, now)
            if self.navigator.reached:
                self._set_state("reached", now)
            elif getattr(self.navigator, "status", "") in ("no_path", "stuck"):
                self._set_state("failed", now)
            else:
                self._command(now, velocity=cmd)
