"""Agent motion: Habitat action semantics, continuous motion, collisions with the grid."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_synthetic import box_room, obj

from hiconav.sim.config import SimConfig
from hiconav.sim.house import Wall
from hiconav.sim.simulator import Simulator, SimulatorError
from hiconav.types import DiscreteAction, Pose2D, VelocityCommand

A = DiscreteAction


def _no_render(sim: Simulator) -> Simulator:
    sim.observe = lambda: None  # motion tests do not need images
    return sim


def test_forward_and_turns_follow_habitat_steps():
    sim = _no_render(Simulator(box_room(6.0)))
    sim.reset(Pose2D(2.0, 3.0, 0.0))
    sim.step(A.MOVE_FORWARD)
    assert sim.pose.x == pytest.approx(2.25) and sim.pose.y == pytest.approx(3.0)
    assert not sim.collided
    sim.step(A.TURN_LEFT)
    assert sim.pose.yaw == pytest.approx(math.radians(30))
    sim.step(A.TURN_RIGHT)
    sim.step(A.TURN_RIGHT)
    assert sim.pose.yaw == pytest.approx(math.radians(-30))
    sim.step(A.LOOK_UP)
    assert sim.tilt == pytest.approx(math.radians(30))
    sim.step(A.LOOK_DOWN)
    sim.step(A.LOOK_DOWN)
    assert sim.tilt == pytest.approx(math.radians(-30))
    assert sim.steps == 7 and not sim.stopped
    assert sim.turns == 3  # the turns in place only: no step forward, look or stop
    sim.step(A.STOP)
    assert sim.stopped and sim.turns == 3
    assert sim.path_length == pytest.approx(0.25)
    sim.reset(Pose2D(2.0, 3.0, 0.0))
    assert sim.turns == 0


def test_forward_into_a_wall_stops_before_it_and_flags_collision():
    sim = _no_render(Simulator(box_room(6.0)))
    sim.reset(Pose2D(5.0, 3.0, 0.0))
    for _ in range(10):
        sim.step(A.MOVE_FORWARD)
    assert sim.collided
    # Wall face at x = 5.95; the disc edge stays at least one cell (5 cm) short of overlap.
    assert sim.pose.x + 0.18 <= 5.95 + 0.05
    assert sim.pose.x < 5.95


def test_a_wall_met_at_an_angle_is_slid_along_unless_sliding_is_off():
    for sliding in (True, False):
        sim = _no_render(Simulator(box_room(6.0), SimConfig(allow_sliding=sliding)))
        sim.reset(Pose2D(5.6, 3.0, math.radians(60)))  # 0.17 m from the wall face at x = 5.95
        for _ in range(4):
            sim.step(A.MOVE_FORWARD)
        assert sim.collided
        assert sim.pose.x + 0.18 <= 5.95 + 0.05  # never into the wall
        if sliding:
            assert sim.pose.y > 3.6  # glided along the wall, losing only the blocked component
            assert sim.path_length == pytest.approx(np.hypot(sim.pose.x - 5.6, sim.pose.y - 3.0), abs=0.1)
        else:
            assert sim.pose.y < 3.3  # stopped dead at the first blocked sub-step


def test_never_through_a_thin_wall_or_object():
    walls = [Wall((3.0, 0.0), (3.0, 6.0), 2.5, 0.1)]  # splits the room in two
    house = box_room(6.0, [obj(0, "sofa", (1.5, 1.5, 0.4), (0.8, 0.8, 0.8))], walls)
    sim = _no_render(Simulator(house))
    rng = np.random.default_rng(0)
    sim.reset(Pose2D(1.5, 4.0, 0.0))
    for _ in range(400):
        a = [A.MOVE_FORWARD] * 3 + [A.TURN_LEFT, A.TURN_RIGHT]
        sim.step(a[int(rng.integers(5))])
        assert sim.pose.x < 3.0 - 0.05  # never crosses the dividing wall
        # Never inside the sofa, and the disc (less one cell of grid quantisation) clears it.
        dx = max(abs(sim.pose.x - 1.5) - 0.4, 0.0)
        dy = max(abs(sim.pose.y - 1.5) - 0.4, 0.0)
        assert math.hypot(dx, dy) >= 0.18 - 0.05


def test_robot_disc_stays_on_navigable_cells_in_a_real_house(shared_data):
    from hiconav.sim.episodes import generate_episodes
    from hiconav.sim.houses import load_house

    house = load_house("procthor:val/3", shared_data)
    sim = _no_render(Simulator(house))
    ep = generate_episodes(house, 1, seed=0)[0]
    sim.reset(ep.start)
    nav = house.nav
    blocked = np.argwhere(~nav.navigable)
    centres = nav.cell_to_world(blocked)
    rng = np.random.default_rng(1)
    collided = 0
    for _ in range(300):
        sim.step([A.MOVE_FORWARD, A.MOVE_FORWARD, A.TURN_LEFT, A.TURN_RIGHT][rng.integers(4)])
        collided += sim.collided
        # Distance from the robot centre to the nearest blocked cell (as a square).
        d = np.maximum(np.abs(centres - sim.pose.xy) - 0.025, 0.0)
        assert np.hypot(d[:, 0], d[:, 1]).min() >= 0.18 - 0.05
    assert collided > 0  # the walk did hit things, so the check was exercised


def test_velocity_motion_integrates_and_collides():
    sim = _no_render(Simulator(box_room(6.0)))
    sim.reset(Pose2D(2.0, 3.0, 0.0))
    sim.step_velocity(VelocityCommand(0.5, 0.0), 1.0)
    assert sim.pose.x == pytest.approx(2.5, abs=1e-6) and not sim.collided
    sim.step_velocity(VelocityCommand(0.0, math.pi / 2), 1.0)
    assert sim.pose.yaw == pytest.approx(math.pi / 2)
    sim.step_velocity(VelocityCommand(1.0, 0.0), 5.0)
    assert sim.collided and sim.pose.y < 5.95 - 0.13
    with pytest.raises(SimulatorError):
        sim.step_velocity(VelocityCommand(1.0, 0.0), 0.0)


def test_reset_inside_a_wall_is_an_error():
    sim = _no_render(Simulator(box_room(6.0, extra_walls=[Wall((3, 0), (3, 6), 2.5, 0.6)])))
    with pytest.raises(SimulatorError, match="not on free floor"):
        sim.reset(Pose2D(3.0, 3.0, 0.0))


def test_observation_frame_fields():
    sim = Simulator(box_room(6.0), SimConfig(width=160, height=120))
    f = sim.reset(Pose2D(2.0, 3.0, 0.0))
    assert f.rgb.shape == (120, 160, 3) and f.depth.shape == (120, 160)
    assert f.instances.shape == (120, 160) and f.instances.dtype == np.int32
    assert f.base_pose == sim.pose and f.intrinsics == sim.intrinsics
    assert f.T_world_cam[2, 3] == pytest.approx(0.88)
    f2 = sim.step(A.MOVE_FORWARD)
    assert f2.seq == f.seq + 1 and f2.stamp > f.stamp
    sim.close()


def test_the_first_frame_with_a_goal_in_view_is_recorded_with_the_path_before_it():
    """Scoring only: where an episode's path went before its goal was first in view."""
    house = box_room(10.0, [obj(2, "bed", (8.0, 5.0, 0.3), (1.6, 2.0, 0.6)),
                            obj(1, "chair", (2.0, 8.5, 0.45), (0.5, 0.5, 0.9))])
    sim = Simulator(house, SimConfig(width=160, height=120))
    sim.reset(Pose2D(2.0, 5.0, math.pi))  # facing away from the bed
    sim.watch([2])
    assert sim.first_in_view is None
    sim.step(A.MOVE_FORWARD)  # 0.25 m, still facing the wall behind
    for _ in range(6):  # turn round toward the bed, 5.45 m off: in range at the image's edge
        sim.step(A.TURN_LEFT)  # (depth is measured along the optical axis, as a depth camera's)
    assert sim.first_in_view is not None
    steps, path, x, y = sim.first_in_view
    assert 1 < steps <= 7 and path == pytest.approx(0.25) and (x, y) == pytest.approx((1.75, 5.0))
    sim.step(A.MOVE_FORWARD)
    sim.step(A.MOVE_FORWARD)
    assert sim.first_in_view[0] == steps  # the first sighting stays
    sim.watch([2])  # watching anew: the goal in view where the robot stands counts at once
    assert sim.first_in_view is not None and sim.first_in_view[0] == sim.steps
    sim.watch([1])  # the chair is to the robot's left, out of the image; the bed's larger id is not it
    assert sim.first_in_view is None
    sim.close()
    far = Simulator(house, SimConfig(width=160, height=120, max_depth=3.0))
    far.reset(Pose2D(2.0, 5.0, 0.0))  # facing the bed 5.2 m off, beyond a 3 m depth range
    far.watch([2])
    assert far.first_in_view is None
    far.close()
