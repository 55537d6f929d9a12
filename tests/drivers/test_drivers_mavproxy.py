"""The MAVLink link routed through MAVProxy, as a user's ground setup would (vehicle -> MAVProxy
-> driver). Skipped unless the pip package MAVProxy is importable (it is not a dependency; it
pulls opencv-python, which clashes with opencv-python-headless, so install it with
``pip install --no-deps MAVProxy pyserial`` or into a folder on PYTHONPATH)."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import time

import pytest
from driver_helpers import drive_to, free_udp_port, test_profile, wait_until
from hiconav.drivers.base import FailsafeState
from hiconav.drivers.mavlink_driver import MavlinkDriver
from hiconav.drivers.vehicle import SimulatedVehicle, VehicleConfig

pytestmark = pytest.mark.skipif(importlib.util.find_spec("MAVProxy") is None, reason="MAVProxy is not installed")


def test_mission_through_mavproxy(tmp_path):
    master, out = free_udp_port(), free_udp_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "MAVProxy.mavproxy", f"--master=udpin:127.0.0.1:{master}",
         f"--out=udpout:127.0.0.1:{out}", "--daemon", "--non-interactive", f"--state-basedir={tmp_path}"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp_path, env=dict(os.environ))
    vehicle = SimulatedVehicle(f"udpout:127.0.0.1:{master}", VehicleConfig()).start()
    driver = MavlinkDriver(test_profile(mavlink={"heartbeat_wait_s": 20.0, "ack_timeout_s": 2.0}),
                           url=f"udpin:127.0.0.1:{out}", handle_signals=False)
    try:
        driver.connect()
        driver.engage()
        assert driver.mode == "GUIDED" and driver.armed
        assert drive_to(driver, (1.0, 0.5), timeout=10.0)
        # MAVProxy dies: the link is gone -> both sides stop
        proc.terminate()
        proc.wait(timeout=10)
        t_cut = time.monotonic()
        assert wait_until(lambda: driver.health().failsafe == FailsafeState.LINK_LOST, 2.0)
        assert driver.health().paused
        assert time.monotonic() - t_cut < 1.5
    finally:
        driver.close()
        vehicle.close()
        if proc.poll() is None:
            proc.kill()
