"""The Navigator in the simulator: it reaches goals on its own map without colliding.

The robot looks around (12 turns of 30 deg), then is sent to cells its map knows as free and
traversable 1.5-5 m away; each step it integrates the new frame, so re-planning happens as the
map changes. Discrete (turn to within 15 deg, then forward) and velocity (pure pursuit) modes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiconav.mapping import OccupancyGrid
from hiconav.mapping.frontiers import reachable_mask
from hiconav.planning import Navigator
from hiconav.types import DiscreteAction, Goal, Pose2D

sim_mod = pytest.importorskip("hiconav.sim")


def start_sim(spec: str, seed: int):
    house = sim_mod.load_house(spec)
    sim = sim_mod.Simulator(house)
    rng = np.random.default_rng(seed)
    import cv2

    n, labels = cv2.connectedComponents(sim.free.astype(np.uint8), connectivity=8)
    big = int(np.argmax(np.bincount(labels[sim.free])))
    rr, cc = np.nonzero(labels == big)
    k = int(rng.integers(len(rr)))
    xy = house.nav.cell_to_world(np.array([rr[k], cc[k]]))
    frame = sim.reset(Pose2D(float(xy[0]), float(xy[1]), 0.0))
    grid = OccupancyGrid()
    grid.integrate(frame)
    for _ in range(12):
        grid.integrate(sim.step(DiscreteAction.TURN_LEFT))
    return sim, grid, rng


def pick_goals(sim, grid: OccupancyGrid, rng, n: int) -> list[np.ndarray]:
    trav = (grid.state == 0) & ~grid.inflated
    rc = grid.world_to_cell(sim.pose.xy)
    reach = reachable_mask(trav, (int(rc[0]), int(rc[1])))
    cells = np.argwhere(reach)
    xy = grid.cell_to_world(cells)
    d = np.hypot(*(xy - sim.pose.xy).T)
    ok = (d > 1.5) & (d < 5.0) & np.array([sim.is_free(p) for p in xy])
    assert ok.sum() > 0, "the look-around mapped no goal candidates"
    return [xy[i] for i in rng.choice(np.flatnonzero(ok), size=min(n, int(ok.sum())), replace=False)]


@pytest.mark.parametrize("spec,seed", [("procthor:val/3", 0), ("gibson:Allensville", 2)])
def test_discrete_navigation_reaches_goals_without_collision(shared_data, spec, seed):
    sim, grid, rng = start_sim(spec, seed)
    nav = Navigator()
    for goal_xy in pick_goals(sim, grid, rng, 2):
        nav.set_goal(Goal(float(goal_xy[0]), float(goal_xy[1]), tolerance=0.25))
        for _ in range(120):
            action = nav.step(grid, sim.pose)
            if action == DiscreteAction.STOP:
                break
            grid.integrate(sim.step(action))
            assert not sim.collided, f"collision at {sim.pose} going to {goal_xy}"
        assert nav.reached, f"{nav.status}: stopped at {sim.pose} with goal {goal_xy}"
        assert np.hypot(*(sim.pose.xy - goal_xy)) <= 0.25 + 1e-6
    assert sim.collisions == 0


def test_velocity_navigation_reaches_goal_without_collision(shared_data):
    sim, grid, rng = start_sim("procthor:val/3", 1)
    nav = Navigator()
    goal_xy = pick_goals(sim, grid, rng, 1)[0]
    nav.set_goal(Goal(float(goal_xy[0]), float(goal_xy[1]), tolerance=0.25, yaw=math.pi / 2))
    dt = 0.2
    for i in range(400):
        cmd = nav.step_velocity(grid, sim.pose, dt)
        if nav.reached:
            break
        frame = sim.step_velocity(cmd, dt)
        if i % 2 == 0:
            grid.integrate(frame)
        assert (
            abs(cmd.v) <= nav.config.local.v_max + 1e-9
            and abs(cmd.omega) <= nav.config.local.omega_max + 1e-9
        )
    assert nav.reached, nav.status
    assert np.hypot(*(sim.pose.xy - goal_xy)) <= 0.25 + 1e-6
    assert abs((sim.pose.yaw - math.pi / 2 + math.pi) % (2 * math.pi) - math.pi) <= math.radians(15) + 1e-6
    assert sim.collisions == 0
