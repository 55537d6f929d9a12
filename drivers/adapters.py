"""``SimulatorFacade``: a real-time ``Driver`` presented with the simulator's stepping interface
(``reset`` / ``step`` / ``step_velocity`` / ``observe``, attributes ``pose``, ``steps``,
``collided``, ``stopped``, ``path_length``), so code written against ``hiconav.sim.Simulator``
(e.g. the driver actor of ``hiconav run --driver mavlink``) can drive a MAVLink robot unchanged.
``health()`` and ``resume()`` pass through to the driver so the driver actor can pause the
mission while a failsafe holds the robot.

It blocks: ``step`` sends the action and waits for its duration (a MOVE_FORWARD of 0.25 m at
0.5 m/s takes 0.5 s) and then until the robot has stopped: the driver has sent a zero setpoint
and a pose newer than that (plus ``settle_s``) has arrived, so the frame after a step shows the
pose the step ended at (a lagging pose makes the navigator oscillate). ``step_velocity`` sends
the command and waits ``dt``. It cannot teleport: ``reset`` leaves the robot where it is and only
waits for the first frame. Frame stamps become seconds since ``reset`` (as the simulator's). Failsafes stay in
the driver; a paused driver turns every step into "stand still".
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from typing import Any

from hiconav.drivers.base import Driver, DriverError, DriverHealth, discrete_to_segment
from hiconav.drivers.profiles import RobotProfile

from hiconav.types import DiscreteAction, Frame, Pose2D, VelocityCommand

__all__ = ["SimulatorFacade", "open_mission_robot"]


class SimulatorFacade:
    """A ``Driver`` behind the simulator's interface (see the module docstring).

    ``path_length`` (m) sums the xy distance between the poses observed after each step (the
    robot's reported poses, so it includes drift between steps). ``frame_source``, when given,
    is closed with the facade (the facade then owns it).
    """

    def __init__(self, driver: Driver, profile: RobotProfile, *, wait_frame_s: float = 10.0,
                 settle_s: float = 0.05, clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep, frame_source: Any = None) -> None:
        self.driver = driver
        self.profile = profile
        self.frame_source = frame_source
        self.name = type(driver).__name__.removesuffix("Driver").lower() or "robot"  # e.g. "mavlink"
        self.path_length = 0.0
        self._last_xy: tuple[float, float] | None = None
        self.wait_frame_s = wait_frame_s
        self.settle_s = settle_s
        self._clock = clock
        self._sleep = sleep
        self.steps = 0
        self.collided = False  # a real robot does not report collisions through MAVLink
        self.stopped = False
        self._frame: Frame | None = None
        self._t_reset = 0.0
        self.settle_timeouts = 0  # steps after which the robot was not seen at rest in time

    @property
    def pose(self) -> Pose2D:
        pose = getattr(self.driver, "pose", None)
        if pose is not None:
            return pose
        if self._frame is None:
            raise DriverError("no pose yet: call reset() first")
        return self._frame.base_pose

    def reset(self, start: Pose2D | None = None) -> Frame:
        """Wait for the first frame; ``start`` is ignored (a real robot starts where it stands)."""
        self.steps = 0
        self.stopped = False
        self._t_reset = self._clock()
        deadline = self._t_reset + self.wait_frame_s
        while True:
            frame = self._latest()
            if frame is not None:
                self._frame = frame
                self.path_length = 0.0
                self._last_xy = (frame.base_pose.x, frame.base_pose.y)
                return frame
            if self._clock() >= deadline:
                raise DriverError(f"no frame from the driver within {self.wait_frame_s} s "
                                  f"(health: {self.driver.health().reason or 'ok'})")
            self._sleep(0.02)

    def _latest(self) -> Frame | None:
        frame = self.driver.latest_frame()
        if frame is None:
            return None
        return dataclasses.replace(frame, stamp=float(frame.stamp) - self._t_reset)

    def _settle(self, timeout: float = 1.0) -> None:
        """Wait until the driver has sent zero and a pose ``settle_s`` newer than that arrived.

        Drivers without ``last_sent`` / ``pose_stamp`` (fallback): wait ``settle_s``.
        """
        if not (hasattr(self.driver, "last_sent") and hasattr(self.driver, "pose_stamp")):
            self._sleep(self.settle_s)
            return
        deadline = self._clock() + timeout
        while tuple(self.driver.last_sent) != (0.0, 0.0):  # type: ignore[attr-defined]
            if self._clock() >= deadline:
                self.settle_timeouts += 1
                return
            self._sleep(0.005)
        zero_at = self._clock()
        while True:
            stamp = self.driver.pose_stamp  # type: ignore[attr-defined]
            if stamp is not None and stamp >= zero_at + self.settle_s:
                return
            if self._clock() >= deadline:
                self.settle_timeouts += 1
                return
            self._sleep(0.005)

    def observe(self) -> Frame:
        frame = self._latest()
        if frame is None:
            if self._frame is None:
                raise DriverError("the driver has no frame")
            return self._frame
        self._frame = frame
        return frame

    def _moved(self) -> None:
        p = self.pose
        if self._last_xy is not None:
            self.path_length += math.hypot(p.x - self._last_xy[0], p.y - self._last_xy[1])
        self._last_xy = (p.x, p.y)

    def health(self) -> DriverHealth:
        return self.driver.health()

    def resume(self) -> None:
        """Clear a latched failsafe (``DriverError`` saying why not); drivers without one: no-op."""
        resume = getattr(self.driver, "resume", None)
        if resume is not None:
            resume()

    def stop(self) -> None:
        """Zero velocity now (does not end the episode; ``step(STOP)`` does)."""
        self.driver.stop()

    def step(self, action: DiscreteAction) -> Frame:
        if action is DiscreteAction.STOP:
            self.driver.stop()
            self.stopped = True
        else:
            lim, disc = self.profile.limits, self.profile.discrete
            _, _, duration = discrete_to_segment(action, forward_step=disc.forward_step,
                                                 turn_rad=math.radians(disc.turn_deg),
                                                 max_linear=lim.max_linear, max_angular=lim.max_angular)
            self.driver.send(action)
            self._sleep(duration)
            self._settle()
        self.steps += 1
        frame = self.observe()
        self._moved()
        return frame

    def step_velocity(self, cmd: VelocityCommand, dt: float) -> Frame:
        if not dt > 0.0:
            raise DriverError(f"dt must be > 0, got {dt}", field="dt")
        self.driver.send(cmd)
        self._sleep(dt)
        self.steps += 1
        frame = self.observe()
        self._moved()
        return frame

    def close(self) -> None:
        """Stop and release the link, then the frame source (if the facade owns one)."""
        try:
            self.driver.close()
        finally:
            close = getattr(self.frame_source, "close", None)
            self.frame_source = None
            if close is not None:
                close()

    def __getattr__(self, name: str) -> Any:  # e.g. house, config for code that reads them
        raise AttributeError(f"SimulatorFacade has no attribute {name!r} (a real robot has no {name})")


def open_mission_robot(profile: RobotProfile, *, url: str | None = None, house: Any = None,
                       handle_signals: bool = True, engage: bool = True) -> SimulatorFacade:
    """Connect a MAVLink robot for a mission (``hiconav run --driver mavlink``).

    Frames come from the profile's ``frames`` section; with ``source: sim`` they are rendered in
    ``house`` (a loaded ``hiconav.sim.House`` or a spec; default the profile's ``frames.house``)
    at the pose the vehicle reports. Connects, waits for the heartbeat, engages (GUIDED/OFFBOARD,
    arm) and returns the facade, which owns both the driver and the frame source. Errors
    (``LinkError``, ``CommandRefused``) close what was opened and propagate.
    """
    from hiconav.drivers import open_driver
    from hiconav.drivers.frame_sources import make_frame_source

    source = make_frame_source(profile, house=house)
    if source is None:
        raise DriverError(f"robot profile {profile.name!r} names no frame source (frames.source: none); "
                          "a mission needs RGB-D frames", field="frames.source")
    try:
        driver = open_driver("mavlink", profile, url=url, frame_source=source, handle_signals=handle_signals,
                             engage=engage)
    except BaseException:
        close = getattr(source, "close", None)
        if close is not None:
            close()
        raise
    return SimulatorFacade(driver, profile, frame_source=source)
