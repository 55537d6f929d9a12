"""A simulated MAVLink ground vehicle: the built-in simulator's kinematics behind a real MAVLink
link on 127.0.0.1, so the MAVLink driver can be tested end to end without a robot.

It behaves as a (much simplified) ArduPilot Rover or PX4 rover autopilot:
- sends HEARTBEAT (MAV_TYPE_GROUND_ROVER, autopilot ArduPilot or PX4, mode in custom_mode, armed
  flag in base_mode) at ``heartbeat_hz`` and at once after a mode or arming change, and the pose
  as LOCAL_POSITION_NED + ATTITUDE (optionally ODOMETRY) at ``pose_hz``;
- accepts SET_POSITION_TARGET_LOCAL_NED velocity setpoints (body or local NED frame, velocity and
  yaw-rate type mask) only when armed and in GUIDED (ArduPilot) / OFFBOARD (PX4); PX4 refuses
  OFFBOARD unless setpoints are already streaming, as the real one does;
- answers MAV_CMD_DO_SET_MODE and MAV_CMD_COMPONENT_ARM_DISARM with COMMAND_ACK, and can be told
  to refuse them (``refuse_modes``, ``refuse_arm``) to test how refusals are reported;
- its own failsafe: no setpoint for ``setpoint_timeout_s`` or no GCS heartbeat for
  ``gcs_timeout_s`` -> velocity 0 (PX4 also leaves OFFBOARD for LOITER/hold);
- ignores malformed bytes and messages it does not handle; with ``signing_key`` it signs what it
  sends (MAVLink 2 signing) and refuses unsigned or wrongly signed messages, as an autopilot with
  signing enabled does;
- moves as a unicycle; with a House, a move that would put the robot disk (``robot_radius``) on a
  non-navigable cell of ``house.nav`` is refused (collision), as in the simulator.

The vehicle's local NED origin is the world origin: NED x = world y (north), NED y = world x.
It renders nothing (frames come from the driver's frame source) and must not be used as a
physics simulator: velocities change instantly (a stop is a stop).
"""

from __future__ import annotations

import collections
import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from hiconav.drivers.base import LinkError
from hiconav.drivers.mavlink_driver import DIALECT, enu_to_ned, mavlink, mavutil

from hiconav.types import Pose2D, wrap_angle

__all__ = ["SimulatedVehicle", "VehicleConfig", "VehicleState"]

ROVER_MODES: dict[str, int] = mavutil.mode_mapping_byname(mavlink.MAV_TYPE_GROUND_ROVER)
PX4_HOLD = "LOITER"  # PX4's "Hold" is AUTO_LOITER


@dataclass
class VehicleConfig:
    autopilot: str = "ardupilot"  # "ardupilot" | "px4"
    system_id: int = 1
    component_id: int = 1
    start: Pose2D = field(default_factory=lambda: Pose2D(0.0, 0.0, 0.0))
    loop_hz: float = 100.0
    pose_hz: float = 25.0
    heartbeat_hz: float = 1.0
    send_odometry: bool = False
    setpoint_timeout_s: float = 0.4
    gcs_timeout_s: float = 3.0
    max_linear: float = 1.0
    max_angular: float = 2.0
    robot_radius: float = 0.18
    armed: bool = False
    refuse_modes: frozenset[str] = frozenset()  # mode names this autopilot will refuse
    refuse_arm: bool = False
    px4_requires_stream: bool = True  # PX4: OFFBOARD only with a live setpoint stream
    px4_offboard_loss_hold: bool = True  # PX4: setpoint loss -> leave OFFBOARD for hold
    signing_key: bytes | None = None  # MAVLink 2 signing (32 bytes): sign out, refuse unsigned in

    def __post_init__(self) -> None:
        if self.autopilot not in ("ardupilot", "px4"):
            raise ValueError(f"autopilot must be 'ardupilot' or 'px4', got {self.autopilot!r}")
        if self.signing_key is not None and len(self.signing_key) != 32:
            raise ValueError(f"signing_key must be 32 bytes, got {len(self.signing_key)}")

    @property
    def guided_mode(self) -> str:
        return "OFFBOARD" if self.autopilot == "px4" else "GUIDED"

    @property
    def initial_mode(self) -> str:
        return PX4_HOLD if self.autopilot == "px4" else "HOLD"


@dataclass
class VehicleState:
    """A consistent copy of the vehicle's state (world ENU pose; v m/s forward, omega rad/s CCW)."""

    pose: Pose2D
    v: float
    omega: float
    mode: str
    armed: bool
    collided: bool
    last_setpoint: float | None
    last_gcs_heartbeat: float | None
    stopped_at: float | None  # when a failsafe last zeroed a non-zero velocity
    stop_reason: str
    last_command: tuple[float, float]  # (v, omega) of the last accepted setpoint
    counters: dict[str, int]


class SimulatedVehicle:
    """The vehicle, running in its own thread once ``start()``-ed (see the module docstring).

    ``url``: where to talk, as pymavlink takes it (``udpout:127.0.0.1:14550`` sends to a GCS
    listening there; ``udpin:127.0.0.1:14560`` waits for one). ``house``: a hiconav.sim House
    (collisions on ``house.nav``) or None for free space.
    """

    def __init__(self, url: str, config: VehicleConfig | None = None, house: Any = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.url = url
        self.config = config or VehicleConfig()
        self.house = house
        self._clock = clock
        self._lock = threading.RLock()
        self._stop_event = threading.Event()
        self._thread: threading.Thread | None = None
        self._conn: Any = None
        c = self.config
        self._pose = c.start
        self._v = 0.0
        self._omega = 0.0
        self._mode = c.initial_mode
        self._armed = c.armed
        self._collided = False
        self._last_setpoint: float | None = None
        self._last_gcs: float | None = None
        self._stopped_at: float | None = None
        self._stop_reason = ""
        self._hb_due = True
        self._last_cmd = (0.0, 0.0)
        self.send_pose = True  # tests: False silences the pose stream (heartbeats go on)
        self.counters: collections.Counter[str] = collections.Counter()
        self._t0 = clock()
        self._free_mask: np.ndarray | None = None  # (H, W) bool robot-centre cells
        if house is not None:
            self._check_start()

    # ------------------------------------------------------------------ lifecycle
    def start(self) -> SimulatedVehicle:
        try:
            self._conn = mavutil.mavlink_connection(self.url, source_system=self.config.system_id,
                                                    source_component=self.config.component_id,
                                                    dialect=DIALECT)
        except (OSError, ValueError) as exc:
            raise LinkError(f"vehicle cannot open {self.url!r}: {exc}", field="listen") from exc
        if self.config.signing_key is not None:
            self._conn.setup_signing(self.config.signing_key, sign_outgoing=True, allow_unsigned_callback=None)
        self._stop_event.clear()
        self._thread = threading.Thread(target=self._loop, name="sim-vehicle", daemon=True)
        self._thread.start()
        return self

    def close(self) -> None:
        self._stop_event.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None
        if self._conn is not None:
            try:
                self._conn.close()
            except OSError:
                pass
            self._conn = None

    def __enter__(self) -> SimulatedVehicle:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def run_forever(self, report: Callable[[VehicleState], None] | None = None,
                    report_period_s: float = 1.0) -> None:
        """Start (if needed) and block until KeyboardInterrupt, calling ``report`` periodically."""
        if self._thread is None:
            self.start()
        try:
            while not self._stop_event.wait(report_period_s):
                if report is not None:
                    report(self.state())
        except KeyboardInterrupt:
            pass
        finally:
            self.close()

    # ------------------------------------------------------------------ state
    def state(self) -> VehicleState:
        with self._lock:
            return VehicleState(self._pose, self._v, self._omega, self._mode, self._armed, self._collided,
                                self._last_setpoint, self._last_gcs, self._stopped_at, self._stop_reason,
                                self._last_cmd, dict(self.counters))

    def set_pose(self, pose: Pose2D) -> None:
        """Teleport (tests: e.g. put the robot outside a geofence)."""
        with self._lock:
            self._pose = pose

    @property
    def clock(self) -> Callable[[], float]:
        return self._clock

    # ------------------------------------------------------------------ collision (hiconav.sim NavGrid)
    def _check_start(self) -> None:
        if not self._free(self._pose.x, self._pose.y):
            raise ValueError(f"vehicle start ({self._pose.x:.2f}, {self._pose.y:.2f}) is not navigable "
                             f"for radius {self.config.robot_radius} m in house {getattr(self.house, 'name', '?')}")

    def _free(self, x: float, y: float) -> bool:
        """The simulator's rule (``Simulator.is_free``): the robot disk centred at (x, y) fits,
        i.e. the cell's clearance (``hiconav.sim.geodesic.clearance``) >= robot_radius."""
        if self.house is None:
            return True
        if self._free_mask is None:
            from hiconav.sim.geodesic import clearance

            self._free_mask = clearance(self.house.nav) >= self.config.robot_radius - 1e-9
        rc = self.house.nav.world_to_cell(np.array([x, y], dtype=np.float64))
        h, w = self._free_mask.shape
        return bool(0 <= rc[0] < h and 0 <= rc[1] < w and self._free_mask[rc[0], rc[1]])

    # ------------------------------------------------------------------ main loop
    def _loop(self) -> None:
        c = self.config
        period = 1.0 / c.loop_hz
        last = self._clock()
        next_pose = next_hb = last
        while not self._stop_event.is_set():
            now = self._clock()
            self._drain(now)
            dt = min(now - last, 0.1)
            last = now
            with self._lock:
                self._failsafe(now)
                self._integrate(dt)
                hb_due = self._hb_due or now >= next_hb
                self._hb_due = False
            if hb_due:
                self._send_heartbeat()
                if now >= next_hb:
                    next_hb = now + 1.0 / c.heartbeat_hz
            if now >= next_pose:
                if self.send_pose:
                    self._send_pose(now)
                next_pose = max(next_pose + 1.0 / c.pose_hz, now)
            self._stop_event.wait(max(0.0, period - (self._clock() - now)))

    def _drain(self, now: float) -> None:
        for _ in range(500):
            try:
                msg = self._conn.recv_msg()
            except Exception:  # noqa: BLE001 - malformed input never stops the vehicle
                self.counters["rx_errors"] += 1
                continue
            if msg is None:
                return
            try:
                self._handle(msg, now)
            except Exception:  # noqa: BLE001 - e.g. a field out of range in a valid-CRC packet
                self.counters["handle_errors"] += 1

    def _failsafe(self, now: float) -> None:
        c = self.config
        reason = ""
        if self._v != 0.0 or self._omega != 0.0:
            if self._last_setpoint is None or now - self._last_setpoint > c.setpoint_timeout_s:
                reason = f"no setpoint for {c.setpoint_timeout_s} s"
            elif self._last_gcs is None or now - self._last_gcs > c.gcs_timeout_s:
                reason = f"no GCS heartbeat for {c.gcs_timeout_s} s"
            if reason:
                self._v = self._omega = 0.0
                self._stopped_at = now
                self._stop_reason = reason
                self.counters["failsafe_stops"] += 1
                if c.autopilot == "px4" and c.px4_offboard_loss_hold and self._mode == "OFFBOARD":
                    self._mode = PX4_HOLD
                    self._hb_due = True
        if not self._armed or self._mode != c.guided_mode:
            self._v = self._omega = 0.0

    def _integrate(self, dt: float) -> None:
        if dt <= 0.0 or (self._v == 0.0 and self._omega == 0.0):
            return
        p = self._pose
        steps = max(1, int(math.ceil(abs(self._v) * dt / 0.02)))  # <= 2 cm per sub-step
        h = dt / steps
        x, y, yaw = p.x, p.y, p.yaw
        collided = False
        for _ in range(steps):
            nx = x + self._v * h * math.cos(yaw)
            ny = y + self._v * h * math.sin(yaw)
            if self._v != 0.0 and not self._free(nx, ny):
                collided = True
            else:
                x, y = nx, ny
            yaw = wrap_angle(yaw + self._omega * h)
        self._pose = Pose2D(x, y, yaw)
        self._collided = collided
        if collided:
            self.counters["collisions"] += 1

    # ------------------------------------------------------------------ incoming
    def _handle(self, msg: Any, now: float) -> None:
        kind = msg.get_type()
        if kind == "BAD_DATA":
            if "signature" in str(getattr(msg, "reason", "")):
                self.counters["bad_signature"] += 1
            else:
                self.counters["bad_data"] += 1
            return
        if msg.get_msgId() < 0:  # a well-framed message of an id this dialect does not know
            self.counters["unknown"] += 1
            return
        if kind == "HEARTBEAT":
            if msg.type == mavlink.MAV_TYPE_GCS:
                with self._lock:
                    self._last_gcs = now
            return
        if kind == "SET_POSITION_TARGET_LOCAL_NED":
            if msg.target_system not in (0, self.config.system_id):
                return
            self._on_setpoint(msg, now)
        elif kind == "COMMAND_LONG":
            if msg.target_system not in (0, self.config.system_id):
                return
            self._on_command(msg, now)
        elif kind == "SET_MODE":
            if msg.target_system == self.config.system_id:
                self._try_mode(self._decode_mode(float(msg.base_mode), float(msg.custom_mode & 0xFFFF), 0.0,
                                                 raw=msg.custom_mode), now)
        else:
            self.counters["ignored"] += 1

    def _on_setpoint(self, msg: Any, now: float) -> None:
        c = self.config
        mask = msg.type_mask
        pos_ignored = (mavlink.POSITION_TARGET_TYPEMASK_X_IGNORE | mavlink.POSITION_TARGET_TYPEMASK_Y_IGNORE
                       | mavlink.POSITION_TARGET_TYPEMASK_Z_IGNORE)
        with self._lock:
            if not self._armed or self._mode != c.guided_mode:
                self.counters["setpoints_rejected"] += 1
                # PX4 needs the stream before OFFBOARD is allowed: remember that it is alive
                self._last_setpoint = now
                return
            if mask & pos_ignored != pos_ignored:
                self.counters["setpoints_unsupported"] += 1  # position targets: not this vehicle
                return
            vx = 0.0 if mask & mavlink.POSITION_TARGET_TYPEMASK_VX_IGNORE else float(msg.vx)
            vy = 0.0 if mask & mavlink.POSITION_TARGET_TYPEMASK_VY_IGNORE else float(msg.vy)
            rate = 0.0 if mask & mavlink.POSITION_TARGET_TYPEMASK_YAW_RATE_IGNORE else float(msg.yaw_rate)
            if not all(math.isfinite(v) for v in (vx, vy, rate)):
                self.counters["setpoints_invalid"] += 1
                return
            frame = msg.coordinate_frame
            if frame in (mavlink.MAV_FRAME_BODY_NED, mavlink.MAV_FRAME_BODY_OFFSET_NED, mavlink.MAV_FRAME_BODY_FRD):
                forward = vx  # a rover cannot strafe: vy is dropped
            elif frame in (mavlink.MAV_FRAME_LOCAL_NED, mavlink.MAV_FRAME_LOCAL_OFFSET_NED):
                _, _, yaw_ned = enu_to_ned(self._pose)
                forward = vx * math.cos(yaw_ned) + vy * math.sin(yaw_ned)
            else:
                self.counters["setpoints_unsupported"] += 1
                return
            self._v = min(max(forward, -c.max_linear), c.max_linear)
            self._omega = min(max(-rate, -c.max_angular), c.max_angular)  # NED yaw rate is clockwise
            self._last_setpoint = now
            self._last_cmd = (self._v, self._omega)
            self.counters["setpoints"] += 1

    def _ack(self, command: int, result: int, text: str = "") -> None:
        if text:
            self._conn.mav.statustext_send(mavlink.MAV_SEVERITY_WARNING if result else mavlink.MAV_SEVERITY_INFO,
                                           text.encode()[:50])
        self._conn.mav.command_ack_send(command, result)

    def _on_command(self, msg: Any, now: float) -> None:
        cmd = msg.command
        if cmd == mavlink.MAV_CMD_DO_SET_MODE:
            name = self._decode_mode(msg.param1, msg.param2, msg.param3)
            self._ack(cmd, *self._try_mode(name, now))
        elif cmd == mavlink.MAV_CMD_COMPONENT_ARM_DISARM:
            arm = msg.param1 >= 0.5
            with self._lock:
                if arm and self.config.refuse_arm:
                    result, text = mavlink.MAV_RESULT_FAILED, "PreArm: refused by vehicle config"
                else:
                    self._armed = arm
                    if not arm:
                        self._v = self._omega = 0.0
                    self._hb_due = True
                    result, text = mavlink.MAV_RESULT_ACCEPTED, "Armed" if arm else "Disarmed"
            self._ack(cmd, result, text)
        else:
            self.counters["commands_unsupported"] += 1
            self._ack(cmd, mavlink.MAV_RESULT_UNSUPPORTED)

    def _decode_mode(self, base: float, custom: float, sub: float, raw: int | None = None) -> str | None:
        if self.config.autopilot == "px4":
            if raw is not None:
                custom_mode = int(raw)
            else:
                custom_mode = (int(custom) << 16) | (int(sub) << 24)
            name = mavutil.interpret_px4_mode(int(base), custom_mode)
            return None if name == "UNKNOWN" else name
        if not int(base) & mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            return None
        return mavutil.mode_mapping_rover.get(int(custom))

    def _try_mode(self, name: str | None, now: float) -> tuple[int, str]:
        c = self.config
        with self._lock:
            if name is None:
                return mavlink.MAV_RESULT_DENIED, "Mode change denied: unknown mode"
            if name in c.refuse_modes:
                return mavlink.MAV_RESULT_DENIED, f"Mode change to {name} denied by vehicle config"
            if (c.autopilot == "px4" and name == "OFFBOARD" and c.px4_requires_stream
                    and (self._last_setpoint is None or now - self._last_setpoint > 0.5)):
                return mavlink.MAV_RESULT_DENIED, "Offboard: no setpoint stream"
            self._mode = name
            self._v = self._omega = 0.0
            self._hb_due = True
            return mavlink.MAV_RESULT_ACCEPTED, f"Mode {name}"

    # ------------------------------------------------------------------ outgoing
    def _send_heartbeat(self) -> None:
        c = self.config
        with self._lock:
            mode, armed = self._mode, self._armed
        base = mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        if armed:
            base |= mavlink.MAV_MODE_FLAG_SAFETY_ARMED
        if c.autopilot == "px4":
            flags, main, sub = mavutil.px4_map[mode]
            base |= flags
            custom = (main << 16) | (sub << 24)
            autopilot = mavlink.MAV_AUTOPILOT_PX4
        else:
            custom = ROVER_MODES[mode]
            if mode == "GUIDED":
                base |= mavlink.MAV_MODE_FLAG_GUIDED_ENABLED
            autopilot = mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA
        status = mavlink.MAV_STATE_ACTIVE if armed else mavlink.MAV_STATE_STANDBY
        try:
            self._conn.mav.heartbeat_send(mavlink.MAV_TYPE_GROUND_ROVER, autopilot, base, custom, status)
        except OSError:
            self.counters["send_errors"] += 1

    def _send_pose(self, now: float) -> None:
        with self._lock:
            pose, v, omega = self._pose, self._v, self._omega
        north, east, yaw_ned = enu_to_ned(pose)
        v_north, v_east = v * math.sin(pose.yaw), v * math.cos(pose.yaw)
        ms = int((now - self._t0) * 1000) & 0xFFFFFFFF
        try:
            mav = self._conn.mav
            mav.local_position_ned_send(ms, north, east, 0.0, v_north, v_east, 0.0)
            mav.attitude_send(ms, 0.0, 0.0, yaw_ned, 0.0, 0.0, -omega)
            if self.config.send_odometry:
                half = yaw_ned / 2.0
                nan21 = [float("nan")] * 21
                mav.odometry_send(ms * 1000, mavlink.MAV_FRAME_LOCAL_NED, mavlink.MAV_FRAME_BODY_FRD,
                                  north, east, 0.0, [math.cos(half), 0.0, 0.0, math.sin(half)],
                                  v, 0.0, 0.0, 0.0, 0.0, -omega, nan21, nan21)
        except OSError:
            self.counters["send_errors"] += 1
