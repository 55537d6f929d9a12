"""The robot-side boundary: the ``Driver`` protocol, its health report and the driver registry.

A driver hands the navigator RGB-D frames (with intrinsics, base pose and stamp) and turns its
commands (``VelocityCommand`` or ``DiscreteAction``) into robot motion. Every driver (simulator,
MAVLink, replay) implements the same five calls, so the actors above never know which robot
they drive.

This module must not import pymavlink, the simulator or any socket code: it is the light,
shared part that ``actors/`` and tests import. Drivers may own threads (the MAVLink driver
streams setpoints from one); the core in ``hiconav/`` never does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from hiconav.errors import HiconavError
from hiconav.registry import Registry
from hiconav.types import DiscreteAction, Frame, Pose2D, VelocityCommand

__all__ = [
    "DRIVERS",
    "CommandRefused",
    "Driver",
    "DriverError",
    "DriverHealth",
    "FailsafeState",
    "FrameSource",
    "LinkError",
    "discrete_to_segment",
]


class DriverError(HiconavError):
    """A driver cannot do what was asked (no link, bad URL, refused command)."""


class LinkError(DriverError):
    """The link to the robot could not be opened or no heartbeat arrived in time."""


class CommandRefused(DriverError):
    """The autopilot refused a command (mode change, arming); ``result`` is MAV_RESULT's name."""

    def __init__(self, message: str, *, command: str, result: str, statustext: str = "") -> None:
        self.command = command
        self.result = result
        self.statustext = statustext
        super().__init__(message)


class FailsafeState:
    """Names of the failsafe states reported in ``DriverHealth.failsafe`` (plain strings)."""

    OK = "ok"
    LINK_LOST = "link_lost"  # no message from the vehicle for longer than link_timeout_s
    HEARTBEAT_LOST = "heartbeat_lost"  # no HEARTBEAT for longer than heartbeat_timeout_s
    POSE_STALE = "pose_stale"  # newest pose older than pose_timeout_s (or none yet)
    GEOFENCE = "geofence"  # the robot left the geofence (latched until resume())
    MODE_LOST = "mode_lost"  # the vehicle left GUIDED/OFFBOARD or disarmed (latched)
    POSE_JUMP = "pose_jump"  # a position farther than the vehicle can move was rejected (latched)
    CLOSED = "closed"
    LATCHED = frozenset({LINK_LOST, HEARTBEAT_LOST, GEOFENCE, MODE_LOST, POSE_JUMP})


@dataclass(frozen=True)
class DriverHealth:
    """What a driver can say about its robot right now.

    ``link_ok``: messages from the robot arrive in time. ``pose_age_s``: seconds since the newest
    pose (inf before the first). ``failsafe``: a ``FailsafeState`` name ("ok" when none).
    ``paused``: the mission must pause (a latched failsafe holds the robot still until
    ``resume()``). ``reason``: a human-readable sentence for logs and the UI.
    """

    link_ok: bool
    pose_age_s: float
    failsafe: str = FailsafeState.OK
    reason: str = ""
    paused: bool = False
    armed: bool | None = None
    mode: str | None = None
    stamp: float = 0.0

    @property
    def ok(self) -> bool:
        """True when the robot may move: link up, pose fresh, no failsafe."""
        return self.link_ok and self.failsafe == FailsafeState.OK and not self.paused


@runtime_checkable
class Driver(Protocol):
    """What the navigator needs from a robot.

    - ``latest_frame()``: the newest RGB-D ``Frame`` (``Frame.base_pose`` and ``T_world_cam`` in
      the world frame: x east, y north, z up), or None before the first one.
    - ``send(cmd)``: a body-frame ``VelocityCommand`` (v m/s forward, omega rad/s CCW) or a
      ``DiscreteAction``. Drivers clamp to the robot profile's limits and never move the robot
      without an explicit command: no command for a while means standing still.
    - ``health()``: a ``DriverHealth``.
    - ``stop()``: command zero velocity now.
    - ``close()``: stop, then release the link; safe to call twice.
    """

    def latest_frame(self) -> Frame | None: ...

    def send(self, command: VelocityCommand | DiscreteAction) -> None: ...

    def health(self) -> DriverHealth: ...

    def stop(self) -> None: ...

    def close(self) -> None: ...


@runtime_checkable
class FrameSource(Protocol):
    """Where a real-robot driver gets RGB-D frames: a camera, a recording, the sim renderer.

    ``frame_at(pose, stamp)`` returns the frame observed from base ``pose`` (world frame) at
    ``stamp`` (driver clock, seconds), or None when no frame is available.
    """

    def frame_at(self, pose: Pose2D, stamp: float) -> Frame | None: ...


# name -> factory(profile, **options) returning a Driver; filled by the driver modules.
DRIVERS: Registry = Registry("driver")


def discrete_to_segment(action: DiscreteAction, *, forward_step: float, turn_rad: float,
                        max_linear: float, max_angular: float) -> tuple[float, float, float]:
    """A discrete action as a timed velocity segment ``(v m/s, omega rad/s, duration s)``.

    MOVE_FORWARD drives ``forward_step`` metres at ``max_linear``; TURN_LEFT/RIGHT turn
    ``turn_rad`` at ``max_angular`` (left = CCW = positive omega); STOP and the camera actions
    (LOOK_UP/DOWN, which a base without a pan-tilt unit cannot do) are zero-length.
    """
    if action is DiscreteAction.MOVE_FORWARD and max_linear > 0:
        return max_linear, 0.0, forward_step / max_linear
    if action in (DiscreteAction.TURN_LEFT, DiscreteAction.TURN_RIGHT) and max_angular > 0:
        sign = 1.0 if action is DiscreteAction.TURN_LEFT else -1.0
        return 0.0, sign * max_angular, abs(turn_rad) / max_angular
    return 0.0, 0.0, 0.0


def clamp_velocity(cmd: VelocityCommand, max_linear: float, max_angular: float,
                   allow_reverse: bool = False) -> tuple[float, float]:
    """Clamp a command to the profile's limits; NaN/inf components become 0 (never move on junk)."""
    v = cmd.v if math.isfinite(cmd.v) else 0.0
    w = cmd.omega if math.isfinite(cmd.omega) else 0.0
    v = min(max(v, -max_linear if allow_reverse else 0.0), max_linear)
    w = min(max(w, -max_angular), max_angular)
    return v, w
