"""A mission over MAVLink in a real house (ProcTHOR val/3): the simulated vehicle moves with the
simulator's collision rule, the driver follows a geodesic path to an object and ends facing it.

The full navigator (mapping, frontiers, VLM) is integrated by the orchestration layer; here the
sim's geodesic path stands in for the planner so the test pins the robot-side chain alone:
Driver protocol -> MAVLink over UDP -> vehicle kinematics + collisions -> pose -> rendered frame.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from driver_helpers import drive_to, wait_until
from hiconav.drivers.frame_sources import SimRendererSource
from hiconav.drivers.vehicle import VehicleConfig

from hiconav.types import Pose2D, VelocityCommand, wrap_angle

sim = pytest.importorskip("hiconav.sim")


@pytest.fixture(scope="module")
def house(shared_data):
    return sim.load_house("procthor:val/3")


def _pick_target(house, start_xy):
    """The object (of a few ObjectNav-like categories) with a geodesic distance of 2.5-6 m."""
    best = None
    for obj in house.objects:
        if obj.category not in ("fridge", "dining_table", "sofa", "bed", "chair", "tv", "toilet", "plant"):
            continue
        gd = sim.GoalDistance(house, instance_ids=[obj.instance_id])
        d = gd.distance(start_xy)
        if 2.5 <= d <= 6.0 and (best is None or d < best[2]):
            best = (obj, gd, d)
    assert best is not None, "no suitable target in procthor:val/3"
    return best


def test_mission_over_mavlink_reaches_target(house, make_link):
    start = Pose2D(*house.start_hint)
    obj, gd, d0 = _pick_target(house, start.xy)
    source = SimRendererSource(sim.Simulator(house))
    vehicle, driver, _ = make_link(VehicleConfig(start=start, max_linear=1.0, max_angular=2.0), house=house,
                                   frame_source=source)
    path = gd.path(start.xy)
    assert len(path) > 10
    waypoints = path[::8][1:].tolist() + [path[-1].tolist()]
    t0 = time.monotonic()
    for wp in waypoints:
        assert drive_to(driver, tuple(wp), tolerance=0.2, timeout=6.0), f"stuck before {wp}"
        if gd.distance(driver.pose.xy) <= 0.9:
            break
    # face the object, then stop
    end = time.monotonic() + 3.0
    while time.monotonic() < end:
        p = driver.pose
        err = wrap_angle(math.atan2(obj.center[1] - p.y, obj.center[0] - p.x) - p.yaw)
        if abs(err) < 0.1:
            break
        driver.send(VelocityCommand(0.0, max(-1.5, min(1.5, 3.0 * err))))
        time.sleep(0.03)
    driver.stop()
    assert wait_until(lambda: vehicle.state().v == 0.0 and vehicle.state().omega == 0.0, 1.0)
    final = vehicle.state().pose
    distance = gd.distance(final.xy)
    print(f"target {obj.category} #{obj.instance_id}: {d0:.2f} m -> {distance:.2f} m in "
          f"{time.monotonic() - t0:.1f} s, {vehicle.state().counters.get('collisions', 0)} collision steps")
    assert distance <= 1.0  # ObjectNav success distance
    frame = driver.latest_frame()
    assert frame is not None and frame.rgb.shape == (480, 640, 3)
    assert frame.base_pose.distance_to(final) < 0.1
    assert obj.instance_id in np.unique(frame.instances)  # the target is in view
    source.close()


def test_vehicle_does_not_pass_through_walls(house, make_link):
    start = Pose2D(*house.start_hint)
    vehicle, driver, _ = make_link(VehicleConfig(start=start), house=house)
    free = sim.Simulator(house).is_free
    end = time.monotonic() + 4.0
    while time.monotonic() < end:  # straight ahead, whatever is there
        driver.send(VelocityCommand(1.0, 0.0))
        if vehicle.state().collided:
            break
        time.sleep(0.03)
    s = vehicle.state()
    assert s.collided and s.counters.get("collisions", 0) > 0
    assert free(np.array([s.pose.x, s.pose.y]))
