"""Geometry of the fast layer: depth back-projection, voxels, 3D boxes and ray casting on grids.

Everything here is vectorised numpy (and cv2 where it is faster); it is pure, synchronous and
stateless apart from a small cache of per-camera pixel rays. It must not know about maps,
memory or the simulator: it turns arrays into arrays.

Conventions (see hiconav/types.py): depth is (H, W) float32 metres along the optical axis,
camera frame is OpenCV (x right, y down, z forward), ``T_world_cam`` (4, 4) maps camera points
to the world (x east, y north, z up). Grids index (row i, col j) with
x = ox + (j + 0.5) * res and y = oy + (i + 0.5) * res.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from hiconav.errors import FrameError
from hiconav.types import CameraIntrinsics

__all__ = [
    "aabb",
    "backproject",
    "bresenham",
    "iou3d_aabb",
    "pixel_rays",
    "ray_cast_grid",
    "validate_depth",
    "voxel_downsample",
    "voxel_iou",
]


@functools.lru_cache(maxsize=16)
def _pixel_rays_cached(
    width: int, height: int, fx: float, fy: float, cx: float, cy: float, stride: int
) -> tuple[np.ndarray, np.ndarray]:
    u = np.arange(0, width, stride, dtype=np.float32)
    v = np.arange(0, height, stride, dtype=np.float32)
    # pixel centres: OpenCV puts pixel (u, v) at continuous coordinate u (integer at the centre)
    xr = ((u - cx) / fx).astype(np.float32)
    yr = ((v - cy) / fy).astype(np.float32)
    xx = np.broadcast_to(xr[None, :], (v.size, u.size)).copy()
    yy = np.broadcast_to(yr[:, None], (v.size, u.size)).copy()
    xx.flags.writeable = False
    yy.flags.writeable = False
    return xx, yy


def pixel_rays(intrinsics: CameraIntrinsics, stride: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Normalised camera rays of the (strided) pixel grid.

    Returns ``(x, y)``, each (ceil(H/stride), ceil(W/stride)) float32 read-only, such that the
    camera-frame point of pixel (v, u) at depth d is (x * d, y * d, d).
    """
    k = intrinsics
    return _pixel_rays_cached(
        int(k.width), int(k.height), float(k.fx), float(k.fy), float(k.cx), float(k.cy), int(stride)
    )


def validate_depth(
    depth: np.ndarray, intrinsics: CameraIntrinsics, T_world_cam: np.ndarray | None, *, where: str = "frame"
) -> np.ndarray:
    """Check a depth image and camera pose; return the depth as float32 (no copy when possible).

    Raises ``FrameError`` naming the field when the depth is not (H, W) matching the intrinsics,
    or when the pose is missing, not (4, 4) or not finite.
    """
    depth = np.asarray(depth)
    expected = (int(intrinsics.height), int(intrinsics.width))
    if depth.ndim != 2 or depth.shape != expected:
        raise FrameError(
            f"depth has shape {depth.shape}, expected (H, W) = {expected} from the camera intrinsics",
            field=f"{where}.depth",
        )
    if not np.issubdtype(depth.dtype, np.floating):
        raise FrameError(f"depth has dtype {depth.dtype}, expected float metres", field=f"{where}.depth")
    if T_world_cam is None:
        raise FrameError("frame has no camera pose (T_world_cam is None)", field=f"{where}.T_world_cam")
    T = np.asarray(T_world_cam)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise FrameError(
            f"T_world_cam must be a finite (4, 4) matrix, got shape {T.shape}", field=f"{where}.T_world_cam"
        )
    return depth.astype(np.float32, copy=False)


def backproject(
    depth: np.ndarray,
    intrinsics: CameraIntrinsics,
    T_world_cam: np.ndarray,
    *,
    stride: int = 1,
    mask: np.ndarray | None = None,
    min_depth: float = 0.1,
    max_depth: float = math.inf,
) -> tuple[np.ndarray, int]:
    """Back-project depth pixels into world-frame points.

    depth: (H, W) float metres along the optical axis; T_world_cam: (4, 4) camera-to-world;
    stride: take every ``stride``-th pixel in both directions; mask: optional (H, W) bool, only
    pixels where it is True are used. Pixels that are NaN, inf, <= 0, < ``min_depth`` or
    > ``max_depth`` are ignored and counted.

    Returns ``(points, n_invalid)``: points (N, 3) float32 in the world frame (rows in
    row-major pixel order), and the number of sampled (and masked-in) pixels that were ignored.
    """
    if stride < 1:
        raise ValueError(f"stride must be >= 1, got {stride}")
    depth = validate_depth(depth, intrinsics, T_world_cam)
    d = depth[::stride, ::stride]
    xr, yr = pixel_rays(intrinsics, stride)
    with np.errstate(invalid="ignore"):
        valid = (d >= max(min_depth, 0.0)) & (d <= max_depth) & (d > 0.0)  # NaN compares False
    if math.isinf(max_depth):
        valid &= np.isfinite(d)
    if mask is not None:
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != depth.shape:
            raise FrameError(f"mask has shape {mask.shape}, expected {depth.shape}", field="mask")
        m = mask[::stride, ::stride]
        n_invalid = int(np.count_nonzero(m & ~valid))
        valid &= m
    else:
        n_invalid = int(valid.size - np.count_nonzero(valid))
    z = d[valid]
    pts_cam = np.empty((z.size, 3), dtype=np.float32)
    pts_cam[:, 0] = xr[valid] * z
    pts_cam[:, 1] = yr[valid] * z
    pts_cam[:, 2] = z
    T = np.asarray(T_world_cam, dtype=np.float32)
    points = pts_cam @ T[:3, :3].T
    points += T[:3, 3]
    return points, n_invalid


def voxel_downsample(points: np.ndarray, voxel: float) -> np.ndarray:
    """Replace the points in each cubic voxel of side ``voxel`` (m) by their centroid.

    points: (N, 3) float; returns (M, 3) float32, M <= N, sorted by voxel key.
    """
    points = np.asarray(points, dtype=np.float32)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points must be (N, 3), got {points.shape}")
    if voxel <= 0:
        raise ValueError(f"voxel must be > 0, got {voxel}")
    if points.shape[0] == 0:
        return points.reshape(0, 3)
    keys = np.floor(points / voxel).astype(np.int64)
    keys -= keys.min(axis=0)
    span = keys.max(axis=0) + 1
    flat = (keys[:, 0] * span[1] + keys[:, 1]) * span[2] + keys[:, 2]
    _, inverse, counts = np.unique(flat, return_inverse=True, return_counts=True)
    out = np.empty((counts.size, 3), dtype=np.float64)
    for k in range(3):
        out[:, k] = np.bincount(inverse, weights=points[:, k], minlength=counts.size)
    out /= counts[:, None]
    return out.astype(np.float32)


def footprint_distance(box_min: np.ndarray, box_max: np.ndarray, xy: np.ndarray) -> float:
    """Planar distance (m) from ``xy`` (2,) world to the footprint of the box ``box_min`` /
    ``box_max`` (3,) world; 0 inside it."""
    dx = max(box_min[0] - xy[0], 0.0, xy[0] - box_max[0])
    dy = max(box_min[1] - xy[1], 0.0, xy[1] - box_max[1])
    return math.hypot(dx, dy)


def rounded_box_distance(x: np.ndarray | float, y: np.ndarray | float, box_min: np.ndarray, box_max: np.ndarray,
                         corner_radius: float = 0.0) -> np.ndarray:
    """Planar distance (m) from world points (``x``, ``y``, arrays of one shape) to a box's
    footprint (``box_min`` / ``box_max`` (3,) world, x and y used) with its corners rounded by
    ``corner_radius`` (at most the half of its shorter side); 0 inside. 0: the box's own distance.

    A memory box is axis-aligned around what the camera saw of an object, and most objects are
    not rectangles that fill it: a plant, a round table, a chair's legs, an object turned in the
    room leave its corners empty. Beside a face the box is as near as the object; off a corner,
    on the diagonal, the object lies up to (sqrt(2) - 1) x the radius farther than the box."""
    lo, hi = np.asarray(box_min, dtype=np.float64), np.asarray(box_max, dtype=np.float64)
    cx, cy = 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])
    hx, hy = max(0.5 * (hi[0] - lo[0]), 0.0), max(0.5 * (hi[1] - lo[1]), 0.0)
    r = float(np.clip(corner_radius, 0.0, min(hx, hy)))
    qx = np.maximum(np.abs(np.asarray(x, dtype=np.float64) - cx) - (hx - r), 0.0)
    qy = np.maximum(np.abs(np.asarray(y, dtype=np.float64) - cy) - (hy - r), 0.0)
    return np.maximum(np.hypot(qx, qy) - r, 0.0)


def footprint_gap(a_min: np.ndarray, a_max: np.ndarray, b_min: np.ndarray, b_max: np.ndarray) -> float:
    """Planar distance (m) between the footprints of two axis-aligned boxes (3,) world; 0 when
    they overlap in plan."""
    dx = max(b_min[0] - a_max[0], a_min[0] - b_max[0], 0.0)
    dy = max(b_min[1] - a_max[1], a_min[1] - b_max[1], 0.0)
    return math.hypot(dx, dy)


def centre_in_footprint(a_min: np.ndarray, a_max: np.ndarray, b_min: np.ndarray, b_max: np.ndarray,
                        pad: float = 0.0) -> bool:
    """Whether the centre of box a's footprint lies in box b's footprint grown by ``pad`` m (both
    axis-aligned boxes (3,) world, x and y used)."""
    cx, cy = 0.5 * (float(a_min[0]) + float(a_max[0])), 0.5 * (float(a_min[1]) + float(a_max[1]))
    return (float(b_min[0]) - pad <= cx <= float(b_max[0]) + pad
            and float(b_min[1]) - pad <= cy <= float(b_max[1]) + pad)


def aabb(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned bounding box (min (3,), max (3,)) of (N, 3) points, N >= 1."""
    points = np.asarray(points)
    if points.ndim != 2 or points.shape[0] == 0:
        raise ValueError(f"aabb needs (N, 3) points with N >= 1, got {points.shape}")
    return points.min(axis=0), points.max(axis=0)


def iou3d_aabb(min_a: np.ndarray, max_a: np.ndarray, min_b: np.ndarray, max_b: np.ndarray) -> float:
    """Intersection over union of two axis-aligned 3D boxes given by their corners (3,)."""
    min_a, max_a = np.asarray(min_a, float), np.asarray(max_a, float)
    min_b, max_b = np.asarray(min_b, float), np.asarray(max_b, float)
    inter_ext = np.clip(np.minimum(max_a, max_b) - np.maximum(min_a, min_b), 0.0, None)
    inter = float(np.prod(inter_ext))
    vol_a = float(np.prod(np.clip(max_a - min_a, 0.0, None)))
    vol_b = float(np.prod(np.clip(max_b - min_b, 0.0, None)))
    union = vol_a + vol_b - inter
    return inter / union if union > 0.0 else 0.0


def voxel_iou(points_a: np.ndarray, points_b: np.ndarray, voxel: float) -> float:
    """IoU of the sets of ``voxel``-sized cubes occupied by two point clouds (N, 3) and (M, 3)."""
    if len(points_a) == 0 or len(points_b) == 0:
        return 0.0
    ka = np.unique(np.floor(np.asarray(points_a) / voxel).astype(np.int64), axis=0)
    kb = np.unique(np.floor(np.asarray(points_b) / voxel).astype(np.int64), axis=0)
    both = np.concatenate([ka, kb])
    n_union = np.unique(both, axis=0).shape[0]
    n_inter = ka.shape[0] + kb.shape[0] - n_union
    return n_inter / n_union


def bresenham(r0: int, c0: int, r1: int, c1: int) -> np.ndarray:
    """Grid cells (N, 2) int (row, col) on the line from (r0, c0) to (r1, c1), both included.

    Vectorised: samples the dominant axis once per cell, so the result equals Bresenham's line.
    """
    dr, dc = r1 - r0, c1 - c0
    n = max(abs(dr), abs(dc))
    if n == 0:
        return np.array([[r0, c0]], dtype=np.int64)
    t = np.arange(n + 1, dtype=np.float64) / n
    rows = np.floor(r0 + dr * t + 0.5).astype(np.int64)
    cols = np.floor(c0 + dc * t + 0.5).astype(np.int64)
    return np.stack([rows, cols], axis=1)


def ray_cast_grid(
    blocked: np.ndarray,
    start_rc: tuple[float, float],
    angles: np.ndarray,
    max_range_cells: float,
    step: float = 0.5,
) -> np.ndarray:
    """Distance (in cells) from ``start_rc`` along each angle to the first blocked cell.

    blocked: (H, W) bool (True stops a ray; leaving the grid stops it too); start_rc: (row, col)
    continuous cell coordinates; angles: (A,) radians in the world frame (0 = +x = +col,
    pi/2 = +y = +row). Returns (A,) float distances, ``max_range_cells`` where nothing was hit.
    Used for the openness term of frontier costs.
    """
    blocked = np.asarray(blocked, dtype=bool)
    angles = np.asarray(angles, dtype=np.float64).reshape(-1)
    ts = np.arange(0.0, max_range_cells + step, step)
    rows = start_rc[0] + np.sin(angles)[:, None] * ts[None, :]
    cols = start_rc[1] + np.cos(angles)[:, None] * ts[None, :]
    ri = np.floor(rows).astype(np.int64)
    ci = np.floor(cols).astype(np.int64)
    h, w = blocked.shape
    outside = (ri < 0) | (ri >= h) | (ci < 0) | (ci >= w)
    hit = outside.copy()
    inside = ~outside
    hit[inside] = blocked[ri[inside], ci[inside]]
    any_hit = hit.any(axis=1)
    first = np.argmax(hit, axis=1)
    dist = np.where(any_hit, ts[first], max_range_cells)
    return np.minimum(dist, max_range_cells)


class GridFrame:
    """Mixin: world <-> cell conversions for a grid with ``origin`` (2,), ``resolution`` and ``shape``.

    Cell (row i, col j) covers x in [ox + j*res, ox + (j+1)*res) and y in [oy + i*res, ...): the
    convention of every grid in the project (the simulator's navigable map, the occupancy grid).
    """

    origin: np.ndarray
    resolution: float

    def world_to_cell(self, xy: np.ndarray) -> np.ndarray:
        """World xy (..., 2) metres -> int (..., 2) cells (row, col); may be outside the grid."""
        xy = np.asarray(xy, dtype=np.float64)
        col = np.floor((xy[..., 0] - self.origin[0]) / self.resolution)
        row = np.floor((xy[..., 1] - self.origin[1]) / self.resolution)
        return np.stack([row, col], axis=-1).astype(np.int64)

    def cell_to_world(self, rc: np.ndarray) -> np.ndarray:
        """Cells (..., 2) (row, col) -> world xy (..., 2) of the cell centres."""
        rc = np.asarray(rc, dtype=np.float64)
        x = self.origin[0] + (rc[..., 1] + 0.5) * self.resolution
        y = self.origin[1] + (rc[..., 0] + 0.5) * self.resolution
        return np.stack([x, y], axis=-1)

    def in_bounds(self, rc: np.ndarray) -> np.ndarray:
        """(...,) bool: the cells lie inside the grid."""
        rc = np.asarray(rc)
        h, w = self.shape  # type: ignore[attr-defined]
        return (rc[..., 0] >= 0) & (rc[..., 0] < h) & (rc[..., 1] >= 0) & (rc[..., 1] < w)
