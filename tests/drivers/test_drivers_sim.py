"""The sim driver: the built-in simulator behind the Driver protocol."""

from __future__ import annotations

import math

import pytest
from hiconav.drivers import open_driver
from hiconav.drivers.base import Driver, FailsafeState
from hiconav.drivers.profiles import profile_from_dict
from hiconav.drivers.sim_driver import SimDriver

from hiconav.types import DiscreteAction, Pose2D, VelocityCommand

sim = pytest.importorskip("hiconav.sim")


@pytest.fixture(scope="module")
def house(shared_data):
    return sim.load_house("procthor:val/3")


@pytest.fixture
def driver(house):
    d = SimDriver(sim.Simulator(house, sim.SimConfig(width=64, height=48)), owns_simulator=True)
    yield d
    d.close()


def test_protocol_and_first_frame(driver, house):
    assert isinstance(driver, Driver)
    f = driver.latest_frame()
    assert f is not None and f.depth.shape == (48, 64)
    assert f.base_pose.distance_to(Pose2D(*house.start_hint)) < 0.31
    assert driver.health().ok


def test_discrete_and_velocity_commands_move_the_robot(driver):
    p0 = driver.pose
    driver.send(DiscreteAction.TURN_LEFT)
    assert driver.pose.yaw == pytest.approx(p0.yaw + math.radians(30))
    driver.send(VelocityCommand(0.5, 0.0))  # clamped to 0.5 m/s for control_dt 0.1 s
    assert driver.latest_frame().base_pose == driver.pose
    assert driver.pose.distance_to(p0) == pytest.approx(0.05, abs=1e-6) or driver.simulator.collided


def test_velocity_is_clamped_to_profile(house):
    profile = profile_from_dict({"name": "r", "limits": {"max_linear": 0.2}, "rates": {"control_dt": 0.5}})
    d = SimDriver(sim.Simulator(house, sim.SimConfig(width=32, height=24)), profile, owns_simulator=True)
    p0 = d.pose
    d.send(VelocityCommand(5.0, 0.0))
    assert d.pose.distance_to(p0) <= 0.1 + 1e-6
    d.close()


def test_geofence_blocks_leaving_motion(house):
    start = Pose2D(*house.start_hint)
    fence = {"kind": "box", "xy_min": [start.x - 0.3, start.y - 0.3], "xy_max": [start.x + 0.3, start.y + 0.3]}
    profile = profile_from_dict({"name": "r", "geofence": fence})
    d = SimDriver(sim.Simulator(house, sim.SimConfig(width=32, height=24)), profile, owns_simulator=True)
    for _ in range(4):
        d.send(DiscreteAction.MOVE_FORWARD)
    assert d.health().failsafe == FailsafeState.OK
    assert d.pose.distance_to(start) <= 0.3 + 1e-6
    d.close()


def test_registry_builds_sim_driver(house):
    profile = profile_from_dict({"name": "r", "camera": {"width": 32, "height": 24}})
    d = open_driver("sim", profile, simulator=sim.Simulator(house, sim.SimConfig(width=32, height=24)))
    assert isinstance(d, SimDriver) and d.latest_frame() is not None
    d.close()
