"""Benchmark of the MAVLink link on 127.0.0.1: setpoint rate, command-to-motion latency, and the
time from a cut link to (a) the vehicle stopping, (b) the driver reporting link loss and (c) the
driver's first zero setpoint (measured from the last message the driver heard).
Prints the figures and ends with one JSON line."""
from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "drivers"))
from driver_helpers import UdpRelay, free_udp_port, test_profile, wait_until  # noqa: E402

from hiconav.drivers.base import FailsafeState  # noqa: E402
from hiconav.drivers.mavlink_driver import MavlinkDriver  # noqa: E402
from hiconav.drivers.vehicle import SimulatedVehicle, VehicleConfig  # noqa: E402
from hiconav.types import VelocityCommand  # noqa: E402


def trial(n_latency: int = 10) -> dict:
    port = free_udp_port()
    relay = UdpRelay(port)
    vehicle = SimulatedVehicle(f"udpout:127.0.0.1:{relay.port}", VehicleConfig()).start()
    driver = MavlinkDriver(test_profile(), url=f"udpin:127.0.0.1:{port}", handle_signals=False).connect()
    driver.engage()
    out: dict = {}
    try:
        n0, t0 = vehicle.state().counters.get("setpoints", 0), time.monotonic()
        time.sleep(2.0)
        out["setpoint_hz"] = (vehicle.state().counters.get("setpoints", 0) - n0) / (time.monotonic() - t0)
        lat = []
        for _ in range(n_latency):
            driver.stop()
            wait_until(lambda: vehicle.state().v == 0.0, 2.0)
            time.sleep(0.1)
            t = time.monotonic()
            driver.send(VelocityCommand(0.5, 0.0))
            wait_until(lambda: vehicle.state().v > 0.0, 2.0, period=0.001)
            lat.append(time.monotonic() - t)
        out["command_to_motion_s"] = lat
        driver.send(VelocityCommand(0.5, 0.0))
        wait_until(lambda: vehicle.state().v > 0.0, 2.0)
        t_cut = relay.cut()
        stop_at = lost_at = zero_at = None
        end = t_cut + 3.0
        while time.monotonic() < end and (stop_at is None or lost_at is None or zero_at is None):
            driver.send(VelocityCommand(0.5, 0.0))
            now = time.monotonic()
            if stop_at is None and vehicle.state().v == 0.0:
                stop_at = now
            if lost_at is None and driver.health().failsafe == FailsafeState.LINK_LOST:
                lost_at = now
            if zero_at is None and driver.last_sent == (0.0, 0.0):
                zero_at = now
            time.sleep(0.002)
        last_heard = driver._last_message  # driver clock = time.monotonic
        out["last_message_to_driver_zero_s"] = None if zero_at is None or last_heard is None else zero_at - last_heard
        out["cut_to_vehicle_stop_s"] = None if stop_at is None else stop_at - t_cut
        out["cut_to_driver_link_lost_s"] = None if lost_at is None else lost_at - t_cut
    finally:
        driver.close()
        vehicle.close()
        relay.close()
    return out


def main() -> None:
    trials = [trial() for _ in range(5)]
    rate = [t["setpoint_hz"] for t in trials]
    lat = [x for t in trials for x in t["command_to_motion_s"]]
    stop = [t["cut_to_vehicle_stop_s"] for t in trials]
    lost = [t["cut_to_driver_link_lost_s"] for t in trials]
    print(f"setpoint rate at the vehicle: {min(rate):.1f}-{max(rate):.1f} Hz (target 20)")
    print(f"command -> vehicle moving: median {statistics.median(lat)*1e3:.0f} ms, max {max(lat)*1e3:.0f} ms")
    print(f"link cut -> vehicle stopped: {', '.join(f'{s:.3f}' for s in stop)} s (limit 0.5; vehicle timeout 0.4)")
    zero = [t["last_message_to_driver_zero_s"] for t in trials]
    print(f"link cut -> driver LINK_LOST: {', '.join(f'{s:.3f}' for s in lost)} s (timeout 0.4)")
    print(f"last message -> driver's first zero setpoint: {', '.join(f'{s:.3f}' for s in zero)} s (limit 0.5)")
    print(json.dumps({"bench": "mavlink_link", "trials": len(trials),
                      "setpoint_hz_min": round(min(rate), 1),
                      "command_to_motion_ms_median": round(statistics.median(lat) * 1e3, 1),
                      "command_to_motion_ms_max": round(max(lat) * 1e3, 1),
                      "cut_to_vehicle_stop_s_max": round(max(stop), 3),
                      "cut_to_driver_link_lost_s_max": round(max(lost), 3),
                      "last_message_to_driver_zero_s_max": round(max(zero), 3)}))


if __name__ == "__main__":
    main()
