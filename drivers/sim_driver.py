"""The default driver: the built-in simulator (``hiconav.sim.Simulator``) behind the ``Driver``
protocol.

Synchronous and thread-free: ``send`` steps the simulator once (a discrete action, or a velocity
for ``rates.control_dt`` seconds) and the resulting frame becomes ``latest_frame()``. Velocities
are clamped to the profile's limits; with a geofence in the profile, forward motion that would
leave it is cut, as on the robot. It must not render or step on its own: no command, no motion.
"""

from __future__ import annotations

import math
from typing import Any

from hiconav.drivers.base import DRIVERS, DriverError, DriverHealth, FailsafeState, clamp_velocity
from hiconav.drivers.failsafe import FailsafeMonitor, FailsafeStatus, Geofence
from hiconav.drivers.profiles import RobotProfile

from hiconav.types import DiscreteAction, Frame, Pose2D, VelocityCommand

__all__ = ["SimDriver"]


class SimDriver:
    """Drive a ``Simulator`` (contract: reset/step/step_velocity/observe, attributes pose/collided).

    ``start``: the start pose (default: the house's ``start_hint``, else the simulator's pose).
    """

    def __init__(self, simulator: Any, profile: RobotProfile | None = None, *, start: Pose2D | None = None,
                 owns_simulator: bool = False) -> None:
        self.simulator = simulator
        self.profile = profile or RobotProfile(name="sim-default", driver="sim")
        self._owns = owns_simulator
        self._fence = Geofence.from_profile(self.profile.geofence)
        self._monitor = FailsafeMonitor(self.profile.failsafe, self._fence)
        if start is None:
            hint = getattr(getattr(simulator, "house", None), "start_hint", None)
            start = Pose2D(*hint) if hint is not None else simulator.pose
        self._frame: Frame | None = simulator.reset(start)
        self._closed = False
        self.last_reason = ""

    @staticmethod
    def from_house(spec: str, profile: RobotProfile | None = None, *, start: Pose2D | None = None,
                   sim_config: Any = None, seed: int = 0) -> SimDriver:
        from hiconav.sim import Simulator, load_house

        return SimDriver(Simulator(load_house(spec), sim_config, seed), profile, start=start, owns_simulator=True)

    @property
    def pose(self) -> Pose2D:
        return self.simulator.pose

    def latest_frame(self) -> Frame | None:
        return self._frame

    def send(self, command: VelocityCommand | DiscreteAction) -> None:
        if self._closed:
            raise DriverError("the sim driver is closed")
        pose = self.simulator.pose
        ok = FailsafeStatus(FailsafeState.OK, "", False, True, 0.0)
        if isinstance(command, DiscreteAction):
            if command is DiscreteAction.MOVE_FORWARD and self._fence is not None:
                step = self.simulator.config.forward_step
                if not self._fence.contains(pose.x + step * math.cos(pose.yaw), pose.y + step * math.sin(pose.yaw)):
                    self.last_reason = "motion toward the geofence boundary refused"
                    return
            self.last_reason = ""
            self._frame = self.simulator.step(command)
        elif isinstance(command, VelocityCommand):
            lim = self.profile.limits
            v, w = clamp_velocity(command, lim.max_linear, lim.max_angular, lim.allow_reverse)
            v, w, self.last_reason = self._monitor.gate(ok, pose, v, w)
            self._frame = self.simulator.step_velocity(VelocityCommand(v, w, command.stamp), self.profile.rates.control_dt)
        else:
            raise DriverError(f"cannot send {type(command).__name__}; expected VelocityCommand or DiscreteAction")

    def stop(self) -> None:
        """The simulator has no momentum: stopping means sending nothing further."""

    def health(self) -> DriverHealth:
        pose = self.simulator.pose
        if self._closed:
            return DriverHealth(False, math.inf, FailsafeState.CLOSED, "closed", True)
        if self._fence is not None and not self._fence.contains(pose.x, pose.y):
            return DriverHealth(True, 0.0, FailsafeState.GEOFENCE, "robot outside the geofence", True)
        return DriverHealth(True, 0.0, FailsafeState.OK, self.last_reason, False)

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            if self._owns and hasattr(self.simulator, "close"):
                self.simulator.close()


def _make_sim(profile: RobotProfile, **options: Any) -> SimDriver:
    simulator = options.pop("simulator", None)
    start = options.pop("start", None)
    if simulator is not None:
        return SimDriver(simulator, profile, start=start)
    house = options.pop("house", None) or profile.frames.house
    if not house:
        raise DriverError("the sim driver needs a house (house= or frames.house in the profile)", field="frames.house")
    return SimDriver.from_house(house, profile, start=start, **options)


DRIVERS.add("sim", _make_sim)
