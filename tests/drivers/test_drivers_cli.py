"""``hiconav vehicle``: the command runs the simulated vehicle that a driver can connect to.

The vehicle is another process: every wait is on readiness (its start-up line, its heartbeat, its
pose) with generous limits for a loaded machine, and the failsafes on both sides are given long
timeouts, since link health under load is not what these tests check.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time

from driver_helpers import READY_S, LineReader, free_udp_port, test_profile, wait_until
from hiconav.drivers.mavlink_driver import MavlinkDriver

from hiconav.types import VelocityCommand

RUN = "import typer; from hiconav.drivers.cli import vehicle; typer.run(vehicle)"
PATIENT = {"link_timeout_s": 30.0, "heartbeat_timeout_s": 30.0, "pose_timeout_s": 30.0, "command_timeout_s": 5.0}
KEY_HEX = "3c" * 32


def start_vehicle(*args: str) -> tuple[subprocess.Popen, LineReader, LineReader]:
    proc = subprocess.Popen([sys.executable, "-u", "-c", RUN, *args, "--setpoint-timeout", "60",
                             "--gcs-timeout", "60"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return proc, LineReader(proc.stdout), LineReader(proc.stderr)


def stop_vehicle(proc: subprocess.Popen, out: LineReader, err: LineReader) -> tuple[str, str]:
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=READY_S)
    finally:
        if proc.poll() is None:
            proc.kill()
    return out.text(), err.text()


def drive_east(driver: MavlinkDriver, beyond_x: float) -> bool:
    deadline = time.monotonic() + READY_S
    while time.monotonic() < deadline:
        driver.send(VelocityCommand(0.5, 0.0))
        if driver.pose.x > beyond_x:
            return True
        wait_until(lambda: False, 0.05)
    return False


def test_vehicle_command_serves_a_px4_vehicle():
    port = free_udp_port()
    proc, out, err = start_vehicle("--listen", f"udpout:127.0.0.1:{port}", "--autopilot", "px4",
                                   "--start", "1,2,0", "--quiet")
    driver = MavlinkDriver(test_profile(mavlink={"autopilot": "px4", "heartbeat_wait_s": READY_S,
                                                 "ack_timeout_s": 10.0}, failsafe=PATIENT),
                           url=f"udpin:127.0.0.1:{port}", handle_signals=False)
    try:
        assert out.wait_for("vehicle (px4, system 1)"), err.text()
        driver.connect()
        assert wait_until(lambda: driver.pose is not None, READY_S)
        assert driver.pose.distance_to(type(driver.pose)(1.0, 2.0, 0.0)) < 1e-3
        driver.engage()
        assert driver.mode == "OFFBOARD"
        assert drive_east(driver, 1.05)
    finally:
        driver.close()
        stdout, stderr = stop_vehicle(proc, out, err)
    assert proc.returncode == 0, stderr
    assert "vehicle (px4, system 1)" in stdout


def test_vehicle_command_signs_its_link_with_a_key_file(tmp_path):
    key_file = tmp_path / "vehicle.key"
    key_file.write_text(KEY_HEX + "\n")
    port = free_udp_port()
    proc, out, err = start_vehicle("--listen", f"udpout:127.0.0.1:{port}", "--signing-key-file", str(key_file),
                                   "--quiet")
    driver = MavlinkDriver(test_profile(mavlink={"heartbeat_wait_s": READY_S, "ack_timeout_s": 10.0,
                                                 "target_system": 1, "target_component": 1,
                                                 "signing_key": KEY_HEX}, failsafe=PATIENT),
                           url=f"udpin:127.0.0.1:{port}", handle_signals=False)
    try:
        assert out.wait_for("MAVLink 2 signing on"), err.text()
        driver.connect()
        driver.engage()
        assert driver.mode == "GUIDED" and driver.armed
        assert wait_until(lambda: driver.pose is not None, READY_S)
        assert drive_east(driver, 0.05)
        assert driver._conn.mav.signing.goodsig_count > 0 and driver.stats["bad_signature"] == 0
    finally:
        driver.close()
        stdout, stderr = stop_vehicle(proc, out, err)
    assert proc.returncode == 0, stderr


def test_vehicle_command_rejects_bad_start():
    proc = subprocess.run([sys.executable, "-c", RUN, "--start", "1,2"], capture_output=True, text=True,
                          timeout=READY_S, check=False)
    assert proc.returncode != 0 and "--start must be x,y,yaw" in proc.stderr


def test_vehicle_command_rejects_a_bad_signing_key_in_one_line():
    proc = subprocess.run([sys.executable, "-m", "hiconav.cli", "vehicle", "--signing-key", "xyz"],
                          capture_output=True, text=True, timeout=READY_S, check=False)
    assert proc.returncode != 0 and "--signing-key must be 64 hex digits" in proc.stderr
    assert "Traceback" not in proc.stderr
