"""``hiconav vehicle``: the command runs the simulated vehicle that a driver can connect to."""

from __future__ import annotations

import signal
import subprocess
import time
import sys

from driver_helpers import free_udp_port, test_profile, wait_until
from hiconav.drivers.mavlink_driver import MavlinkDriver

from hiconav.types import VelocityCommand

RUN = "import typer; from hiconav.drivers.cli import vehicle; typer.run(vehicle)"


def test_vehicle_command_serves_a_px4_vehicle():
    port = free_udp_port()
    proc = subprocess.Popen([sys.executable, "-c", RUN, "--listen", f"udpout:127.0.0.1:{port}",
                             "--autopilot", "px4", "--start", "1,2,0", "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    driver = MavlinkDriver(test_profile(mavlink={"autopilot": "px4", "heartbeat_wait_s": 15.0}),
                           url=f"udpin:127.0.0.1:{port}", handle_signals=False)
    try:
        driver.connect()
        assert wait_until(lambda: driver.pose is not None, 2.0)
        assert driver.pose.distance_to(type(driver.pose)(1.0, 2.0, 0.0)) < 1e-3
        driver.engage()
        assert driver.mode == "OFFBOARD"
        deadline = time.monotonic() + 5.0  # the vehicle is another process: allow for a loaded machine
        while time.monotonic() < deadline:
            driver.send(VelocityCommand(0.5, 0.0))
            if driver.pose.x > 1.05:
                break
            wait_until(lambda: False, 0.05)
        assert driver.pose.x > 1.05
    finally:
        driver.close()
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=10)
    assert proc.returncode == 0, err
    assert "vehicle (px4, system 1)" in out


def test_vehicle_command_rejects_bad_start():
    proc = subprocess.run([sys.executable, "-c", RUN, "--start", "1,2"], capture_output=True, text=True, timeout=60,
                          check=False)
    assert proc.returncode != 0 and "--start must be x,y,yaw" in proc.stderr
