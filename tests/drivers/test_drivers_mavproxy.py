"""The MAVLink link routed through MAVProxy, as a user's ground setup would (vehicle -> MAVProxy
-> driver). MAVProxy is not a dependency (it pulls opencv-python, which clashes with
opencv-python-headless): ``make setup`` installs it with ``pip install --no-deps MAVProxy
pyserial``. A missing MAVProxy fails this test; it does not skip.

Waits are on readiness (the driver's heartbeat wait covers MAVProxy's start-up), with generous
limits for a loaded machine; nothing here measures time.
"""

from __future__ import annotations

import os
import subprocess
import sys

import MAVProxy  # noqa: F401 - a missing install must fail here, not skip
from driver_helpers import drive_to, free_udp_port, test_profile, wait_until
from hiconav.drivers.base import FailsafeState
from hiconav.drivers.mavlink_driver import MavlinkDriver
from hiconav.drivers.vehicle import SimulatedVehicle, VehicleConfig

READY_S = 120.0  # MAVProxy's start-up (imports) on a loaded 2-core machine


def test_mission_through_mavproxy(tmp_path):
    master, out = free_udp_port(), free_udp_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "MAVProxy.mavproxy", f"--master=udpin:127.0.0.1:{master}",
         f"--out=udpout:127.0.0.1:{out}", "--daemon", "--non-interactive", f"--state-basedir={tmp_path}"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp_path, env=dict(os.environ))
    vehicle = SimulatedVehicle(f"udpout:127.0.0.1:{master}", VehicleConfig()).start()
    # link health is not under test while MAVProxy relays on a busy machine: a long link timeout
    driver = MavlinkDriver(test_profile(mavlink={"heartbeat_wait_s": READY_S, "ack_timeout_s": 10.0},
                                        failsafe={"link_timeout_s": 5.0, "heartbeat_timeout_s": 10.0,
                                                  "pose_timeout_s": 5.0}),
                           url=f"udpin:127.0.0.1:{out}", handle_signals=False)
    try:
        driver.connect()
        driver.engage()
        assert driver.mode == "GUIDED" and driver.armed
        assert drive_to(driver, (1.0, 0.5), timeout=READY_S)
        # MAVProxy dies: the link is gone -> the driver reports it and pauses
        proc.terminate()
        proc.wait(timeout=READY_S)
        assert wait_until(lambda: driver.health().failsafe == FailsafeState.LINK_LOST, READY_S)
        assert driver.health().paused and not driver.health().link_ok
    finally:
        driver.close()
        vehicle.close()
        if proc.poll() is None:
            proc.kill()
