"""Synthetic RGB-D views of axis-aligned boxes for the memory-graph tests.

Ray-casts boxes (slab method) from a robot pose with the project's camera conventions
(``camera_pose_from_base``), and turns each visible box into a Detection with its mask. Exact
geometry, no simulator, so the merge tests depend only on the memory code.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hiconav.types import CameraIntrinsics, Detection, Frame, Pose2D, camera_pose_from_base

INTR = CameraIntrinsics.from_hfov(320, 240, 79.0)
CAM_HEIGHT = 0.88


@dataclass(frozen=True)
class Box:
    label: str
    center: tuple[float, float, float]
    size: tuple[float, float, float]


def chair(x: float, y: float, label: str = "chair") -> Box:
    return Box(label, (x, y, 0.45), (0.5, 0.5, 0.9))


def look_at(x: float, y: float, tx: float, ty: float) -> Pose2D:
    return Pose2D(x, y, math.atan2(ty - y, tx - x))


def render(pose: Pose2D, boxes: list[Box], *, stamp: float = 0.0, seq: int = 0,
           far: float = 20.0) -> Frame:
    """Frame (rgb, depth along the optical axis, instances = box index or -1) seen from ``pose``.

    The floor (z = 0) is rendered too, so masks and depth look like a real view.
    """
    T = camera_pose_from_base(pose, CAM_HEIGHT)
    u, v = np.meshgrid(np.arange(INTR.width), np.arange(INTR.height))
    rays_cam = np.stack([(u - INTR.cx) / INTR.fx, (v - INTR.cy) / INTR.fy, np.ones_like(u, float)], -1)
    dirs = rays_cam @ T[:3, :3].T  # world directions with unit optical-axis component
    origin = T[:3, 3]
    t_best = np.full(u.shape, np.inf)
    inst = np.full(u.shape, -1, np.int32)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_floor = np.where(dirs[..., 2] < 0, -origin[2] / dirs[..., 2], np.inf)
        t_best = np.minimum(t_best, t_floor)
        for k, b in enumerate(boxes):
            lo = np.array(b.center) - np.array(b.size) / 2
            hi = np.array(b.center) + np.array(b.size) / 2
            t1 = (lo - origin) / dirs
            t2 = (hi - origin) / dirs
            tmin = np.nanmax(np.minimum(t1, t2), axis=-1)
            tmax = np.nanmin(np.maximum(t1, t2), axis=-1)
            hit = (tmax >= tmin) & (tmin > 0) & (tmin < t_best)
            t_best = np.where(hit, tmin, t_best)
            inst = np.where(hit, k, inst)
    depth = np.where(np.isfinite(t_best) & (t_best < far), t_best, 0.0).astype(np.float32)
    rgb = np.zeros((INTR.height, INTR.width, 3), np.uint8)
    rgb[..., 1] = 120
    for k in range(len(boxes)):
        rgb[inst == k] = (40 + 50 * k % 200, 90, 200)
    return Frame(rgb, depth, INTR, T, pose, stamp, inst, seq)


def detect(frame: Frame, boxes: list[Box], *, score: float = 0.9) -> list[Detection]:
    """One detection per visible box (mask from the instance channel)."""
    out = []
    inst = np.asarray(frame.instances)
    for k, b in enumerate(boxes):
        mask = inst == k
        if mask.sum() < 30:
            continue
        rows, cols = np.nonzero(mask)
        box = np.array([cols.min(), rows.min(), cols.max(), rows.max()], np.float32)
        out.append(Detection(b.label, score, box, mask, None, "synthetic", k))
    return out
