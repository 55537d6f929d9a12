"""Motion cost (eq. 17-21): geodesic distances, heading, motion consistency, openness, M."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _exploration_fakes import FakeGrid

from hiconav.exploration.config import CostConfig
from hiconav.exploration.cost import (
    cost_matrix,
    geodesic_distances,
    motion_consistency,
    openness,
    travel_time,
)
from hiconav.types import Frontier


def room(h: int = 100, w: int = 100) -> FakeGrid:
    """10 m x 10 m free room at 0.1 m, walls on the border."""
    state = np.zeros((h, w), dtype=np.int8)
    state[0, :] = state[-1, :] = state[:, 0] = state[:, -1] = 1
    inflated = state == 1
    return FakeGrid(state=state, inflated=inflated)


def frontier(fid: int, vp: tuple[float, float], centroid: tuple[float, float]) -> Frontier:
    return Frontier(id=fid, centroid=np.array(centroid, float), viewpoint=np.array(vp, float), size=10)


def test_geodesic_goes_around_a_wall() -> None:
    g = room()
    g.state[50, 1:80] = 1  # wall at y = 5 m from x = 0 to 8 m, gap on the right
    g.inflated = g.state == 1
    pts = np.array([[2.0, 3.0], [2.0, 7.0], [5.0, 3.0]])
    D = geodesic_distances(g, pts, CostConfig(stride=1))
    assert D[0, 2] == pytest.approx(3.0, abs=0.15)  # straight, free
    detour = math.hypot(6.1, 2.0) * 2  # around the wall end at (8.1, 5)
    assert D[0, 1] > 4.0 * 2
    assert D[0, 1] == pytest.approx(detour, rel=0.1)
    assert np.allclose(D, D.T)
    Dc = geodesic_distances(g, pts, CostConfig(stride=2))
    assert Dc[0, 1] == pytest.approx(D[0, 1], rel=0.05)


def test_matrix_is_open_path_and_symmetric_between_frontiers() -> None:
    g = room()
    fs = [frontier(1, (8.0, 2.0), (8.5, 2.0)), frontier(2, (2.0, 8.0), (2.0, 8.5)), frontier(3, (8.0, 8.0), (8.5, 8.5))]
    cm = cost_matrix(g, np.array([5.0, 5.0]), 0.0, np.zeros(2), fs, CostConfig(stride=1))
    assert cm.M.shape == (4, 4) and cm.kept == (0, 1, 2)
    assert np.all(cm.M[1:, 0] == 0.0)  # M_k0 = 0
    assert np.all(np.diag(cm.M) == 0.0)
    assert np.allclose(cm.M[1:, 1:], cm.M[1:, 1:].T)  # eq. 21
    assert np.all(cm.M[0, 1:] > 0)


def test_travel_time_is_the_max_of_translation_and_rotation() -> None:  # eq. 17
    D = np.array([[0.0, 1.0], [1.0, 0.0]])
    t = travel_time(D, np.array([0.0, math.pi / 2]), v_max=1.0, xi_dot_max=0.5)
    assert t[0, 1] == pytest.approx(math.pi)  # rotation bound: (pi/2) / 0.5
    t = travel_time(D, np.array([0.0, math.pi / 2]), v_max=0.1, xi_dot_max=0.5)
    assert t[0, 1] == pytest.approx(10.0)  # translation bound
    # headings wrap: 179 deg vs -179 deg differ by 2 deg
    t = travel_time(np.zeros((2, 2)), np.radians([179.0, -179.0]), 1.0, 1.0)
    assert t[0, 1] == pytest.approx(math.radians(2.0))


def test_motion_consistency_angle() -> None:  # eq. 18
    pts = np.array([[2.0, 0.0], [-2.0, 0.0], [0.0, 3.0]])
    c = motion_consistency(np.zeros(2), np.array([0.4, 0.0]), pts, min_speed=0.05)
    assert c == pytest.approx([0.0, math.pi, math.pi / 2])
    assert motion_consistency(np.zeros(2), np.array([0.01, 0.0]), pts, min_speed=0.05).tolist() == [0, 0, 0]


def test_heading_consistency_enters_robot_edges_only() -> None:
    g = room()
    ahead, behind = frontier(1, (8.0, 5.0), (8.5, 5.0)), frontier(2, (2.0, 5.0), (1.5, 5.0))
    cfg = CostConfig(stride=1, w_c=2.0, w_f=0.0)
    moving = cost_matrix(g, np.array([5.0, 5.0]), 0.0, np.array([0.5, 0.0]), [ahead, behind], cfg)
    still = cost_matrix(g, np.array([5.0, 5.0]), 0.0, np.zeros(2), [ahead, behind], cfg)
    assert moving.c_c == pytest.approx([0.0, math.pi])
    assert moving.M[0, 2] - still.M[0, 2] == pytest.approx(2.0 * math.pi)
    assert moving.M[0, 1] == pytest.approx(still.M[0, 1])
    assert np.allclose(moving.M[1:, :], still.M[1:, :])


def test_openness_measures_the_unknown_pocket_depth() -> None:  # eq. 19
    g = room()
    g.state[40:60, 60:70] = -1  # a 1 m deep unknown pocket (x in [6, 7)), observed free beyond
    g.state[70:90, 60:100] = -1  # unknown up to the grid edge (x in [6, 10) and beyond)
    g.inflated = g.state == 1
    h_pocket = openness(g, np.array([5.0, 5.0]), np.array([5.95, 5.0]), h_max=3.0)
    assert h_pocket == pytest.approx(1.05, abs=0.1)  # from the centre to x = 7.0
    h_open = openness(g, np.array([5.0, 8.0]), np.array([5.95, 8.0]), h_max=3.0)
    assert h_open == 3.0
    fs = [frontier(1, (5.0, 5.0), (5.95, 5.0)), frontier(2, (5.0, 8.0), (5.95, 8.0))]
    cm = cost_matrix(g, np.array([5.0, 6.5]), 0.0, np.zeros(2), fs, CostConfig(stride=1, w_f=4.0, h_max=3.0))
    assert cm.c_s == pytest.approx([h_pocket / 3.0, 1.0])
    # same distance and heading from the robot: the confined pocket is cheaper by w_f (1 - c_s)
    assert cm.M[0, 2] - cm.M[0, 1] == pytest.approx(4.0 * (1.0 - h_pocket / 3.0), abs=0.05)
    # the default weight (0, chosen on the Gibson tune floors) still measures c_s but weighs it not
    cm = cost_matrix(g, np.array([5.0, 6.5]), 0.0, np.zeros(2), fs, CostConfig(stride=1, h_max=3.0))
    assert cm.c_s == pytest.approx([h_pocket / 3.0, 1.0])
    assert cm.M[0, 2] == pytest.approx(cm.M[0, 1], abs=0.05)


def test_unreachable_frontiers_are_dropped() -> None:
    g = room()
    g.state[20:30, 20] = 1
    g.state[20:30, 30] = 1
    g.state[20, 20:31] = 1
    g.state[30, 20:31] = 1  # a closed box around (2.5, 2.5)
    g.inflated = g.state == 1
    fs = [frontier(1, (2.5, 2.5), (2.6, 2.5)), frontier(2, (8.0, 8.0), (8.5, 8.5))]
    cm = cost_matrix(g, np.array([5.0, 5.0]), 0.0, np.zeros(2), fs, CostConfig(stride=1, snap_radius_m=0.2))
    assert cm.kept == (1,)
    assert cm.M.shape == (2, 2)
