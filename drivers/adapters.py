"""``SimulatorFacade``: a real-time ``Driver`` presented with the simulator's stepping interface
(``reset`` / ``step`` / ``step_velocity`` / ``observe``, attributes ``pose``, ``steps``,
``collided``), so code written against ``hiconav.sim.Simulator`` (e.g. the driver actor) can
drive a MAVLink robot unchanged.

It blocks: ``step`` sends the action and waits for its duration (a MOVE_FORWARD of 0.25 m at
0.5 m/s takes 0.5 s), ``step_velocity`` sends the command and waits ``dt``. It cannot teleport:
``reset`` leaves the robot where it is and only waits for the first frame. Failsafes stay in
the driver; a paused driver turns every step into "stand still".
"""

from __future__ import annotations

import math
import time
from typing import Any, Callable

from hiconav.drivers.base import Driver, DriverError, discrete_to_segment
from hiconav.drivers.profiles import RobotProfile
from hiconav.types import DiscreteAction, Frame, Pose2D, VelocityCommand

__all__ = ["SimulatorFacade"]


class SimulatorFacade:
    def __init__(self, driver: Driver, profile: RobotProfile, *, wait_frame_s: float = 10.0,
                 settle_s: float = 0.05, clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.driver = driver
        self.profile = profile
        self.wait_frame_s = wait_frame_s
        self.settle_s = settle_s
        self._clock = clock
        self._sleep = sleep
        self.steps = 0
        self.collided = False  # a real robot does not report collisions through MAVLink
        self.stopped = False
        self._frame: Frame | None = None

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
        deadline = self._clock() + self.wait_frame_s
        while True:
            frame = self.driver.latest_frame()
            if frame is not None:
                self._frame = frame
                return frame
            if self._clock() >= deadline:
                raise DriverError(f"no frame from the driver within {self.wait_frame_s} s "
                                  f"(health: {self.driver.health().reason or 'ok'})")
            self._sleep(0.02)

    def observe(self) -> Frame:
        frame = self.driver.latest_frame()
        if frame is None:
            if self._frame is None:
                raise DriverError("the driver has no frame")
            return self._frame
        self._frame = frame
        return frame

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
            self._sleep(duration + self.settle_s)
        self.steps += 1
        return self.observe()

    def step_velocity(self, cmd: VelocityCommand, dt: float) -> Frame:
        if not dt > 0.0:
            raise DriverError(f"dt must be > 0, got {dt}", field="dt")
        self.driver.send(cmd)
        self._sleep(dt)
        self.steps += 1
        return self.observe()

    def close(self) -> None:
        self.driver.close()

    def __getattr__(self, name: str) -> Any:  # e.g. house, config for code that reads them
        raise AttributeError(f"SimulatorFacade has no attribute {name!r} (a real robot has no {name})")
