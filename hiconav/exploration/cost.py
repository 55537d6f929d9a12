"""Motion cost between the robot and frontier nodes (paper "Motion Cost Modeling", eq. 17-21).

t(kr, ks) = max(d(p_kr, p_ks) / v_max, |xi_kr - xi_ks| / xi_dot_max)            (eq. 17)
c_c(k) = arccos((p_k - p_0) . v_0 / (|p_k - p_0| |v_0|)), 0 when |v_0| < min_speed (eq. 18)
c_s(k) = h_k / h_max                                                            (eq. 19)
M_0k = t(0, k) + w_c c_c(k) + w_f c_s(k);  M_krks = t(kr, ks);  M_k0 = 0         (eq. 20, 21)

- d is the geodesic distance on the current grid: traversable = known free and clear of the
  robot radius (unknown cells too if ``unknown_traversable``). One multi-source Dijkstra
  (scipy.sparse.csgraph.dijkstra with ``indices=`` all n+1 sources) on an 8-connected graph of
  the grid coarsened by ``stride`` (``coarse_traversable``: tight passages stay open, walls do
  not leak), never n^2 A* runs. A robot or viewpoint cell that is blocked snaps to the nearest traversable cell within
  ``snap_radius_m``. Frontiers unreachable from the robot are dropped.
- p_k is the frontier's viewpoint; its heading xi_k is the direction from the viewpoint to the
  frontier centroid (from the robot to the centroid when they coincide); the robot's heading
  xi_0 is its yaw.
- h_k: cast a ray from the viewpoint through the frontier centroid; beyond the centroid, once
  the ray has entered unknown space, the first observed cell (free or occupied) ends it and h_k
  is its distance from the centroid; h_k = h_max when nothing observed is hit within h_max
  (cells outside the grid count as unknown). Small h_k = a small enclosed pocket.

This module computes costs only: it must not score utilities or order frontiers.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

from hiconav.exploration.config import CostConfig
from hiconav.mapping.frontiers import nearest_reachable_cell
from hiconav.mapping.occupancy import GridLike, lethal_mask, squeeze_mask
from hiconav.types import Frontier, wrap_angle

UNKNOWN = -1




@dataclass(frozen=True)
class CostMatrix:
    """The WTRP matrix for the kept frontiers.

    M: (n+1, n+1) seconds, node 0 = robot, node i = frontiers[kept[i-1]]; kept: indices into the
    input frontier list (unreachable ones dropped); distance: (n+1, n+1) geodesic metres;
    heading: (n+1,) xi in rad; c_c, c_s, h: (n,) the robot-edge terms (eq. 18, 19).
    """

    M: np.ndarray
    kept: tuple[int, ...]
    distance: np.ndarray
    heading: np.ndarray
    c_c: np.ndarray
    c_s: np.ndarray
    h: np.ndarray


def traversable_mask(grid: GridLike, config: CostConfig | None = None, *, squeeze: bool = False) -> np.ndarray:
    """(H, W) bool cells the robot may cross: free (or unknown if configured) and clear of the robot
    radius (``lethal_mask``: tight passages count, as the navigator may plan through them);
    ``squeeze``: clear of the lethal layer one cell thinner (``squeeze_mask``, the navigator's last
    resort)."""
    cfg = config or CostConfig()
    state = np.asarray(grid.state)
    ok = (state == 0) | (cfg.unknown_traversable & (state == UNKNOWN))
    return ok & ~(squeeze_mask(grid) if squeeze else lethal_mask(grid))


def _coarsen(mask: np.ndarray, stride: int) -> np.ndarray:
    """(H, W) bool -> (ceil(H/s), ceil(W/s)) bool, True where any fine cell is True."""
    if stride == 1:
        return mask.copy()
    H, W = mask.shape
    Hc, Wc = -(-H // stride), -(-W // stride)
    pad = np.zeros((Hc * stride, Wc * stride), dtype=bool)
    pad[:H, :W] = mask
    # OR of the stride x stride strided views: the same result as
    # pad.reshape(Hc, s, Wc, s).any(axis=(1, 3)), ~20x faster (numpy's multi-axis bool reduction is slow)
    out = pad[0::stride, 0::stride].copy()
    for i in range(stride):
        for j in range(stride):
            if i or j:
                out |= pad[i::stride, j::stride]
    return out


def coarse_traversable(grid: GridLike, config: CostConfig, *, squeeze: bool = False) -> np.ndarray:
    """The traversable mask coarsened by ``config.stride``: a coarse cell is traversable when any
    of its fine cells is and none is an obstacle. Passages one fine cell wide stay open (tight
    doorways, where only the robot radius is clear, look like that; an all-cells rule closed them
    and dropped every frontier behind them), and walls cannot leak: a coarse cell on a wall is
    blocked, and diagonal steps may not cut between two blocked coarse cells."""
    trav = traversable_mask(grid, config, squeeze=squeeze)
    s = config.stride
    if s == 1:
        return trav
    return _coarsen(trav, s) & ~_coarsen(np.asarray(grid.state) == 1, s)


def _grid_graph(mask: np.ndarray, step: float) -> tuple[sp.csr_matrix, np.ndarray]:
    """8-connected graph of the True cells of mask (edge lengths step, step * sqrt 2); returns
    (graph over the True cells, (H, W) node id per cell, -1 elsewhere)."""
    H, W = mask.shape
    rr, cc = np.nonzero(mask)
    node = np.full(mask.shape, -1, dtype=np.int64)
    node[rr, cc] = np.arange(rr.size)
    rows, cols, vals = [], [], []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        r2, c2 = rr + dr, cc + dc
        ok = (r2 < H) & (c2 >= 0) & (c2 < W)
        ok[ok] = mask[r2[ok], c2[ok]]
        if dr and dc:  # no corner cutting: both straight neighbours must be traversable too
            ok[ok] = mask[rr[ok], c2[ok]] & mask[r2[ok], cc[ok]]
        rows.append(node[rr[ok], cc[ok]])
        cols.append(node[r2[ok], c2[ok]])
        vals.append(np.full(int(ok.sum()), step * (math.sqrt(2.0) if dr and dc else 1.0)))
    g = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(rr.size, rr.size))
    return g, node


def geodesic_distances(grid: GridLike, points_xy: np.ndarray, config: CostConfig | None = None, *,
                       squeeze: bool = False) -> np.ndarray:
    """(k, k) geodesic metres between world points (k, 2) on the traversable grid (``squeeze``: see
    ``traversable_mask``); inf when unreachable or off the grid. One Dijkstra call with all k
    sources (see module docstring)."""
    cfg = config or CostConfig()
    pts = np.asarray(points_xy, dtype=float).reshape(-1, 2)
    k = pts.shape[0]
    out = np.full((k, k), np.inf)
    if k == 0:
        return out
    s = cfg.stride
    coarse = coarse_traversable(grid, cfg, squeeze=squeeze)
    graph, node = _grid_graph(coarse, s * grid.resolution)
    rc = np.asarray(grid.world_to_cell(pts)) // s
    radius = math.ceil(cfg.snap_radius_m / (s * grid.resolution))
    src = np.full(k, -1, dtype=np.int64)
    for i in range(k):
        cell = nearest_reachable_cell(coarse, rc[i], radius)
        if cell is not None:
            src[i] = node[cell]
    valid = np.flatnonzero(src >= 0)
    if valid.size == 0:
        return out
    uniq, inv = np.unique(src[valid], return_inverse=True)
    dist = dijkstra(graph, directed=False, indices=uniq)  # (u, V)
    sub = dist[:, uniq][inv][:, inv]  # (valid, valid)
    out[np.ix_(valid, valid)] = sub
    np.fill_diagonal(out, 0.0)
    return out


def openness(grid: GridLike, viewpoint_xy: np.ndarray, centre_xy: np.ndarray, h_max: float,
             fallback_from_xy: np.ndarray | None = None) -> float:
    """h_k (m) by ray casting from the viewpoint through the cluster centre (eq. 19; see module
    docstring). ``fallback_from_xy`` gives the ray direction when viewpoint == centre."""
    c = np.asarray(centre_xy, dtype=float)
    u = c - np.asarray(viewpoint_xy, dtype=float)
    if np.hypot(*u) < 1e-6 and fallback_from_xy is not None:
        u = c - np.asarray(fallback_from_xy, dtype=float)
    norm = float(np.hypot(*u))
    if norm < 1e-6:
        return float(h_max)
    u = u / norm
    step = 0.5 * grid.resolution
    t = np.arange(0.0, h_max + 1e-9, step)
    rc = np.asarray(grid.world_to_cell(c[None, :] + t[:, None] * u[None, :]))
    state = np.asarray(grid.state)
    H, W = state.shape
    inside = (rc[:, 0] >= 0) & (rc[:, 0] < H) & (rc[:, 1] >= 0) & (rc[:, 1] < W)
    val = np.full(t.shape, UNKNOWN, dtype=np.int64)
    val[inside] = state[rc[inside, 0], rc[inside, 1]]
    unknown = val == UNKNOWN
    if not unknown.any():
        return float(h_max)
    first_unknown = int(np.argmax(unknown))
    observed_after = np.flatnonzero(~unknown[first_unknown:])
    if observed_after.size == 0:
        return float(h_max)
    return float(min(h_max, t[first_unknown + observed_after[0]]))


def frontier_heading(frontier: Frontier, robot_xy: np.ndarray) -> float:
    """xi_k: direction (rad) from the viewpoint to the centroid (robot -> centroid if they coincide)."""
    v = np.asarray(frontier.centroid, float) - np.asarray(frontier.viewpoint, float)
    if np.hypot(*v) < 1e-6:
        v = np.asarray(frontier.centroid, float) - np.asarray(robot_xy, float)
    return float(math.atan2(v[1], v[0])) if np.hypot(*v) > 1e-9 else 0.0


def motion_consistency(robot_xy: np.ndarray, velocity_xy: np.ndarray, points_xy: np.ndarray,
                       min_speed: float) -> np.ndarray:
    """c_c (n,) rad: angle between (p_k - p_0) and v_0 (eq. 18); 0 when |v_0| < min_speed."""
    pts = np.asarray(points_xy, float).reshape(-1, 2)
    v = np.asarray(velocity_xy, float)[:2]
    speed = float(np.hypot(*v))
    if speed < max(min_speed, 1e-9):
        return np.zeros(pts.shape[0])
    rel = pts - np.asarray(robot_xy, float)[:2]
    dist = np.hypot(rel[:, 0], rel[:, 1])
    cos = (rel @ v) / np.maximum(dist * speed, 1e-12)
    return np.where(dist > 1e-9, np.arccos(np.clip(cos, -1.0, 1.0)), 0.0)


def travel_time(distance: np.ndarray, heading: np.ndarray, v_max: float, xi_dot_max: float) -> np.ndarray:
    """t (k, k) = max(d / v_max, |wrap(xi_r - xi_s)| / xi_dot_max) (eq. 17)."""
    dxi = np.abs((heading[:, None] - heading[None, :] + math.pi) % (2 * math.pi) - math.pi)
    return np.maximum(distance / v_max, dxi / xi_dot_max)


def cost_matrix(grid: GridLike, robot_xy: np.ndarray, robot_yaw: float, velocity_xy: np.ndarray,
                frontiers: Sequence[Frontier], config: CostConfig | None = None, *,
                squeeze: bool = False) -> CostMatrix:
    """The WTRP matrix M (eq. 20, 21) over the frontiers reachable from the robot (``squeeze``:
    through passages only the lethal layer one cell thinner leaves open)."""
    cfg = config or CostConfig()
    robot_xy = np.asarray(robot_xy, float)[:2]
    n_all = len(frontiers)
    vps = np.array([np.asarray(f.viewpoint, float) for f in frontiers]).reshape(-1, 2)
    finite = np.all(np.isfinite(vps), axis=1) if n_all else np.zeros(0, bool)
    pts = np.vstack([robot_xy[None, :], np.where(finite[:, None], vps, robot_xy)])
    D = geodesic_distances(grid, pts, cfg, squeeze=squeeze)
    reach = np.flatnonzero(finite & np.isfinite(D[0, 1:]))
    kept = tuple(int(i) for i in reach)
    idx = np.concatenate([[0], reach + 1])
    D = D[np.ix_(idx, idx)]
    heading = np.array([float(robot_yaw)] + [frontier_heading(frontiers[i], robot_xy) for i in kept])
    M = travel_time(D, heading, cfg.v_max, cfg.xi_dot_max)  # eq. 17, 21
    kp = vps[list(kept)] if kept else np.zeros((0, 2))
    c_c = motion_consistency(robot_xy, velocity_xy, kp, cfg.min_speed)  # eq. 18
    h = np.array([openness(grid, frontiers[i].viewpoint, frontiers[i].centroid, cfg.h_max, robot_xy)
                  for i in kept])
    c_s = h / cfg.h_max if kept else np.zeros(0)  # eq. 19
    M[0, 1:] += cfg.w_c * c_c + cfg.w_f * c_s  # eq. 20
    M[1:, 0] = 0.0  # open path: returning to the robot is free
    np.fill_diagonal(M, 0.0)
    return CostMatrix(M=M, kept=kept, distance=D, heading=heading, c_c=c_c, c_s=c_s, h=h)


__all__ = [
    "CostMatrix",
    "GridLike",
    "cost_matrix",
    "frontier_heading",
    "geodesic_distances",
    "motion_consistency",
    "openness",
    "travel_time",
    "traversable_mask",
    "wrap_angle",
]
