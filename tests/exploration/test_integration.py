"""The planner on the fast layer's real grid and frontiers in a ProcTHOR house (shared data)."""

from __future__ import annotations

import numpy as np
import pytest

from hiconav.exploration import ExplorationPlanner
from hiconav.types import DiscreteAction, TaskSpec


@pytest.fixture(scope="module")
def scene(shared_data):
    sim_mod = pytest.importorskip("hiconav.sim")
    mapping = pytest.importorskip("hiconav.mapping")
    from hiconav.sim.episodes import generate_episodes

    house = sim_mod.load_house("procthor:val/3")
    ep = generate_episodes(house, 1, 0)[0]
    sim = sim_mod.Simulator(house, seed=0)
    grid = mapping.OccupancyGrid()
    grid.integrate(sim.reset(ep.start))
    for _ in range(11):  # look around once
        grid.integrate(sim.step(DiscreteAction.TURN_LEFT))
    snap = grid.snapshot()
    frontiers = mapping.FrontierTracker().update(snap, sim.pose.xy)
    return snap, frontiers, sim.pose, ep


def test_plan_on_a_real_grid(scene) -> None:
    snap, frontiers, pose, ep = scene
    assert len(frontiers) >= 2
    planner = ExplorationPlanner()
    task = TaskSpec(f"find a {ep.target}", targets=(ep.target,))
    out = planner.plan(snap, frontiers, None, task, pose, np.zeros(2), lambda a, b: float(a == b), now=0.0)
    ids = {f.id for f in frontiers}
    assert out.goal is not None and out.goal.id == out.order[0]
    assert set(out.order) | set(out.dropped) == ids and not set(out.order) & set(out.dropped)
    cm = planner.last_cost
    assert np.all(cm.M[1:, 0] == 0.0) and np.all(np.isfinite(cm.M))
    # geodesic >= straight-line distance between viewpoints (up to the coarse-grid snapping)
    vps = np.array([pose.xy] + [np.asarray(frontiers[i].viewpoint) for i in cm.kept])
    euclid = np.linalg.norm(vps[:, None] - vps[None], axis=-1)
    assert np.all(cm.distance >= euclid - 0.3)
    # re-planning from the same state keeps the goal (no oscillation)
    again = planner.plan(snap, frontiers, None, task, pose, np.zeros(2), lambda a, b: float(a == b), now=0.5)
    assert again.goal.id == out.goal.id and not again.switched
