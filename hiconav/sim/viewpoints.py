"""Which object instances a camera can see at all: rendered checks of ObjectNav goal view points.

Habitat's ObjectNav data set keeps an object instance as a goal only where it has *view
points*: navigable positions near it from which the rendered object covers enough of the image.
``geodesic.goal_sources`` gives the view point cells in 2D (within ``VIEW_RADIUS`` of the
footprint, line of sight past walls); this module renders from a few of them, camera turned
and tilted toward the object, and counts the instance's pixels. The check matters because our renderer
draws every object as a solid box: ProcTHOR puts children *inside* their receptacle's box (a
vase in a dresser's drawer, a laptop on a bed's mattress below the headboard's top, a teddy bear
on a shelf inside a shelving unit), and such an instance shows in no pixel from anywhere. An
episode whose every goal is hidden cannot be solved by any navigator and measures nothing.

Views are sampled, not exhaustive: the view point cells are split into ``SECTORS`` bearing
sectors around the object, and per sector the farthest cell (the object fits the vertical field
of view best from there) is rendered first, then the nearest; the check stops at the first view
with ``min_pixels`` pixels. It renders only; it must not choose episodes (see ``episodes``).
"""

from __future__ import annotations

import math

import numpy as np

from hiconav.sim.geodesic import goal_sources, house_graph
from hiconav.sim.house import House
from hiconav.types import Pose2D, camera_pose_from_base

__all__ = ["MIN_VIEW_PIXELS", "SECTORS", "instance_view_pixels", "viewable_instances"]

MIN_VIEW_PIXELS = 150  # the oracle detector's default minimum area: fewer pixels are never detected
SECTORS = 8


def _view_cells(cells: np.ndarray, offsets: np.ndarray, centre_rc: np.ndarray) -> np.ndarray:
    """Indices of the cells to render, in order: per bearing sector the farthest, then the nearest."""
    d = cells - centre_rc[None, :]
    sector = ((np.arctan2(d[:, 0], d[:, 1]) + math.pi) / (2 * math.pi) * SECTORS).astype(np.int64) % SECTORS
    far, near = [], []
    for s in range(SECTORS):
        idx = np.flatnonzero(sector == s)
        if idx.size:
            far.append(int(idx[np.argmax(offsets[idx])]))
            k = int(idx[np.argmin(offsets[idx])])
            if k != far[-1]:
                near.append(k)
    return np.array(far + near, dtype=np.int64)


def instance_view_pixels(house: House, instance_id: int, sim, *, min_pixels: int = MIN_VIEW_PIXELS) -> int:
    """Most pixels of ``instance_id`` in the sampled views from its view points (0 if it has none).

    ``sim`` is a ``Simulator`` on ``house`` (its renderer, intrinsics and camera height are used;
    its robot is not moved). Stops at the first view with at least ``min_pixels``.
    """
    graph = house_graph(house, sim.config.robot_radius)
    cells, offsets = goal_sources(graph, house.footprint(instance_id), house.nav.resolution,
                                  sim.config.robot_radius, house.sight_walls)
    if not len(cells):
        return 0
    obj = house.objects[instance_id]
    centre_rc = house.nav.world_to_cell(np.asarray(obj.center[:2], dtype=np.float64)).astype(np.float64)
    best = 0
    for k in _view_cells(cells, offsets, centre_rc):
        xy = house.nav.cell_to_world(cells[k])
        dx, dy = obj.center[0] - xy[0], obj.center[1] - xy[1]
        # turned and tilted toward the object's centre: the question is whether anything hides it,
        # not whether a level camera frames it (a painting 1.8 m up is above the level field of view
        # from 1 m, yet in plain sight; the robot sees it from farther away)
        tilt = math.atan2(obj.center[2] - sim.config.camera_height, math.hypot(dx, dy))
        T = camera_pose_from_base(Pose2D(float(xy[0]), float(xy[1]), math.atan2(dy, dx)),
                                  sim.config.camera_height, tilt)
        _rgb, _depth, instances = sim.renderer.render(T, sim.intrinsics)
        best = max(best, int(np.count_nonzero(instances == instance_id)))
        if best >= min_pixels:
            break
    return best


def viewable_instances(house: House, instance_ids, sim, *, min_pixels: int = MIN_VIEW_PIXELS) -> tuple[int, ...]:
    """The ids among ``instance_ids`` that show at least ``min_pixels`` pixels from a view point."""
    return tuple(i for i in instance_ids
                 if instance_view_pixels(house, i, sim, min_pixels=min_pixels) >= min_pixels)
