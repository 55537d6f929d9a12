"""Test helper: a deterministic rendered walk through a simulator house (ground-truth planning).

The walk visits random free cells with A* on the simulator's own free mask and converts the path
to discrete actions (turn to within 15 deg, then forward), turning on the spot now and then to look
around. It only drives the robot; what the map makes of the frames is the test's business.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from hiconav.planning import astar, smooth_path, to_discrete
from hiconav.types import DiscreteAction, Frame, Pose2D


def gt_walk(sim, n_frames: int, seed: int = 0) -> Iterator[Frame]:
    """Yield ``n_frames`` frames (the reset frame first) of a walk driven by ground truth."""
    rng = np.random.default_rng(seed)
    nav = sim.house.nav
    free = sim.free
    rr, cc = np.nonzero(free)
    # start in the largest connected free region
    import cv2

    n, labels = cv2.connectedComponents(free.astype(np.uint8), connectivity=8)
    sizes = np.bincount(labels[rr, cc])
    big = int(np.argmax(sizes))
    cand = np.flatnonzero(labels[rr, cc] == big)
    k = int(rng.choice(cand))
    start = nav.cell_to_world(np.array([rr[k], cc[k]]))
    frame = sim.reset(Pose2D(float(start[0]), float(start[1]), float(rng.uniform(-np.pi, np.pi))))
    yield frame
    produced = 1
    path_xy: np.ndarray | None = None
    blocked = ~free
    while produced < n_frames:
        if path_xy is None or len(path_xy) == 0:
            # look around on arrival, then pick a new goal
            for _ in range(int(rng.integers(0, 12))):
                if produced >= n_frames:
                    return
                yield sim.step(DiscreteAction.TURN_LEFT)
                produced += 1
            g = int(rng.choice(cand))
            s = nav.world_to_cell(sim.pose.xy)
            cells = astar(blocked, (int(s[0]), int(s[1])), (int(rr[g]), int(cc[g])))
            if cells is None or len(cells) < 4:
                path_xy = None
                continue
            path_xy = nav.cell_to_world(smooth_path(blocked, cells))[1:]
        pose = sim.pose
        while len(path_xy) and np.hypot(*(path_xy[0] - pose.xy)) < 0.2:
            path_xy = path_xy[1:]
        if len(path_xy) == 0:
            continue
        action = to_discrete(pose, path_xy[0], 15.0)
        frame = sim.step(action)
        produced += 1
        if sim.collided:
            path_xy = None
        yield frame
