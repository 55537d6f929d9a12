"""Helpers for the driver tests: free localhost UDP ports, a link-cutting UDP relay, a bounded
``wait_until`` poll, a test robot profile and a minimal go-to-goal controller.

All traffic stays on 127.0.0.1; every test picks fresh random ports, so tests may run in parallel
with other projects' tests on the same machine.
"""

from __future__ import annotations

import math
import select
import socket
import threading
import time
from collections.abc import Callable

from hiconav.drivers.profiles import RobotProfile

from hiconav.types import Pose2D, VelocityCommand, wrap_angle


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_until(predicate: Callable[[], bool], timeout: float, period: float = 0.01) -> bool:
    """Poll ``predicate`` until true or ``timeout`` s pass (bounded); returns the last value."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(period)
    return bool(predicate())


READY_S = 120.0  # how long a subprocess may take to get ready on a loaded 2-core machine


class LineReader:
    """Reads a subprocess's text stream on a thread, so a test can wait for a readiness line with
    a deadline (a blocking ``readline`` has none). ``lines`` keeps everything read."""

    def __init__(self, stream) -> None:
        self.lines: list[str] = []
        self._new = threading.Condition()
        self._thread = threading.Thread(target=self._run, args=(stream,), daemon=True)
        self._thread.start()

    def _run(self, stream) -> None:
        for line in stream:
            with self._new:
                self.lines.append(line.rstrip("\n"))
                self._new.notify_all()

    def wait_for(self, text: str, timeout: float = READY_S) -> bool:
        """True once a line containing ``text`` has been read, False after ``timeout`` s or EOF."""
        deadline = time.monotonic() + timeout
        with self._new:
            while not any(text in line for line in self.lines):
                left = deadline - time.monotonic()
                if left <= 0 or not self._thread.is_alive():
                    return any(text in line for line in self.lines)
                self._new.wait(min(left, 0.5))
            return True

    def text(self) -> str:
        self._thread.join(timeout=READY_S)
        return "\n".join(self.lines)


def test_profile(**sections: dict) -> RobotProfile:
    """A MAVLink profile for tests: fast limits, short waits."""
    data: dict = {"name": "test", "driver": "mavlink",
                  "limits": {"max_linear": 1.0, "max_angular": 2.0},
                  "mavlink": {"heartbeat_wait_s": 3.0, "ack_timeout_s": 1.0, "retries": 1}}
    for key, value in sections.items():
        data.setdefault(key, {}).update(value)
    return RobotProfile.model_validate(data)


test_profile.__test__ = False  # not a test


def drive_to(driver, goal_xy: tuple[float, float], *, tolerance: float = 0.15, timeout: float = 10.0,
             v_max: float = 0.8) -> bool:
    """A minimal go-to-goal controller through the Driver protocol (stands in for the navigator)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        pose: Pose2D | None = driver.pose
        if pose is None or not driver.health().ok:
            time.sleep(0.02)
            continue
        dx, dy = goal_xy[0] - pose.x, goal_xy[1] - pose.y
        dist = math.hypot(dx, dy)
        if dist < tolerance:
            driver.stop()
            return True
        err = wrap_angle(math.atan2(dy, dx) - pose.yaw)
        v = min(v_max, 1.5 * dist) * max(0.0, math.cos(err)) if abs(err) < 0.6 else 0.0
        driver.send(VelocityCommand(v, max(-2.0, min(2.0, 3.0 * err))))
        time.sleep(0.03)
    driver.stop()
    return False


class UdpRelay:
    """A UDP relay between a vehicle (udpout -> ``port``) and a driver (udpin on
    ``driver_port``) that can cut the link both ways, like a radio going out of range."""

    def __init__(self, driver_port: int) -> None:
        self.driver_addr = ("127.0.0.1", driver_port)
        self.vehicle_side = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.vehicle_side.bind(("127.0.0.1", 0))
        self.port = self.vehicle_side.getsockname()[1]
        self.driver_side = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.driver_side.bind(("127.0.0.1", 0))
        self.vehicle_addr: tuple[str, int] | None = None
        self.cut_at: float | None = None
        self._cut = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def cut(self) -> float:
        self.cut_at = time.monotonic()
        self._cut.set()
        return self.cut_at

    def restore(self) -> None:
        self._cut.clear()

    def _run(self) -> None:
        socks = [self.vehicle_side, self.driver_side]
        while not self._stop.is_set():
            ready, _, _ = select.select(socks, [], [], 0.02)
            for s in ready:
                try:
                    data, addr = s.recvfrom(65535)
                except OSError:
                    continue
                if self._cut.is_set():
                    continue
                try:
                    if s is self.vehicle_side:
                        self.vehicle_addr = addr
                        self.driver_side.sendto(data, self.driver_addr)
                    elif self.vehicle_addr is not None:
                        self.vehicle_side.sendto(data, self.vehicle_addr)
                except OSError:
                    pass

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=1.0)
        self.vehicle_side.close()
        self.driver_side.close()


