"""The cell to stand on near a candidate: its camera, the furniture around it, and the cascade of
cell searches from roomy to tight.

``approach_cell`` (``geometry``) finds one cell under one set of rules; ``cell_near`` tries them
in the order a robot should: where the robot already stands in a passage only its radius clears,
a tight cell first (a cell along that passage is no tighter than where it is, and keeping the
margin sends the robot along the passage to its one roomy cell); then a roomy cell; then, with
furniture all around the object, a cell only the robot's radius clears. Pure: plain memory
objects, anchors and grid snapshots in, a world xy out.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from hiconav.decisions.geometry import approach_cell


def camera_of(memory: Any) -> tuple[float, float] | None:
    """(camera height m, vertical field of view rad) from the newest memory anchor, or None."""
    anchors = tuple(getattr(memory, "anchors", ()) or ())
    if not anchors:
        return None
    a = max(anchors, key=lambda a: int(a.id))
    K = getattr(a, "intrinsics", None)
    if K is None:
        return None
    return float(np.asarray(a.T_world_cam)[2, 3]), 2.0 * math.atan2(K.height / 2.0, K.fy)


def furniture_boxes(memory: Any, object_id: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """The (lo, hi) 3D boxes of every memory object but ``object_id``: see-through for the line
    of sight past walls (``wall_clear``), as the 2D map draws furniture as opaque as walls."""
    return [(np.asarray(o.box_min), np.asarray(o.box_max)) for o in getattr(memory, "objects", ())
            if int(o.id) != int(object_id)]


def wall_heights(memory: Any, top: float) -> tuple[float, float] | None:
    """``wall_clear``'s heights: (camera height, the object's ``top``), or None without a camera."""
    camera = camera_of(memory)
    return None if camera is None else (camera[0], float(top))


def in_margin(grid: Any, robot_xy: np.ndarray) -> bool:
    """The robot's own cell lies in the map's inflation margin (or on its lethal layer, which the
    map's phase grows past the robot in a narrow passage): it stands in a passage only its radius
    clears."""
    if grid is None:
        return False
    res, origin = float(grid.resolution), np.asarray(grid.origin, dtype=np.float64)
    r, c = int((robot_xy[1] - origin[1]) / res), int((robot_xy[0] - origin[0]) / res)
    inflated = np.asarray(grid.inflated)
    if not (0 <= r < inflated.shape[0] and 0 <= c < inflated.shape[1]):
        return False
    return bool(inflated[r, c])


def cell_near(grid: Any, box_min: np.ndarray, box_max: np.ndarray, robot_xy: np.ndarray, distance: float,
              excluded: list[np.ndarray] | None, **rules: Any) -> np.ndarray | None:
    """A free cell within ``distance`` of the box's footprint (world xy), by ``approach_cell``
    under ``rules`` (its keyword arguments), tight first where the robot stands in a margin, then
    roomy, then tight; None when no search finds one."""
    cell = None
    if in_margin(grid, robot_xy):
        cell = approach_cell(grid, box_min, box_max, robot_xy, distance, excluded, tight=True, prefer_roomy=False,
                             **rules)
    if cell is None:
        cell = approach_cell(grid, box_min, box_max, robot_xy, distance, excluded, **rules)
    if cell is None:
        cell = approach_cell(grid, box_min, box_max, robot_xy, distance, excluded, tight=True, **rules)
    return cell


__all__ = ["camera_of", "cell_near", "furniture_boxes", "in_margin", "wall_heights"]
