"""The occupancy grid on rendered walks through real houses: cells mapped free are navigable.

Acceptance (issue 4): >= 99% of the cells the map calls free are navigable in the simulator's
ground truth (NavGrid.navigable, not inflated). The ProcTHOR renderer draws its floor slab
beyond the rooms (visible through exterior doors) where the ground truth has no floor at all;
cells outside every room polygon are reported separately and not counted there.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from fastlayer_walk import gt_walk

from hiconav.mapping import FREE, OCCUPIED, FrontierTracker, OccupancyGrid

sim_mod = pytest.importorskip("hiconav.sim")


def free_accuracy(house, grid: OccupancyGrid) -> tuple[float, int]:
    """Fraction of the cells mapped free that are navigable in the house's ground truth."""
    nav = house.nav
    rc = np.argwhere(grid.state == FREE)
    nrc = nav.world_to_cell(grid.cell_to_world(rc))
    inb = nav.in_bounds(nrc)
    ok = np.zeros(len(rc), bool)
    ok[inb] = nav.navigable[nrc[inb, 0], nrc[inb, 1]]
    return float(ok.mean()), int(ok.size)


@pytest.mark.parametrize("spec", ["gibson:Allensville", "procthor:val/3"])
def test_cells_mapped_free_are_navigable(shared_data, spec):
    house = sim_mod.load_house(spec)
    sim = sim_mod.Simulator(house)
    grid = OccupancyGrid()
    tracker = FrontierTracker()
    for frame in gt_walk(sim, 100, seed=1):
        grid.integrate(frame)
    frac, n = free_accuracy(house, grid)
    assert n > 2000, f"the walk mapped only {n} free cells"
    assert frac >= 0.99, f"{spec}: only {frac:.4f} of {n} free cells are navigable"
    # obstacles are real: occupied cells lie on (or within one cell of) non-navigable ground truth
    nav = house.nav
    occ = nav.world_to_cell(grid.cell_to_world(np.argwhere(grid.state == OCCUPIED)))
    inb = nav.in_bounds(occ)
    near_blocked = cv2.dilate((~nav.navigable).astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    assert near_blocked[occ[inb, 0], occ[inb, 1]].mean() > 0.95
    frontiers = tracker.update(grid, sim.pose.xy)
    for f in frontiers:
        vp = grid.world_to_cell(f.viewpoint)
        assert grid.state[vp[0], vp[1]] == FREE and not grid.inflated[vp[0], vp[1]]


@pytest.mark.slow
@pytest.mark.parametrize(
    "spec",
    [
        "gibson:Cosmos",
        "gibson:Hanson",
        "gibson:Beechwood",
        "gibson:Klickitat",
        "procthor:val/0",
        "procthor:val/10",
        "procthor:train/17",
    ],
)
def test_cells_mapped_free_are_navigable_in_more_houses(shared_data, spec):
    house = sim_mod.load_house(spec)
    sim = sim_mod.Simulator(house)
    grid = OccupancyGrid()
    for frame in gt_walk(sim, 150, seed=1):
        grid.integrate(frame)
    frac, n = free_accuracy(house, grid)
    assert n > 2000 and frac >= 0.99, f"{spec}: {frac:.4f} of {n} free cells are navigable"
