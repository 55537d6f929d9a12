"""Fixtures for the driver tests: a simulated vehicle and a connected MAVLink driver on fresh
localhost ports (helpers in ``driver_helpers.py``)."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest
from driver_helpers import UdpRelay, free_udp_port, test_profile
from hiconav.drivers.profiles import RobotProfile


@pytest.fixture
def port() -> int:
    return free_udp_port()


@pytest.fixture
def make_link(port: int) -> Iterator[Callable]:
    """``make_link(vehicle_config=None, profile=None, house=None, engage=True, relay=False)`` ->
    (vehicle, driver, relay|None), all closed at teardown."""
    from hiconav.drivers.mavlink_driver import MavlinkDriver
    from hiconav.drivers.vehicle import SimulatedVehicle, VehicleConfig

    made: list = []

    def make(vehicle_config: VehicleConfig | None = None, profile: RobotProfile | None = None, *,
             house=None, engage: bool = True, relay: bool = False, frame_source=None):
        relay_obj = UdpRelay(port) if relay else None
        if relay_obj is not None:
            made.append(relay_obj)
        target = relay_obj.port if relay_obj is not None else port
        vehicle = SimulatedVehicle(f"udpout:127.0.0.1:{target}", vehicle_config or VehicleConfig(), house=house)
        made.append(vehicle)
        vehicle.start()
        driver = MavlinkDriver(profile or test_profile(), url=f"udpin:127.0.0.1:{port}",
                               frame_source=frame_source, handle_signals=False)
        made.append(driver)
        driver.connect()
        if engage:
            driver.engage()
        return vehicle, driver, relay_obj

    yield make
    for obj in reversed(made):
        obj.close()
