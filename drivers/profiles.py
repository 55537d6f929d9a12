"""Robot profiles: the YAML description of one robot (camera, limits, footprint, rates, failsafes,
geofence, MAVLink link), validated with pydantic on load.

A profile is data about a robot; this module computes nothing about motion and opens no link.
Errors name the file, the line and the dotted field (``ConfigError``), e.g.
``config/robots/rover.yaml:12 [limits.max_linear]: Input should be greater than 0``.
Profiles ship in ``config/robots/*.yaml`` (package ``hiconav.config``) and are loaded by name
(``load_profile("px4_rover")``) or by path.
"""

from __future__ import annotations

import math
from importlib import resources
from pathlib import Path
from typing import Any, Literal

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from hiconav import yamlio
from hiconav.errors import ConfigError
from hiconav.limits import MAX_DURATION_S
from hiconav.types import CameraIntrinsics, Pose2D, camera_pose_from_base

__all__ = [
    "CameraExtrinsics",
    "CameraProfile",
    "FailsafeProfile",
    "GeofenceProfile",
    "MavlinkProfile",
    "RobotProfile",
    "available_profiles",
    "load_profile",
    "parse_signing_key",
    "profile_from_dict",
]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class CameraExtrinsics(_Model):
    """Camera mount on the base: offsets in the base frame (m), tilt (deg, up positive), yaw (deg)."""

    height: float = Field(0.88, gt=0.0, description="optical centre above the floor (m)")
    forward: float = 0.0
    left: float = 0.0
    tilt_deg: float = Field(0.0, ge=-90.0, le=90.0)
    yaw_deg: float = Field(0.0, ge=-180.0, le=180.0)


class CameraProfile(_Model):
    """Pinhole intrinsics (either ``hfov_deg`` or all of fx, fy, cx, cy) and the mount."""

    width: int = Field(640, gt=0)
    height: int = Field(480, gt=0)
    hfov_deg: float | None = Field(79.0, gt=0.0, lt=180.0)
    fx: float | None = Field(None, gt=0.0)
    fy: float | None = Field(None, gt=0.0)
    cx: float | None = None
    cy: float | None = None
    min_depth: float = Field(0.1, ge=0.0)
    max_depth: float = Field(5.0, gt=0.0)
    depth_scale: float = Field(0.001, gt=0.0, description="metres per raw depth unit (uint16 sensors)")
    extrinsics: CameraExtrinsics = CameraExtrinsics()

    @model_validator(mode="after")
    def _check(self) -> CameraProfile:
        given = [v is not None for v in (self.fx, self.fy, self.cx, self.cy)]
        if any(given) and not all(given):
            raise ValueError("give all of fx, fy, cx, cy (or none of them and hfov_deg)")
        if not any(given) and self.hfov_deg is None:
            raise ValueError("give hfov_deg or fx, fy, cx, cy")
        if self.max_depth <= self.min_depth:
            raise ValueError(f"max_depth ({self.max_depth}) must exceed min_depth ({self.min_depth})")
        return self

    def intrinsics(self) -> CameraIntrinsics:
        if self.fx is not None:
            return CameraIntrinsics(self.width, self.height, self.fx, self.fy, self.cx, self.cy)  # type: ignore[arg-type]
        return CameraIntrinsics.from_hfov(self.width, self.height, float(self.hfov_deg))  # type: ignore[arg-type]

    def T_world_cam(self, base: Pose2D) -> np.ndarray:
        """(4, 4) float64 camera-to-world transform for base pose ``base`` (world frame)."""
        e = self.extrinsics
        c, s = math.cos(base.yaw), math.sin(base.yaw)
        mount = Pose2D(base.x + c * e.forward - s * e.left, base.y + s * e.forward + c * e.left,
                       base.yaw + math.radians(e.yaw_deg))
        return camera_pose_from_base(mount, e.height, math.radians(e.tilt_deg))


class LimitsProfile(_Model):
    max_linear: float = Field(0.5, gt=0.0, le=20.0, description="m/s")
    max_angular: float = Field(1.0, gt=0.0, le=20.0, description="rad/s")
    allow_reverse: bool = False


class FootprintProfile(_Model):
    radius: float = Field(0.18, gt=0.0, le=5.0, description="m, the robot as a disk")


class RatesProfile(_Model):
    setpoint_hz: float = Field(20.0, ge=10.0, le=200.0, description="MAVLink setpoint stream (>= 10 Hz)")
    heartbeat_hz: float = Field(1.0, gt=0.0, le=50.0, description="our GCS heartbeat")
    frame_hz: float = Field(10.0, gt=0.0, le=120.0)
    control_dt: float = Field(0.1, gt=0.0, le=2.0, description="s a velocity command lasts in the sim")


class DiscreteProfile(_Model):
    forward_step: float = Field(0.25, gt=0.0)
    turn_deg: float = Field(30.0, gt=0.0, le=180.0)


class FailsafeProfile(_Model):
    """Timeouts (s). A latched failsafe (link, heartbeat, geofence, mode) pauses until resume()."""

    # link loss -> first zero setpoint takes link_timeout_s plus at most one setpoint tick (the
    # sender also wakes at the loss deadline itself): 0.4 s + 1/20 s leaves margin below 0.5 s
    link_timeout_s: float = Field(0.4, gt=0.0, le=MAX_DURATION_S, description="no message from the vehicle -> stop, pause")
    heartbeat_timeout_s: float = Field(3.0, gt=0.0, le=MAX_DURATION_S, description="no HEARTBEAT -> stop, pause")
    pose_timeout_s: float = Field(0.5, gt=0.0, le=MAX_DURATION_S, description="pose older than this -> stop")
    command_timeout_s: float = Field(0.5, gt=0.0, le=MAX_DURATION_S, description="no command from the navigator -> zero")
    geofence_lookahead_s: float = Field(1.0, ge=0.0, le=MAX_DURATION_S, description="refuse motion that leaves the fence")
    resume_on_link_recovery: bool = False
    max_speed: float | None = Field(None, gt=0.0, description="m/s the vehicle can move at most (None: "
                                    "limits.max_linear); a position farther than max_speed x elapsed "
                                    "+ pose_jump_margin_m from the last one is rejected")
    pose_jump_margin_m: float = Field(0.5, ge=0.0, description="m allowed beyond max_speed x elapsed")


class GeofenceProfile(_Model):
    """Where the robot may be, world frame (m): a box (xy_min, xy_max) or a polygon (>= 3 points)."""

    kind: Literal["none", "box", "polygon"] = "none"
    xy_min: tuple[float, float] | None = None
    xy_max: tuple[float, float] | None = None
    polygon: list[tuple[float, float]] | None = None
    margin: float = Field(0.0, ge=0.0, description="keep this far inside the boundary (m)")

    @model_validator(mode="after")
    def _check(self) -> GeofenceProfile:
        if self.kind == "box":
            if self.xy_min is None or self.xy_max is None:
                raise ValueError("a box geofence needs xy_min and xy_max")
            if not (self.xy_min[0] < self.xy_max[0] and self.xy_min[1] < self.xy_max[1]):
                raise ValueError(f"xy_min {self.xy_min} must be below xy_max {self.xy_max} in x and y")
        elif self.kind == "polygon":
            if self.polygon is None or len(self.polygon) < 3:
                raise ValueError("a polygon geofence needs at least 3 points [[x, y], ...]")
        return self


class MavlinkProfile(_Model):
    """Link defaults; ``url`` as pymavlink takes it: udpin:HOST:PORT, udpout:, tcp:, /dev/ttyUSB0."""

    url: str = "udpin:127.0.0.1:14550"
    baud: int = Field(57600, gt=0)
    autopilot: Literal["ardupilot", "px4"] = "ardupilot"
    mode: str | None = Field(None, description="GUIDED (ArduPilot) / OFFBOARD (PX4) when null")
    arm: bool = True
    source_system: int = Field(255, ge=1, le=255)
    source_component: int = Field(190, ge=0, le=255)
    target_system: int = Field(0, ge=0, le=255, description="the vehicle's system id; 0 = the first "
                               "vehicle heard (logged as a warning: a peer heard first would be obeyed)")
    target_component: int = Field(1, ge=0, le=255, description="the autopilot's component id (1); "
                                  "0 = the first heard from target_system")
    signing_key: str | None = Field(None, description="MAVLink 2 signing: the 32-byte secret key as 64 hex "
                                    "digits; when set, unsigned or wrongly signed messages are refused")
    signing_key_file: str | None = Field(None, description="a file holding the signing key (64 hex digits)")
    signing_link_id: int = Field(0, ge=0, le=255, description="our MAVLink 2 signing link id")
    heartbeat_wait_s: float = Field(10.0, gt=0.0, le=MAX_DURATION_S)
    ack_timeout_s: float = Field(1.5, gt=0.0, le=MAX_DURATION_S)
    retries: int = Field(2, ge=0, le=10)

    @field_validator("signing_key")
    @classmethod
    def _check_key(cls, value: str | None) -> str | None:
        if value is not None:
            parse_signing_key(value, "signing_key")
        return value

    @model_validator(mode="after")
    def _check_signing(self) -> MavlinkProfile:
        if self.signing_key is not None and self.signing_key_file is not None:
            raise ValueError("give signing_key or signing_key_file, not both")
        return self

    @property
    def guided_mode(self) -> str:
        return self.mode or ("OFFBOARD" if self.autopilot == "px4" else "GUIDED")

    def secret_key(self) -> bytes | None:
        """The 32-byte signing key (from signing_key, or read from signing_key_file), or None.

        Raises ``ConfigError`` naming the field (and the file) when it is not 64 hex digits.
        """
        if self.signing_key is not None:
            return parse_signing_key(self.signing_key, "signing_key")
        if self.signing_key_file is None:
            return None
        path = Path(self.signing_key_file).expanduser()
        try:
            text = path.read_text(encoding="ascii").strip()
        except (OSError, UnicodeDecodeError) as exc:
            raise ConfigError(f"cannot read the MAVLink signing key file: {exc}", file=str(path),
                              field="mavlink.signing_key_file") from None
        try:
            return parse_signing_key(text, "signing_key_file")
        except ValueError as exc:
            raise ConfigError(str(exc), file=str(path), field="mavlink.signing_key_file") from None


def parse_signing_key(text: str, what: str = "signing key") -> bytes:
    """A MAVLink 2 secret key (32 bytes) from 64 hex digits (spaces and a 0x prefix allowed)."""
    digits = "".join(str(text).split())
    if digits[:2].lower() == "0x":
        digits = digits[2:]
    try:
        key = bytes.fromhex(digits)
    except ValueError:
        key = b""
    if len(key) != 32:
        raise ValueError(f"{what} must be 64 hex digits (a 32-byte MAVLink 2 secret key), "
                         f"got {len(digits)} characters")
    return key


class FramesProfile(_Model):
    """Where a real-robot driver gets RGB-D: the sim renderer, a recorded folder, an OpenCV device."""

    source: Literal["none", "sim", "replay", "opencv"] = "none"
    house: str | None = None
    path: str | None = None
    device: int | str | None = None
    depth_device: int | str | None = None

    @model_validator(mode="after")
    def _check(self) -> FramesProfile:
        if self.source == "sim" and not self.house:
            raise ValueError("frames.source 'sim' needs house (e.g. procthor:val/3)")
        if self.source == "replay" and not self.path:
            raise ValueError("frames.source 'replay' needs path (a recorded folder)")
        if self.source == "opencv" and self.device is None:
            raise ValueError("frames.source 'opencv' needs device (index or URL)")
        return self


class RobotProfile(_Model):
    name: str
    description: str = ""
    driver: Literal["sim", "mavlink", "replay"] = "sim"
    camera: CameraProfile = CameraProfile()
    limits: LimitsProfile = LimitsProfile()
    footprint: FootprintProfile = FootprintProfile()
    rates: RatesProfile = RatesProfile()
    discrete: DiscreteProfile = DiscreteProfile()
    failsafe: FailsafeProfile = FailsafeProfile()
    geofence: GeofenceProfile = GeofenceProfile()
    mavlink: MavlinkProfile = MavlinkProfile()
    frames: FramesProfile = FramesProfile()

    def with_updates(self, **sections: dict[str, Any]) -> RobotProfile:
        """A copy with some sections' fields replaced, validated again (``mavlink={"url": ...}``)."""
        data = self.model_dump()
        for key, value in sections.items():
            if isinstance(value, dict) and isinstance(data.get(key), dict):
                data[key].update(value)
            else:
                data[key] = value
        return profile_from_dict(data, source="<override>")


def _robots_dir() -> Path:
    return Path(str(resources.files("hiconav.config") / "robots"))


def available_profiles() -> list[str]:
    """Names of the profiles shipped in config/robots/."""
    folder = _robots_dir()
    return sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []


def _line_of(node: yaml.Node | None, loc: tuple[Any, ...]) -> int | None:
    """1-based line of the YAML node at pydantic location ``loc`` (deepest node that exists)."""
    line = node.start_mark.line + 1 if node is not None else None
    for key in loc:
        if isinstance(node, yaml.MappingNode):
            match = [v for k, v in node.value if getattr(k, "value", None) == str(key)]
            if not match:
                # an unexpected or missing key: point at the key itself or stay on the parent
                keys = [k for k, _ in node.value if getattr(k, "value", None) == str(key)]
                return keys[0].start_mark.line + 1 if keys else line
            node = match[0]
        elif isinstance(node, yaml.SequenceNode) and isinstance(key, int) and key < len(node.value):
            node = node.value[key]
        else:
            break
        line = node.start_mark.line + 1
    return line


def profile_from_dict(data: Any, *, source: str = "<dict>", root: yaml.Node | None = None) -> RobotProfile:
    """Validate a mapping as a ``RobotProfile``; errors name ``source``, line and field."""
    if not isinstance(data, dict):
        raise ConfigError(f"a robot profile must be a mapping, got {type(data).__name__}", file=source)
    try:
        return RobotProfile.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors()
        lines = []
        for err in errors:
            field = ".".join(str(p) for p in err["loc"]) or "(root)"
            line = _line_of(root, tuple(err["loc"]))
            where = f"{source}:{line}" if line else source
            lines.append(f"{where} [{field}]: {err['msg']}")
        first = errors[0]
        field = ".".join(str(p) for p in first["loc"]) or None
        message = first["msg"] if len(lines) == 1 else (
            f"{len(lines)} errors in the robot profile:\n  " + "\n  ".join(lines))
        raise ConfigError(message, file=source, line=_line_of(root, tuple(first["loc"])),
                          field=field) from None


def load_profile(spec: str | Path) -> RobotProfile:
    """Load a robot profile by path (``my_robot.yaml``) or by shipped name (``px4_rover``)."""
    path = Path(spec)
    if not path.is_file():
        candidate = _robots_dir() / f"{spec}.yaml"
        if not candidate.is_file():
            known = ", ".join(available_profiles()) or "(none)"
            raise ConfigError(f"no robot profile {str(spec)!r}: not a file, and not one of {known}",
                              field="profile")
        path = candidate
    data, root = yamlio.load_file(path, what="robot profile")
    if data is None:
        raise ConfigError("the robot profile is empty", file=str(path))
    if isinstance(data, dict) and "name" not in data:
        data = {"name": path.stem, **data}
    return profile_from_dict(data, source=str(path), root=root)
