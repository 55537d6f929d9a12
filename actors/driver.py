"""DriverActor: the robot (the built-in simulator, or a real robot behind
``drivers.adapters.SimulatorFacade``) behind a Node.

Executes the newest command (latest-wins; stale commands are dropped and counted), publishes the
resulting frame to perception, and ends the episode on STOP, on the step limit, or on an
emergency stop (zero command; further commands are ignored). It never decides anything.

A robot with ``health()`` (a ``drivers.DriverHealth``: the MAVLink driver's failsafes) pauses the
mission while ``health().paused`` (link or heartbeat lost, geofence, mode lost): commands are
dropped (the driver already streams zero), no frames go out, a ``HealthAlert("driver_paused")``
goes to the mission and the runtime, and every pause is kept in ``pauses``. When the failsafe
clears (``resume()`` or a recoverable loss) a fresh frame restarts the pipeline.

``lockstep`` (real-time robots, where a step takes a few hundred ms): a command computed before
the newest frame went out is stale (control issued it on an older snapshot, e.g. when a new goal
arrived while the robot was still moving) and is dropped (counted as ``dropped["stale"]``);
executing it would leave every later command one frame behind the robot (the navigator then
zig-zags and sees false "stuck" steps). The simulator's steps are instantaneous: off by default.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np
from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor

from hiconav.messages import CommandMsg, EpisodeEnded, FrameMsg, HealthAlert
from hiconav.types import DiscreteAction, Pose2D, VelocityCommand


class DriverActor(NodeActor):
    """pykka actor of the driver (the robot / simulator)."""


class DriverNode(Node):
    """Owns the simulator (``reset``/``step``/``step_velocity``/``observe``, ``steps``, ``pose``).

    trajectory: (N, 3) x, y, yaw after each executed action, starting with the reset pose.
    """

    name = "driver"
    actor_class = DriverActor

    def __init__(self, sim: Any, start: Pose2D, *, rate_hz: float = 10.0, max_steps: int = 500,
                 velocity_dt: float = 0.1, frame_to: tuple[str, ...] = ("perception",),
                 ended_to: tuple[str, ...] = ("runtime", "mission", "recorder"),
                 health_to: tuple[str, ...] = ("runtime", "mission"), lockstep: bool = False,
                 stream: bool = False) -> None:
        super().__init__(rate_hz)
        self.sim = sim
        self.start_pose = start
        self.max_steps = max_steps
        self.velocity_dt = velocity_dt
        self.frame_to = frame_to
        self.ended_to = ended_to
        self.health_to = health_to
        self.lockstep = lockstep
        # real time: the camera streams at the driver's rate whether or not a command arrived (the
        # fast layer keeps mapping while the mission waits, e.g. for the VLM to parse the instruction)
        self.stream = stream and not lockstep
        self.streamed = 0
        self._frame_sent_at = -float("inf")  # runtime clock when the newest frame went out
        self.paused = False
        self.pauses: list[dict[str, Any]] = []  # {"start", "end" (None while paused), "reason"}
        self.ended: EpisodeEnded | None = None
        self.trajectory: list[tuple[float, float, float]] = []
        self.sources: list[str] = []  # per executed command (trajectory[i] -> [i + 1]): CommandMsg.source
        self.actions: list[str] = []
        self.last_command: VelocityCommand | DiscreteAction | None = None
        self._pending_frame: Any = None
        self._reobserve = False  # the robot's last frame was invalid: observe again next tick
        self.last_bad_frame = ""
        self.latest_wins(CommandMsg)

    def start(self, now: float) -> None:
        self._pending_frame = self._frame(lambda: self.sim.reset(self.start_pose))
        self._record()

    def _record(self, source: str | None = None) -> None:
        """Append the pose to the trajectory; after a command (``source``: its behaviour) that too."""
        p = self.sim.pose
        self.trajectory.append((float(p.x), float(p.y), float(p.yaw)))
        if source is not None:
            self.sources.append(source)

    def _end(self, reason: str, now: float) -> None:
        if self.ended is None:
            self.ended = EpisodeEnded(reason, int(self.sim.steps), now)
            self.emit(self.ended_to, self.ended)

    def _check_health(self, now: float) -> bool:
        """True while the robot's failsafe pauses the mission (robots without ``health``: never)."""
        health = getattr(self.sim, "health", None)
        if health is None:
            return False
        h = health()
        if h.paused and not self.paused:
            self.paused = True
            reason = h.reason or h.failsafe
            self.pauses.append({"start": now, "end": None, "reason": reason, "failsafe": h.failsafe})
            self.emit(self.health_to, HealthAlert("driver_paused", f"mission paused: {reason}", now))
        elif not h.paused and self.paused:
            self.paused = False
            self.pauses[-1]["end"] = now
            self.emit(self.health_to, HealthAlert("driver_resumed", "mission resumed", now))
            self._pending_frame = self.sim.observe()  # restart the pipeline from the current view
        return self.paused

    def _drop(self, slot: str) -> None:
        self.stats.dropped[slot] = self.stats.dropped.get(slot, 0) + 1

    def _frame(self, make: Any) -> Any:
        """``make()`` (a frame from the robot), or None when the robot's frame is invalid (a NaN
        pose, a broken image: ``FrameError``): the frame is dropped and counted, never the
        mission, and the next tick observes again (a lockstep robot streams nothing by itself)."""
        from hiconav.errors import FrameError

        try:
            return make()
        except FrameError as exc:
            self._drop("bad_frame")
            self.last_bad_frame = str(exc)
            self._reobserve = True
            return None

    def tick(self, now: float) -> None:
        t0 = time.perf_counter()
        if self.ended is None and self._check_health(now):
            if self.take(CommandMsg) is not None:  # the driver streams zero while paused
                self._drop("paused")
            return
        if self._reobserve and self._pending_frame is None and self.ended is None:
            self._reobserve = False
            self._pending_frame = self._frame(self.sim.observe)
        if self._pending_frame is not None:
            self.emit(self.frame_to, FrameMsg(self._pending_frame, int(self.sim.steps)))
            self._pending_frame = None
            self._frame_sent_at = now
        cmd = self.take(CommandMsg)
        if cmd is None and self.stream and self.ended is None and now - self._frame_sent_at >= 0.9 * self.period:
            streamed = self._frame(self.sim.observe)
            if streamed is not None:
                self.emit(self.frame_to, FrameMsg(streamed, int(self.sim.steps)))
                self.streamed += 1
            self._frame_sent_at = now
            return
        if cmd is None or self.ended is not None:
            return
        if (self.lockstep and cmd.action is not None and cmd.action is not DiscreteAction.STOP
                and cmd.stamp < self._frame_sent_at):  # discrete only: velocity commands are continuous
            self._drop("stale")
            return
        if cmd.action is not None:
            self.last_command = cmd.action
            self.actions.append(cmd.action.value)
            frame = self._frame(lambda: self.sim.step(cmd.action))
            self._record(cmd.source)
            if cmd.action == DiscreteAction.STOP:
                self._end("stop", now)
                return
        elif cmd.velocity is not None:
            self.last_command = cmd.velocity
            frame = self._frame(lambda: self.sim.step_velocity(cmd.velocity, self.velocity_dt))
            self._record(cmd.source)
        else:
            return
        if self.sim.steps >= self.max_steps:
            self._end("max_steps", now)
            return
        if frame is None:
            return  # dropped: observed again next tick
        self.emit(self.frame_to, FrameMsg(frame, int(self.sim.steps)))
        self._frame_sent_at = now + (time.perf_counter() - t0)  # the step took real time

    def emergency_stop(self, reason: str, now: float) -> None:
        """Zero command: nothing moves any more; the episode ends (reason 'emergency')."""
        self.last_command = VelocityCommand.zero(now)
        self.take(CommandMsg)
        stop = getattr(self.sim, "stop", None)  # a real robot: zero setpoint now
        if stop is not None:
            try:
                stop()
            except Exception:  # the episode ends anyway; the driver's own failsafe zeroes too
                pass
        self._end("emergency", now)

    def stop(self, now: float) -> None:
        close = getattr(self.sim, "close", None)
        if close is not None:
            close()
        if threading.current_thread() is not threading.main_thread():
            # WORKAROUND (simulator area): the renderer caches one EGL context per thread *id*, and
            # ids are reused once a thread ends, so a later actor thread would inherit a context that
            # is not current in it ("cannot create program"). Drop this thread's context as it ends.
            try:
                from hiconav.sim import renderer

                ctx = renderer._THREAD_CONTEXTS.pop(threading.get_ident(), None)
                if ctx is not None:
                    ctx.release()
            except Exception:  # the renderer may have changed: the workaround is best effort
                pass

    @property
    def path(self) -> np.ndarray:
        return np.asarray(self.trajectory, dtype=np.float64).reshape(-1, 3)
