"""Failsafe logic for real-robot drivers: link and heartbeat loss, stale pose, geofence, mode loss,
and a zero setpoint on Ctrl-C / exit.

``FailsafeMonitor`` is pure and clock-free: the driver passes the times it measured (and the
newest position it rejected as a jump beyond what the vehicle can move), and gets back the state
and the velocity it may send. It never commands motion of its own; the only output it
can produce is "less motion" (zero, or a clamped forward speed). A latched failsafe (link,
heartbeat, geofence, mode, pose jump) holds the robot still and pauses the mission until ``resume()`` finds
every condition healthy again. ``install_stop_handlers`` is the one piece with side effects: it
hooks SIGINT/SIGTERM and atexit so that a zero setpoint goes out before the process ends.
"""

from __future__ import annotations

import atexit
import math
import signal
import threading
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from hiconav.drivers.base import FailsafeState as _FS
from hiconav.drivers.profiles import FailsafeProfile, GeofenceProfile

from hiconav.types import Pose2D

__all__ = ["FailsafeMonitor", "FailsafeStatus", "Geofence", "install_stop_handlers"]


class Geofence:
    """An allowed region of the world (x east, y north, metres): a box or a simple polygon.

    ``margin`` (m) shrinks the region: a point closer than ``margin`` to the boundary is outside.
    """

    def __init__(self, polygon: np.ndarray, margin: float = 0.0) -> None:
        poly = np.asarray(polygon, dtype=np.float64)
        if poly.ndim != 2 or poly.shape[0] < 3 or poly.shape[1] != 2:
            raise ValueError(f"geofence polygon must be (N>=3, 2), got {poly.shape}")
        self.polygon = poly
        self.margin = float(margin)

    @staticmethod
    def box(xy_min: tuple[float, float], xy_max: tuple[float, float], margin: float = 0.0) -> Geofence:
        (x0, y0), (x1, y1) = xy_min, xy_max
        return Geofence(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), margin)

    @staticmethod
    def from_profile(profile: GeofenceProfile) -> Geofence | None:
        if profile.kind == "box":
            return Geofence.box(profile.xy_min, profile.xy_max, profile.margin)  # type: ignore[arg-type]
        if profile.kind == "polygon":
            return Geofence(np.array(profile.polygon), profile.margin)
        return None

    def contains(self, x: float, y: float) -> bool:
        """True when (x, y) is inside the polygon and at least ``margin`` from its edges."""
        if not (math.isfinite(x) and math.isfinite(y)):
            return False
        p = self.polygon
        q = np.roll(p, -1, axis=0)
        # even-odd ray casting along +x
        crosses = (p[:, 1] > y) != (q[:, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_at = p[:, 0] + (y - p[:, 1]) * (q[:, 0] - p[:, 0]) / (q[:, 1] - p[:, 1])
        inside = bool(np.count_nonzero(crosses & (x < x_at)) % 2)
        if not inside or self.margin <= 0.0:
            return inside
        return self.distance_to_boundary(x, y) >= self.margin

    def distance_to_boundary(self, x: float, y: float) -> float:
        p = self.polygon
        d = np.roll(p, -1, axis=0) - p
        t = np.clip(((x - p[:, 0]) * d[:, 0] + (y - p[:, 1]) * d[:, 1]) / np.maximum((d**2).sum(1), 1e-12), 0, 1)
        closest = p + t[:, None] * d
        return float(np.min(np.hypot(closest[:, 0] - x, closest[:, 1] - y)))


@dataclass(frozen=True)
class FailsafeStatus:
    state: str
    reason: str
    paused: bool
    link_ok: bool
    pose_age_s: float

    @property
    def ok(self) -> bool:
        return self.state == _FS.OK and not self.paused


class FailsafeMonitor:
    """Decides, from measured times and the pose, whether the robot may move.

    Times are seconds on one monotonic clock chosen by the driver. ``last_message``: newest
    message of any kind from the vehicle; ``last_heartbeat``: newest HEARTBEAT; ``pose_stamp``:
    when the newest pose arrived (None before the first). ``engaged``: None before the driver
    engaged (mode + arm), else whether the vehicle is still in the guided mode and armed.
    """

    def __init__(self, config: FailsafeProfile | None = None, geofence: Geofence | None = None) -> None:
        self.config = config or FailsafeProfile()
        self.geofence = geofence
        self._latched: tuple[str, str] | None = None

    @property
    def latched(self) -> tuple[str, str] | None:
        return self._latched

    def _conditions(self, now: float, last_message: float | None, last_heartbeat: float | None,
                    pose_stamp: float | None, pose: Pose2D | None, engaged: bool | None,
                    pose_jump: tuple[float, str] | None = None) -> list[tuple[str, str]]:
        c = self.config
        found: list[tuple[str, str]] = []
        if last_message is None or now - last_message > c.link_timeout_s:
            age = "never" if last_message is None else f"{now - last_message:.2f} s ago"
            found.append((_FS.LINK_LOST, f"no message from the vehicle (last {age}; "
                                         f"limit {c.link_timeout_s} s)"))
        if last_heartbeat is None or now - last_heartbeat > c.heartbeat_timeout_s:
            age = "never" if last_heartbeat is None else f"{now - last_heartbeat:.2f} s ago"
            found.append((_FS.HEARTBEAT_LOST, f"no HEARTBEAT (last {age}; limit {c.heartbeat_timeout_s} s)"))
        if engaged is False:
            found.append((_FS.MODE_LOST, "the vehicle left the guided mode or disarmed"))
        if pose_jump is not None and now - pose_jump[0] <= c.pose_timeout_s:
            found.append((_FS.POSE_JUMP, pose_jump[1]))
        if pose is not None and self.geofence is not None and not self.geofence.contains(pose.x, pose.y):
            found.append((_FS.GEOFENCE, f"robot at ({pose.x:.2f}, {pose.y:.2f}) is outside the geofence"))
        if pose_stamp is None or now - pose_stamp > c.pose_timeout_s:
            age = "none yet" if pose_stamp is None else f"{now - pose_stamp:.2f} s old"
            found.append((_FS.POSE_STALE, f"pose is stale ({age}; limit {c.pose_timeout_s} s)"))
        return found

    def evaluate(self, now: float, *, last_message: float | None, last_heartbeat: float | None,
                 pose_stamp: float | None, pose: Pose2D | None, engaged: bool | None,
                 pose_jump: tuple[float, str] | None = None) -> FailsafeStatus:
        found = self._conditions(now, last_message, last_heartbeat, pose_stamp, pose, engaged, pose_jump)
        link_ok = not any(s == _FS.LINK_LOST for s, _ in found)
        pose_age = math.inf if pose_stamp is None else max(0.0, now - pose_stamp)
        if self._latched is None:
            for state, reason in found:
                # never heard the vehicle (or its heartbeat) yet: not a loss (connect() is still
                # waiting), no latch
                recoverable = (state == _FS.LINK_LOST and last_message is None) or (
                    state == _FS.HEARTBEAT_LOST and last_heartbeat is None) or (
                    state == _FS.LINK_LOST and self.config.resume_on_link_recovery)
                if state in _FS.LATCHED and not recoverable:
                    self._latched = (state, reason)
                    break
        if self._latched is not None:
            return FailsafeStatus(self._latched[0], self._latched[1], True, link_ok, pose_age)
        if found:
            state, reason = found[0]
            return FailsafeStatus(state, reason, False, link_ok, pose_age)
        return FailsafeStatus(_FS.OK, "", False, link_ok, pose_age)

    def resume(self, now: float, *, last_message: float | None, last_heartbeat: float | None,
               pose_stamp: float | None, pose: Pose2D | None, engaged: bool | None,
               pose_jump: tuple[float, str] | None = None) -> tuple[bool, str]:
        """Clear a latched failsafe if every condition is healthy now; returns (ok, why not)."""
        found = self._conditions(now, last_message, last_heartbeat, pose_stamp, pose, engaged, pose_jump)
        if found:
            return False, found[0][1]
        self._latched = None
        return True, ""

    def next_deadline(self, now: float, *, last_message: float | None, last_heartbeat: float | None,
                      pose_stamp: float | None) -> float | None:
        """The earliest time after ``now`` at which a timeout (link, heartbeat, pose) expires if
        nothing more arrives, or None. The driver's sender wakes then, so that the zero setpoint
        of a lost link goes out at ``link_timeout_s`` and not up to one setpoint period later."""
        c = self.config
        times = [t + limit for t, limit in ((last_message, c.link_timeout_s),
                                            (last_heartbeat, c.heartbeat_timeout_s),
                                            (pose_stamp, c.pose_timeout_s)) if t is not None]
        future = [t for t in times if t > now]
        return min(future) if future else None

    def gate(self, status: FailsafeStatus, pose: Pose2D | None, v: float, omega: float) -> tuple[float, float, str]:
        """The velocity that may be sent: zero unless ``status.ok``; forward motion is cut when it
        would leave the geofence within ``geofence_lookahead_s`` (turning on the spot stays allowed)."""
        if not status.ok or pose is None:
            return 0.0, 0.0, status.reason or "no pose"
        if self.geofence is not None and v != 0.0 and self.config.geofence_lookahead_s > 0:
            reach = v * self.config.geofence_lookahead_s
            x = pose.x + reach * math.cos(pose.yaw)
            y = pose.y + reach * math.sin(pose.yaw)
            if not self.geofence.contains(x, y):
                return 0.0, omega, "motion toward the geofence boundary refused"
        return v, omega, ""


def install_stop_handlers(stop: Callable[[], None]) -> Callable[[], None]:
    """Call ``stop()`` (send a zero setpoint) on SIGINT, SIGTERM and interpreter exit.

    The previous signal handlers run afterwards (so Ctrl-C still raises KeyboardInterrupt).
    Signal handlers can only be installed from the main thread; elsewhere only atexit is used.
    Returns a function that removes the hooks again.
    """
    done = threading.Event()

    def run_once() -> None:
        if not done.is_set():
            done.set()
            try:
                stop()
            except Exception:  # noqa: BLE001 - exiting anyway; never mask the original signal
                pass

    atexit.register(run_once)
    previous: dict[int, object] = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            prev = signal.getsignal(sig)
            previous[sig] = prev

            def handler(signum: int, frame: object, _prev: object = prev) -> None:
                run_once()
                if callable(_prev):
                    _prev(signum, frame)  # type: ignore[operator]
                elif _prev == signal.SIG_DFL:
                    if signum == signal.SIGINT:
                        raise KeyboardInterrupt
                    raise SystemExit(128 + signum)

            signal.signal(sig, handler)

    def uninstall() -> None:
        atexit.unregister(run_once)
        if threading.current_thread() is threading.main_thread():
            for sig, prev in previous.items():
                signal.signal(sig, prev)  # type: ignore[arg-type]

    return uninstall
