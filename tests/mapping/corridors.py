"""A room whose only way on is a corridor the lethal layer closes: the squeeze fallback's scene.

Imported as a plain module by the mapping and exploration tests (they put this folder on sys.path)."""

from __future__ import annotations

import cv2
import numpy as np

from hiconav.mapping import GridSnapshot
from hiconav.mapping.occupancy import disk_kernel

RES = 0.05


def corridor_grid(width: int) -> GridSnapshot:
    """A closed room (rows 10..49, cols 10..39, 5-cell walls; x 0.5-2.0 m) whose east wall is a
    2.5 m thick block with a corridor ``width`` cells wide (rows 27.., y 1.35 m) into a free area
    seen beyond it (cols 90..104, unknown past them: its frontier lies farther than
    ``viewpoint_search_m`` from the room). Lethal layer: the robot radius (3.1 cells), which
    closes any corridor up to 7 cells wide; one cell thinner it opens 6; inflation 4.6 cells."""
    s = np.full((60, 120), -1, np.int8)
    s[5:55, 5:45] = 1
    s[10:50, 10:40] = 0
    s[5:55, 40:90] = 1
    s[27:27 + width, 40:90] = 0
    s[15:45, 90:105] = 0
    return snapshot(s)


def snapshot(state: np.ndarray) -> GridSnapshot:
    """A grid snapshot of ``state`` with the lethal (3.1 cells) and inflated (4.6 cells) layers."""
    occ = (state == 1).astype(np.uint8)
    return GridSnapshot(state=state, inflated=cv2.dilate(occ, disk_kernel(4.6)).astype(bool),
                        lethal=cv2.dilate(occ, disk_kernel(3.1)).astype(bool), explored=state != -1,
                        origin=np.zeros(2), resolution=RES, version=1, stamp=0.0)
