"""The MAVLink driver: drives an ArduPilot or PX4 ground vehicle (or the simulated one in
``vehicle.py``) through pymavlink, MAVLink 2.

What it does:
- connects by URL (``udpin:HOST:PORT``, ``udpout:HOST:PORT``, ``tcp:HOST:PORT``, a serial device
  such as ``/dev/ttyACM0`` with ``baud``), waits for the vehicle's HEARTBEAT (clear error on
  timeout), and sends its own GCS HEARTBEAT at ``rates.heartbeat_hz`` (1 Hz);
- reads the pose from LOCAL_POSITION_NED + ATTITUDE, or ODOMETRY, and converts NED to our ENU
  world (x east = NED y, y north = NED x, yaw_enu = pi/2 - yaw_ned);
- streams SET_POSITION_TARGET_LOCAL_NED in MAV_FRAME_BODY_NED with a velocity + yaw-rate type
  mask at ``rates.setpoint_hz`` (>= 10 Hz) from a sender thread; the yaw rate is negated
  because NED's z points down (CCW omega > 0 is a negative NED yaw rate);
- switches mode (ArduPilot GUIDED by custom mode number, PX4 OFFBOARD by main/sub custom mode)
  and arms, waiting for COMMAND_ACK and the HEARTBEAT that confirms it; refusals raise
  ``CommandRefused`` with the MAV_RESULT name and the vehicle's last STATUSTEXT;
- applies the failsafes of ``failsafe.FailsafeMonitor`` on every setpoint tick (and wakes at
  the moment a timeout expires): link loss (0.4 s by default, so the first zero setpoint goes out
  within 0.5 s) and heartbeat loss pause the mission and send zero; a stale pose stops motion; a
  geofence breach stops and latches; motion that would leave the fence is cut.

Whom it trusts:
- one vehicle: the system AND component id of ``mavlink.target_system`` / ``target_component``,
  or (``target_system: 0``) the first vehicle heard, locked from then on with a logged warning;
  messages from any other system or component are counted and dropped;
- positions the vehicle can physically reach: one farther from the last accepted position than
  ``failsafe.max_speed`` (default ``limits.max_linear``) x elapsed + ``pose_jump_margin_m`` is
  rejected and latches the POSE_JUMP failsafe (zero setpoint, mission paused);
- with ``mavlink.signing_key`` (or ``signing_key_file``): MAVLink 2 signing via pymavlink's
  ``setup_signing``; everything we send is signed and unsigned or wrongly signed messages are
  refused (a wrong key means no link: ``connect()`` reports the rejected messages).

What it must not do: move on its own. The robot only moves while the navigator keeps sending
commands (each command lasts ``failsafe.command_timeout_s``), so a failed or silent VLM leaves
the robot standing. RGB-D frames come from a separate ``FrameSource``.
"""

from __future__ import annotations

import collections
import logging
import math
import os
import threading
import time
from collections.abc import Callable
from typing import Any

# MAVLink 2 and the ArduPilot dialect (a superset of common) before pymavlink is imported.
os.environ["MAVLINK20"] = "1"
os.environ.setdefault("MAVLINK_DIALECT", "ardupilotmega")

from hiconav.drivers.base import (
    DRIVERS,
    CommandRefused,
    DriverError,
    DriverHealth,
    FailsafeState,
    FrameSource,
    LinkError,
    clamp_velocity,
    discrete_to_segment,
)
from hiconav.drivers.failsafe import FailsafeMonitor, Geofence, install_stop_handlers
from hiconav.drivers.profiles import RobotProfile
from pymavlink import mavutil

from hiconav.types import DiscreteAction, Frame, Pose2D, VelocityCommand, wrap_angle

__all__ = [
    "VELOCITY_YAWRATE_MASK",
    "MavlinkDriver",
    "enu_to_ned",
    "mavlink",
    "ned_to_enu",
    "quaternion_to_yaw",
]

_log = logging.getLogger("hiconav.drivers.mavlink")

DIALECT = "ardupilotmega"
PX4_STREAM_S = 0.5  # s of setpoint streaming before asking PX4 for OFFBOARD
mavutil.set_dialect(DIALECT)
mavlink: Any = mavutil.mavlink

# POSITION_TARGET_TYPEMASK: ignore position (x, y, z), acceleration (ax, ay, az) and yaw; use
# velocity (vx, vy, vz) and yaw rate.
VELOCITY_YAWRATE_MASK = (
    mavlink.POSITION_TARGET_TYPEMASK_X_IGNORE | mavlink.POSITION_TARGET_TYPEMASK_Y_IGNORE
    | mavlink.POSITION_TARGET_TYPEMASK_Z_IGNORE | mavlink.POSITION_TARGET_TYPEMASK_AX_IGNORE
    | mavlink.POSITION_TARGET_TYPEMASK_AY_IGNORE | mavlink.POSITION_TARGET_TYPEMASK_AZ_IGNORE
    | mavlink.POSITION_TARGET_TYPEMASK_YAW_IGNORE
)


def ned_to_enu(north: float, east: float, yaw_ned: float) -> Pose2D:
    """NED (x north, y east, yaw clockwise from north) -> ENU Pose2D (x east, y north, yaw CCW from east)."""
    return Pose2D(float(east), float(north), wrap_angle(math.pi / 2.0 - yaw_ned))


def enu_to_ned(pose: Pose2D) -> tuple[float, float, float]:
    """ENU Pose2D -> (north, east, yaw_ned)."""
    return pose.y, pose.x, wrap_angle(math.pi / 2.0 - pose.yaw)


def quaternion_to_yaw(q: Any) -> float:
    """Yaw (rad, about the frame's z) of a (w, x, y, z) quaternion, as MAVLink orders it."""
    w, x, y, z = (float(v) for v in q)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def result_name(result: int) -> str:
    entry = mavlink.enums["MAV_RESULT"].get(result)
    return entry.name if entry is not None else f"MAV_RESULT({result})"


def command_name(command: int) -> str:
    entry = mavlink.enums["MAV_CMD"].get(command)
    return entry.name if entry is not None else f"MAV_CMD({command})"


class MavlinkDriver:
    """A ``Driver`` for a MAVLink ground vehicle (see the module docstring).

    Typical use::

        with MavlinkDriver(load_profile("ardupilot_rover"), frame_source=src) as robot:
            robot.engage()                        # GUIDED/OFFBOARD + arm, refusals raise
            robot.send(VelocityCommand(0.3, 0.0))  # repeat at >= 2 Hz to keep moving
            frame = robot.latest_frame()

    ``url`` overrides ``profile.mavlink.url``. ``clock`` is the monotonic clock used for every
    age and timeout. ``handle_signals`` installs SIGINT/SIGTERM/atexit hooks that send a zero
    setpoint before the process ends (on by default when connecting from the main thread).
    """

    def __init__(self, profile: RobotProfile | None = None, *, url: str | None = None,
                 frame_source: FrameSource | None = None, clock: Callable[[], float] = time.monotonic,
                 handle_signals: bool = True) -> None:
        self.profile = profile or RobotProfile(name="mavlink-default", driver="mavlink")
        self.url = url or self.profile.mavlink.url
        self.frame_source = frame_source
        self._clock = clock
        self._handle_signals = handle_signals
        self.monitor = FailsafeMonitor(self.profile.failsafe, Geofence.from_profile(self.profile.geofence))
        self._conn: Any = None
        self._lock = threading.RLock()
        self._send_lock = threading.RLock()  # re-entrant: the SIGINT handler may send mid-send
        self._changed = threading.Condition(self._lock)
        self._stop_event = threading.Event()
        self._threads: list[threading.Thread] = []
        self._uninstall: Callable[[], None] | None = None
        self._t0 = clock()
        self._closed = False
        # vehicle state (guarded by _lock). The vehicle is one system AND component: the
        # profile's, or the first vehicle heard (locked then, with a warning)
        cfg = self.profile.mavlink
        self.target_system: int | None = cfg.target_system or None
        self.target_component: int = cfg.target_component
        self._component_locked = cfg.target_system != 0 and cfg.target_component != 0
        self._secret_key: bytes | None = cfg.secret_key()  # ConfigError on a bad key, before any I/O
        lim = self.profile.limits
        self._max_speed = self.profile.failsafe.max_speed or lim.max_linear
        self._pos_ref: tuple[float, float, float] | None = None  # last accepted north, east, stamp
        self._pose_jump: tuple[float, str] | None = None  # when and why a position was rejected
        self._last_message: float | None = None
        self._last_heartbeat: float | None = None
        self._heartbeat: Any = None
        self._mode: str | None = None
        self._armed: bool | None = None
        self._pos_ned: tuple[float, float, float] | None = None  # north, east, stamp
        self._yaw_ned: tuple[float, float] | None = None  # yaw, stamp
        self._pose: Pose2D | None = None
        self._pose_stamp: float | None = None
        self._acks: dict[int, tuple[int, float]] = {}
        self._statustext: collections.deque[str] = collections.deque(maxlen=20)
        # commands (guarded by _lock): (v, omega, valid until)
        self._setpoint: tuple[float, float, float] = (0.0, 0.0, -math.inf)
        self._engaged = False
        self._last_sent: tuple[float, float] = (0.0, 0.0)
        self._stream_since: float | None = None
        self._gate_reason = ""
        self.last_refusal: CommandRefused | None = None
        self.stats: collections.Counter[str] = collections.Counter()

    # ------------------------------------------------------------------ lifecycle
    def connect(self) -> MavlinkDriver:
        """Open the link, start the receiver and sender threads, wait for the vehicle heartbeat."""
        if self._conn is not None:
            return self
        cfg = self.profile.mavlink
        try:
            self._conn = mavutil.mavlink_connection(
                self.url, baud=cfg.baud, source_system=cfg.source_system,
                source_component=cfg.source_component, dialect=DIALECT, autoreconnect=True)
        except (OSError, ValueError) as exc:
            raise LinkError(f"cannot open MAVLink connection {self.url!r}: {exc}", field="mavlink.url") from exc
        if self._secret_key is not None:
            # sign all we send; refuse unsigned and wrongly signed messages (no unsigned callback)
            self._conn.setup_signing(self._secret_key, sign_outgoing=True, allow_unsigned_callback=None,
                                     link_id=cfg.signing_link_id)
        self._stop_event.clear()
        for name, target in (("mavlink-rx", self._rx_loop), ("mavlink-tx", self._tx_loop)):
            thread = threading.Thread(target=target, name=name, daemon=True)
            thread.start()
            self._threads.append(thread)
        if self._handle_signals:
            self._uninstall = install_stop_handlers(self.stop)
        deadline = self._clock() + cfg.heartbeat_wait_s
        with self._changed:
            while self._last_heartbeat is None:
                left = deadline - self._clock()
                if left <= 0:
                    break
                self._changed.wait(min(left, 0.1))
        if self._last_heartbeat is None:
            self.close()
            refused = self.stats["bad_signature"]
            if refused:
                raise LinkError(
                    f"no vehicle HEARTBEAT on {self.url!r} within {cfg.heartbeat_wait_s} s: {refused} "
                    "messages were refused for a missing or wrong MAVLink 2 signature. Does the vehicle "
                    "sign with the same key as mavlink.signing_key / signing_key_file?",
                    field="mavlink.signing_key")
            heard = self.stats["other_system"] + self.stats["other_component"]
            raise LinkError(
                f"no vehicle HEARTBEAT on {self.url!r} within {cfg.heartbeat_wait_s} s: is the vehicle "
                "(or `hiconav vehicle`) running and sending to this address? With udpin the vehicle "
                "must send to this port; with udpout it must listen on it."
                + (f" ({heard} messages came from other systems or components than "
                   f"target_system {self.target_system} / target_component {self.target_component})"
                   if heard else ""), field="mavlink.url")
        return self

    def engage(self) -> None:
        """Switch to the guided mode (GUIDED / OFFBOARD) and arm if the profile says so.

        PX4 accepts OFFBOARD only while setpoints stream (> 2 Hz): the sender thread streams zero
        setpoints from connect(); here we wait until it has done so for ``PX4_STREAM_S``.
        """
        with self._lock:
            px4 = self._heartbeat is not None and self._heartbeat.autopilot == mavlink.MAV_AUTOPILOT_PX4
        if px4:
            deadline = self._clock() + 2.0
            while self._clock() < deadline and (
                    self._stream_since is None or self._clock() - self._stream_since < PX4_STREAM_S):
                time.sleep(0.02)
        self.set_mode(self.profile.mavlink.guided_mode)
        if self.profile.mavlink.arm:
            self.arm()
        with self._lock:
            self._engaged = True

    def close(self) -> None:
        """Send zero setpoints, stop the threads and close the link (idempotent)."""
        if self._closed:
            return
        self._closed = True
        try:
            if self._conn is not None:
                for _ in range(3):
                    self._send_velocity(0.0, 0.0)
        finally:
            self._stop_event.set()
            for thread in self._threads:
                if thread is not threading.current_thread():
                    thread.join(timeout=2.0)
            if self._conn is not None:
                try:
                    self._conn.close()
                except OSError:
                    pass
            if self._uninstall is not None:
                self._uninstall()
                self._uninstall = None

    def __enter__(self) -> MavlinkDriver:
        return self.connect()

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ Driver protocol
    def latest_frame(self) -> Frame | None:
        """The frame from ``frame_source`` at the newest pose (None without pose or source)."""
        with self._lock:
            pose, stamp = self._pose, self._pose_stamp
        if pose is None or stamp is None or self.frame_source is None:
            return None
        return self.frame_source.frame_at(pose, stamp)

    def send(self, command: VelocityCommand | DiscreteAction) -> None:
        """Set the velocity the sender thread streams; it lapses after command_timeout_s.

        A ``DiscreteAction`` becomes a timed segment (forward_step at max_linear, turn_deg at
        max_angular); LOOK_UP/LOOK_DOWN and STOP command zero.
        """
        now = self._clock()
        lim = self.profile.limits
        if isinstance(command, DiscreteAction):
            v, w, duration = discrete_to_segment(
                command, forward_step=self.profile.discrete.forward_step,
                turn_rad=math.radians(self.profile.discrete.turn_deg),
                max_linear=lim.max_linear, max_angular=lim.max_angular)
            until = now + duration
        elif isinstance(command, VelocityCommand):
            v, w = clamp_velocity(command, lim.max_linear, lim.max_angular, lim.allow_reverse)
            until = now + self.profile.failsafe.command_timeout_s
        else:
            raise DriverError(f"cannot send {type(command).__name__}; expected VelocityCommand or DiscreteAction")
        with self._lock:
            self._setpoint = (v, w, until)

    def stop(self) -> None:
        """Zero velocity now (also sent immediately, not only on the next tick)."""
        with self._lock:
            self._setpoint = (0.0, 0.0, -math.inf)
        if self._conn is not None and not self._closed:
            self._send_velocity(0.0, 0.0)

    def health(self) -> DriverHealth:
        now = self._clock()
        status = self._evaluate(now)
        with self._lock:
            reason = status.reason or self._gate_reason
            return DriverHealth(link_ok=status.link_ok, pose_age_s=status.pose_age_s,
                                failsafe=FailsafeState.CLOSED if self._closed else status.state,
                                reason=reason, paused=status.paused or self._closed,
                                armed=self._armed, mode=self._mode, stamp=now)

    # ------------------------------------------------------------------ extra API
    @property
    def pose(self) -> Pose2D | None:
        with self._lock:
            return self._pose

    @property
    def pose_stamp(self) -> float | None:
        """Driver-clock time (s) at which the newest pose arrived (None before the first)."""
        with self._lock:
            return self._pose_stamp

    @property
    def mode(self) -> str | None:
        with self._lock:
            return self._mode

    @property
    def armed(self) -> bool | None:
        with self._lock:
            return self._armed

    @property
    def last_sent(self) -> tuple[float, float]:
        """The (v, omega) of the last setpoint sent, ENU body convention (omega CCW)."""
        with self._lock:
            return self._last_sent

    def statustexts(self) -> list[str]:
        with self._lock:
            return list(self._statustext)

    def resume(self) -> None:
        """Clear a latched failsafe once every condition is healthy (re-engaging if the vehicle
        left the guided mode); raises ``DriverError`` saying why not otherwise."""
        with self._lock:
            engaged_wanted = self._engaged
            mode_ok = self._mode == self.profile.mavlink.guided_mode
            arm_ok = bool(self._armed) or not self.profile.mavlink.arm
        if engaged_wanted and not (mode_ok and arm_ok):
            self.engage()
        now = self._clock()
        with self._lock:
            ok, why = self.monitor.resume(now, **self._inputs())
            self._setpoint = (0.0, 0.0, -math.inf)
        if not ok:
            raise DriverError(f"cannot resume: {why}")

    def set_mode(self, mode: str) -> None:
        """Request ``mode`` (e.g. GUIDED, OFFBOARD, HOLD) and wait for the ACK and the heartbeat."""
        with self._lock:
            hb = self._heartbeat
        if hb is None:
            raise LinkError("no vehicle heartbeat yet; connect() first")
        if hb.autopilot == mavlink.MAV_AUTOPILOT_PX4:
            if mode not in mavutil.px4_map:
                raise DriverError(f"unknown PX4 mode {mode!r}; known: {', '.join(sorted(mavutil.px4_map))}",
                                  field="mavlink.mode")
            base, main, sub = mavutil.px4_map[mode]
            params = (float(base), float(main), float(sub))
        else:
            mapping = mavutil.mode_mapping_byname(hb.type) or mavutil.mode_mapping_byname(
                mavlink.MAV_TYPE_GROUND_ROVER)
            if mode not in mapping:
                raise DriverError(f"unknown ArduPilot mode {mode!r} for vehicle type {hb.type}; "
                                  f"known: {', '.join(sorted(mapping))}", field="mavlink.mode")
            params = (float(mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED), float(mapping[mode]), 0.0)
        self._command(mavlink.MAV_CMD_DO_SET_MODE, *params)
        self._wait_state(lambda: self._mode == mode, f"the vehicle to report mode {mode}")

    def arm(self) -> None:
        """Arm (MAV_CMD_COMPONENT_ARM_DISARM 1), wait for the ACK and the armed flag in HEARTBEAT."""
        self._command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1.0)
        self._wait_state(lambda: bool(self._armed), "the vehicle to report armed")

    def disarm(self) -> None:
        self.stop()
        self._command(mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 0.0)
        with self._lock:
            self._engaged = False
        self._wait_state(lambda: self._armed is False, "the vehicle to report disarmed")

    # ------------------------------------------------------------------ internals
    def _inputs(self) -> dict[str, Any]:
        engaged: bool | None = None
        if self._engaged:
            engaged = self._mode == self.profile.mavlink.guided_mode and (
                bool(self._armed) or not self.profile.mavlink.arm)
        return {"last_message": self._last_message, "last_heartbeat": self._last_heartbeat,
                "pose_stamp": self._pose_stamp, "pose": self._pose, "engaged": engaged,
                "pose_jump": self._pose_jump}

    def _evaluate(self, now: float):  # -> FailsafeStatus
        with self._lock:
            status = self.monitor.evaluate(now, **self._inputs())
            if status.paused:
                self._setpoint = (0.0, 0.0, -math.inf)
            return status

    def _command(self, command: int, *params: float) -> None:
        """COMMAND_LONG with retries; returns on MAV_RESULT_ACCEPTED, raises otherwise."""
        cfg = self.profile.mavlink
        p = list(params) + [0.0] * (7 - len(params))
        for attempt in range(cfg.retries + 1):
            sent_at = self._clock()
            with self._lock:
                self._acks.pop(command, None)
                n_text = len(self._statustext)
                target = self.target_system or 0
            if not self._send(self._conn.mav.command_long_send,
                              target, self.target_component, command, attempt, *p):
                continue  # counted in stats["send_errors"]; the next attempt sends again
            deadline = sent_at + cfg.ack_timeout_s
            with self._changed:
                while command not in self._acks and self._clock() < deadline:
                    self._changed.wait(min(0.05, max(deadline - self._clock(), 0.0)))
                ack = self._acks.get(command)
                texts = list(self._statustext)[n_text:] if len(self._statustext) >= n_text else []
            if ack is None:
                continue
            result = ack[0]
            if result == mavlink.MAV_RESULT_IN_PROGRESS:
                continue
            if result == mavlink.MAV_RESULT_ACCEPTED:
                return
            text = texts[-1] if texts else (self._statustext[-1] if self._statustext else "")
            refusal = CommandRefused(
                f"vehicle refused {command_name(command)} ({', '.join(f'{x:g}' for x in params)}): "
                f"{result_name(result)}" + (f"; vehicle says: {text}" if text else ""),
                command=command_name(command), result=result_name(result), statustext=text)
            self.last_refusal = refusal
            raise refusal
        raise LinkError(f"no COMMAND_ACK for {command_name(command)} after {cfg.retries + 1} tries "
                        f"({cfg.ack_timeout_s} s each)", field="mavlink.ack_timeout_s")

    def _wait_state(self, predicate: Callable[[], bool], what: str) -> None:
        # confirmation arrives with the next HEARTBEAT (1 Hz on real autopilots)
        timeout = max(self.profile.mavlink.ack_timeout_s, 2.5)
        deadline = self._clock() + timeout
        with self._changed:
            while not predicate():
                left = deadline - self._clock()
                if left <= 0:
                    raise DriverError(f"command accepted, but timed out after {timeout} s waiting for {what}")
                self._changed.wait(min(left, 0.05))

    def _send_velocity(self, v: float, omega: float) -> None:
        """One SET_POSITION_TARGET_LOCAL_NED, body frame: vx forward, yaw rate = -omega (NED z down)."""
        if self.target_system is None or self._conn is None:
            return
        ms = int((self._clock() - self._t0) * 1000) & 0xFFFFFFFF
        if not self._send(self._conn.mav.set_position_target_local_ned_send,
                          ms, self.target_system, self.target_component, mavlink.MAV_FRAME_BODY_NED,
                          VELOCITY_YAWRATE_MASK, 0.0, 0.0, 0.0, float(v), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                          -float(omega)):
            return
        with self._lock:
            self._last_sent = (float(v), float(omega))
            if self._stream_since is None:
                self._stream_since = self._clock()
        self.stats["setpoints"] += 1

    def _send_heartbeat(self) -> None:
        """Our GCS heartbeat (MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID)."""
        self._send(self._conn.mav.heartbeat_send, mavlink.MAV_TYPE_GCS, mavlink.MAV_AUTOPILOT_INVALID,
                   0, 0, mavlink.MAV_STATE_ACTIVE)

    def _send(self, send: Callable[..., Any], *args: Any) -> bool:
        """Send one message; False (counted in ``stats["send_errors"]``) if the send failed.

        Any exception counts, not only socket errors: pymavlink's ``udpin`` write iterates the
        set of peers that the receiver thread grows (``RuntimeError: Set changed size during
        iteration``), and a full buffer or a closed port raises ``OSError``. A failed send is a
        lost message, like one the link drops: the caller goes on, and a stream that stays
        silent stops the robot through the vehicle's own setpoint timeout.
        """
        try:
            with self._send_lock:
                send(*args)
        except Exception as exc:  # noqa: BLE001 - see above: a send must never end a sender loop
            self.stats["send_errors"] += 1
            if self.stats["send_errors"] == 1 or self.stats["send_errors"] % 100 == 0:
                _log.warning("MAVLink send failed (%d so far): %s: %s",
                            self.stats["send_errors"], type(exc).__name__, exc)
            return False
        return True

    def _tx_loop(self) -> None:
        self._next_tick = self._next_hb = self._clock()
        period = 1.0 / self.profile.rates.setpoint_hz
        while not self._stop_event.is_set():
            try:
                wake = self._tick(self._clock())
            except Exception:  # noqa: BLE001 - the sender must outlive any one tick's failure
                self.stats["tx_errors"] += 1
                _log.exception("MAVLink sender tick failed (%d so far); the loop goes on",
                              self.stats["tx_errors"])
                wake = self._clock() + period
            self._stop_event.wait(max(0.0, wake - self._clock()))

    _next_tick: float | None = None
    _next_hb: float | None = None

    def _tick(self, now: float) -> float:
        """One sender step at ``now``: GCS heartbeat when due, failsafe check, one setpoint.

        Returns when to run the next: the next setpoint tick (1 / setpoint_hz), or earlier, just
        after a link / heartbeat / pose timeout would expire, so that a lost link's first zero
        setpoint goes out link_timeout_s after the last message, not up to a period later.
        """
        if self._next_tick is None or self._next_hb is None:
            self._next_tick = self._next_hb = now
        period = 1.0 / self.profile.rates.setpoint_hz
        if now >= self._next_hb:
            self._send_heartbeat()
            self._next_hb += 1.0 / self.profile.rates.heartbeat_hz
            if self._next_hb < now:
                self._next_hb = now + 1.0 / self.profile.rates.heartbeat_hz
        status = self._evaluate(now)
        with self._lock:
            v, w, until = self._setpoint
            if now > until:
                v = w = 0.0
            v, w, why = self.monitor.gate(status, self._pose, v, w)
            self._gate_reason = why
            deadline = self.monitor.next_deadline(now, last_message=self._last_message,
                                                  last_heartbeat=self._last_heartbeat,
                                                  pose_stamp=self._pose_stamp)
        self._send_velocity(v, w)
        if now >= self._next_tick:
            self._next_tick += period
            later = self._clock()
            if self._next_tick < later:  # overran (a loaded machine): do not burst to catch up
                self._next_tick = later + period
        wake = self._next_tick
        if deadline is not None and deadline + 1e-3 < wake:
            wake = deadline + 1e-3  # just past it: the timeout compares with ">"
        return wake

    def _rx_loop(self) -> None:
        conn = self._conn
        while not self._stop_event.is_set():
            try:
                msg = conn.recv_match(blocking=True, timeout=0.05)
            except Exception:  # noqa: BLE001 - a parse or socket error must not kill the receiver
                self.stats["rx_errors"] += 1
                if self._stop_event.wait(0.01):
                    return
                continue
            if msg is not None:
                try:
                    self._handle(msg)
                except Exception:  # noqa: BLE001 - malformed field values: count and go on
                    self.stats["handle_errors"] += 1

    def _handle(self, msg: Any) -> None:
        kind = msg.get_type()
        if kind == "BAD_DATA":
            if "signature" in str(getattr(msg, "reason", "")):
                self.stats["bad_signature"] += 1  # unsigned, or signed with another key
            else:
                self.stats["bad_data"] += 1
            return
        if msg.get_msgId() < 0:  # framed, but an id this dialect does not know
            self.stats["unknown"] += 1
            return
        src, comp = msg.get_srcSystem(), msg.get_srcComponent()
        now = self._clock()
        with self._changed:
            if self.target_system is None or not self._component_locked:
                if not (kind == "HEARTBEAT" and self._conn.probably_vehicle_heartbeat(msg)
                        and self.target_system in (None, src)):
                    if self.target_system is not None and src != self.target_system:
                        self.stats["other_system"] += 1
                    return
                self._lock_vehicle(src, comp)
            if src != self.target_system:
                self.stats["other_system"] += 1
                return
            if comp != self.target_component:
                self.stats["other_component"] += 1
                return
            if kind == "HEARTBEAT":
                if msg.type == mavlink.MAV_TYPE_GCS or not self._conn.probably_vehicle_heartbeat(msg):
                    return
                self._last_message = now
                first = self._last_heartbeat is None
                self._last_heartbeat = now
                self._heartbeat = msg
                if first:
                    # answer at once: on udpin our first heartbeats went nowhere (no peer yet),
                    # and an autopilot stops guided motion while it hears no GCS
                    self._send_heartbeat()
                self._mode = mavutil.mode_string_v10(msg)
                self._armed = bool(msg.base_mode & mavlink.MAV_MODE_FLAG_SAFETY_ARMED)
            elif kind == "LOCAL_POSITION_NED":
                self._last_message = now
                if self._accept_position(msg.x, msg.y, now):
                    self._pos_ned = (msg.x, msg.y, now)
                    self._update_pose(now)
            elif kind == "ATTITUDE":
                self._last_message = now
                self._yaw_ned = (msg.yaw, now)
                self._update_pose(now)
            elif kind == "ODOMETRY":
                self._last_message = now
                if (msg.frame_id in (mavlink.MAV_FRAME_LOCAL_NED, mavlink.MAV_FRAME_LOCAL_FRD)
                        and self._accept_position(msg.x, msg.y, now)):
                    self._pos_ned = (msg.x, msg.y, now)
                    self._yaw_ned = (quaternion_to_yaw(msg.q), now)
                    self._update_pose(now)
            elif kind == "COMMAND_ACK":
                self._last_message = now
                self._acks[msg.command] = (msg.result, now)
            elif kind == "STATUSTEXT":
                self._last_message = now
                self._statustext.append(str(msg.text))
            else:
                self._last_message = now
                self.stats["ignored"] += 1
                return
            self._changed.notify_all()

    def _lock_vehicle(self, system: int, component: int) -> None:
        """Take the first vehicle heard as the vehicle (the profile did not name it); warn."""
        what = ("the robot profile names no vehicle (mavlink.target_system 0)" if self.target_system is None
                else f"the robot profile names system {system} but no component (target_component 0)")
        self.target_system = system
        self.target_component = component
        self._component_locked = True
        _log.warning(
            "MAVLink: %s, so the driver locked to the first vehicle heard on %s: system %d, component "
            "%d. A peer heard first would have been obeyed as the vehicle; set mavlink.target_system "
            "and mavlink.target_component in the profile to refuse every other.", what, self.url,
            system, component)

    def _accept_position(self, north: float, east: float, now: float) -> bool:
        """Whether a reported position is physically possible: finite, and within max_speed x
        elapsed + pose_jump_margin_m of the last accepted one (driver clock). A rejected one
        latches the POSE_JUMP failsafe; the pose keeps its last accepted value."""
        if not (math.isfinite(north) and math.isfinite(east)):
            self.stats["bad_pose"] += 1
            return False
        ref = self._pos_ref
        if ref is not None:
            dist = math.hypot(north - ref[0], east - ref[1])
            elapsed = max(0.0, now - ref[2])
            margin = self.profile.failsafe.pose_jump_margin_m
            allowed = self._max_speed * elapsed + margin
            if dist > allowed:
                self.stats["pose_jumps"] += 1
                self._pose_jump = (now, (
                    f"a reported position {dist:.2f} m from the last one {elapsed:.3f} s earlier was "
                    f"rejected: at most {allowed:.2f} m is possible (max_speed {self._max_speed:g} m/s "
                    f"x elapsed + margin {margin:g} m); spoofed or broken odometry?"))
                return False
        self._pos_ref = (float(north), float(east), now)
        return True

    def _update_pose(self, now: float) -> None:
        if self._pos_ned is None or self._yaw_ned is None:
            return
        north, east, t_pos = self._pos_ned
        yaw, t_yaw = self._yaw_ned
        if not math.isfinite(yaw):
            self.stats["bad_pose"] += 1
            return
        self._pose = ned_to_enu(north, east, yaw)
        self._pose_stamp = min(t_pos, t_yaw)


def _make_mavlink(profile: RobotProfile, **options: Any) -> MavlinkDriver:
    """Registry factory: ``MavlinkDriver(profile, **options).connect()``; engage unless engage=False.

    Without ``frame_source=`` the profile's ``frames`` section picks one (sim renderer, recorded
    folder, OpenCV device, or none).
    """
    engage = options.pop("engage", True)
    if options.get("frame_source") is None:
        from hiconav.drivers.frame_sources import make_frame_source

        options["frame_source"] = make_frame_source(profile, house=options.pop("house", None))
    driver = MavlinkDriver(profile, **options).connect()
    if engage:
        try:
            driver.engage()
        except Exception:
            driver.close()
            raise
    return driver


DRIVERS.add("mavlink", _make_mavlink)
