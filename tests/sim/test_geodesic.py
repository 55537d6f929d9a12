"""Geodesic distances agree with an independent Dijkstra (heapq) and with geometry."""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest
from sim_synthetic import box_room, obj

from hiconav.sim.geodesic import GoalDistance, GridGraph, clearance, traversable
from hiconav.sim.house import Wall


def _heap_dijkstra(mask, sources, offsets, res):
    """Reference: 8-connected, no corner cutting, initial values = offsets."""
    h, w = mask.shape
    dist = np.full((h, w), np.inf)
    heap = []
    for (r, c), o in zip(sources, offsets):
        if o < dist[r, c]:
            dist[r, c] = o
            heapq.heappush(heap, (o, r, c))
    while heap:
        d, r, c = heapq.heappop(heap)
        if d > dist[r, c]:
            continue
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                if not (dr or dc):
                    continue
                rr, cc = r + dr, c + dc
                if not (0 <= rr < h and 0 <= cc < w and mask[rr, cc]):
                    continue
                if dr and dc and not (mask[r + dr, c] and mask[r, c + dc]):
                    continue
                nd = d + res * (math.sqrt(2) if dr and dc else 1.0)
                if nd < dist[rr, cc]:
                    dist[rr, cc] = nd
                    heapq.heappush(heap, (nd, rr, cc))
    return dist


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_scipy_dijkstra_matches_a_heap_reimplementation(seed):
    rng = np.random.default_rng(seed)
    mask = rng.random((40, 55)) > 0.25
    free = np.argwhere(mask)
    k = rng.choice(len(free), size=4, replace=False)
    sources = free[k]
    offsets = rng.uniform(0.0, 0.2, size=4)
    got = GridGraph(mask, 0.05).multi_source(sources, offsets)
    ref = _heap_dijkstra(mask, sources, offsets, 0.05)
    assert np.array_equal(np.isfinite(got), np.isfinite(ref))
    fin = np.isfinite(ref)
    np.testing.assert_allclose(got[fin], ref[fin], atol=1e-6)


def test_a_source_reads_exactly_its_offset_so_a_robot_at_the_success_distance_succeeds():
    # The sparse graph needs a positive edge weight; that epsilon must not reach the result
    # (1.000000001 m at a view point exactly 1 m away failed the <= 1 m success test).
    mask = np.ones((5, 40), dtype=bool)
    got = GridGraph(mask, 0.05).multi_source(np.array([[2, 0], [2, 39]]), np.array([1.0, 0.0]))
    assert got[2, 0] == 1.0
    assert got[2, 39] == 0.0
    assert got[2, 38] == 0.05


def test_goal_distance_in_open_space_is_straight_line_to_the_footprint():
    house = box_room(8.0, [obj(0, "chair", (6.0, 4.0, 0.45), (0.5, 0.5, 0.9))])
    gd = GoalDistance(house, instance_ids=[0])
    # Same row as the chair: distance to its near face (x = 5.75), within a cell.
    for x in (1.0, 2.5, 4.0):
        assert gd.distance(np.array([x, 4.0])) == pytest.approx(5.75 - x, abs=0.06)


def test_goal_distance_goes_around_a_wall():
    wall = Wall((4.0, 0.0), (4.0, 6.0), 2.5, 0.1)  # open only for y in (6, 8)
    house = box_room(8.0, [obj(0, "bed", (6.0, 2.0, 0.3), (1.0, 1.0, 0.6))], [wall])
    gd = GoalDistance(house, instance_ids=[0])
    start = np.array([2.0, 2.0])
    d = gd.distance(start)
    # Lower bound: via the gap corner (4, 6 + radius) to the bed's nearest corner (5.5, 2.5).
    corner = np.array([4.0, 6.05 + 0.18])
    lower = np.linalg.norm(corner - start) + np.linalg.norm(np.array([5.5, 2.5]) - corner)
    assert d >= lower - 0.1
    assert d <= lower * 1.1 + 0.2
    assert d > 2 * (5.5 - 2.0)  # far longer than the straight line


def test_traversable_respects_robot_radius():
    house = box_room(4.0)
    free = traversable(house.nav, 0.18)
    cl = clearance(house.nav)
    assert np.all(cl[free] >= 0.18 - 1e-9)
    # A cell next to the wall face (x = 0.05 .. 0.10) is navigable but not traversable.
    rc = house.nav.world_to_cell(np.array([0.12, 2.0]))
    assert house.nav.navigable[rc[0], rc[1]] and not free[rc[0], rc[1]]


def test_unreachable_goal_is_infinite():
    wall = Wall((4.0, 0.0), (4.0, 8.0), 2.5, 0.1)
    house = box_room(8.0, [obj(0, "toilet", (6.0, 2.0, 0.4), (0.5, 0.5, 0.8))], [wall])
    gd = GoalDistance(house, instance_ids=[0])
    assert math.isinf(gd.distance(np.array([2.0, 2.0])))
    assert math.isfinite(gd.distance(np.array([6.0, 5.0])))


def test_a_goal_behind_a_wall_is_not_found_from_the_other_side():
    """View points must see the object: a painting 0.3 m behind a wall is 0.45 m away in a
    straight line from the next room, but that room's robot must walk round through the gap."""
    wall = Wall((4.0, 0.0), (4.0, 6.0), 2.5, 0.1)  # open only for y in (6, 8)
    house = box_room(8.0, [obj(0, "painting", (4.35, 2.0, 1.5), (0.1, 0.6, 0.5))], [wall])
    assert house.sight_walls is not None and house.sight_walls.any()
    gd = GoalDistance(house, instance_ids=[0])
    beside = gd.distance(np.array([3.6, 2.0]))  # next room, 0.7 m from the painting's cells
    assert beside > 5.0  # round through the gap at y = 6 and back down
    assert gd.distance(np.array([4.8, 2.0])) < 0.6  # in front of it
    # Without sight walls (the old rule) the next room counted as a view point.
    import dataclasses

    blind = GoalDistance(dataclasses.replace(house, sight_walls=None, _cache={}), instance_ids=[0])
    assert blind.distance(np.array([3.6, 2.0])) < 1.0


def test_a_line_cannot_slip_between_wall_cells_that_touch_at_a_corner():
    from hiconav.sim.geodesic import sees_footprint

    walls = np.zeros((9, 9), dtype=bool)
    for k in range(9):
        walls[k, 8 - k] = True  # a one-cell staircase wall from (0, 8) to (8, 0)
    foot = np.zeros_like(walls)
    foot[7, 7] = True
    seen = sees_footprint(np.array([[1, 1], [8, 8]]), foot, walls, 10.0)
    assert seen.tolist() == [False, True]


def test_an_object_whose_cell_lies_in_its_wall_is_seen_from_its_own_side_only():
    """A painting's single footprint cell can fall in the wall row it hangs on; the wall must
    not grow over the free cells in front of it."""
    from hiconav.sim.geodesic import sees_footprint

    walls = np.zeros((12, 12), dtype=bool)
    walls[5:7, :] = True  # a two-cell wall, rows 5 and 6
    foot = np.zeros_like(walls)
    foot[6, 6] = True  # the painting, in the wall's upper row
    seen = sees_footprint(np.array([[7, 6], [9, 6], [10, 8], [3, 6]]), foot, walls, 10.0)
    assert seen.tolist() == [True, True, True, False]


def test_an_object_that_no_view_point_reaches_within_a_metre_can_still_be_found():
    """The fallback ring (Gibson's gap around furniture): the nearest traversable cells are
    1.25 m from the footprint, and stopping there must count."""
    from hiconav.sim.geodesic import VIEW_RADIUS, goal_sources, house_graph

    house = box_room(8.0, [obj(0, "toilet", (4.0, 4.0, 0.4), (0.5, 0.5, 0.8)),
                           obj(1, "cabinet", (4.0, 4.0, 0.4), (2.5, 2.5, 0.8))])
    graph = house_graph(house, 0.18)
    cells, offsets = goal_sources(graph, house.footprint(0), house.nav.resolution, 0.18)
    assert len(cells) and offsets.min() <= VIEW_RADIUS
    gd = GoalDistance(house, instance_ids=[0])
    assert gd.distance(np.array([4.0, 5.5])) <= 1.0  # beside the cabinet, 1.25 m from the toilet


@pytest.mark.parametrize("x", [2.0, 2.0125, 2.025, 2.04])  # any phase against the 5 cm cells
def test_a_thin_wall_object_has_a_footprint_along_its_whole_length(x):
    """val/65/2: a painting 3 cm thick lay between two columns of cell centres and its footprint
    was the single cell at its middle, so a robot 0.57 m from its end was 1.02 m "away"."""
    house = box_room(6.0, [obj(0, "painting", (x, 3.0, 1.5), (0.03, 0.9, 0.6))])
    xy = house.nav.cell_to_world(house.footprint(0))
    assert xy[:, 1].min() < 2.6 and xy[:, 1].max() > 3.4
    d = GoalDistance(house, instance_ids=(0,)).distance(np.array([x - 0.4, 2.2]))
    assert d == pytest.approx(math.hypot(0.4, 0.35), abs=0.08)
