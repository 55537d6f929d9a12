"""hiconav.geometry: back-projection, voxels, boxes, lines and ray casting."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiconav.errors import FrameError
from hiconav.geometry import (
    aabb,
    backproject,
    bresenham,
    iou3d_aabb,
    ray_cast_grid,
    voxel_downsample,
    voxel_iou,
)
from hiconav.types import CameraIntrinsics, Pose2D, camera_pose_from_base

K = CameraIntrinsics.from_hfov(64, 48, 79.0)


def test_backprojected_point_projects_back_to_its_pixel():
    rng = np.random.default_rng(0)
    depth = rng.uniform(0.5, 4.0, (48, 64)).astype(np.float32)
    T = camera_pose_from_base(Pose2D(1.0, -2.0, 0.7), 0.88, tilt=-0.3)
    pts, n_bad = backproject(depth, K, T)
    assert n_bad == 0 and pts.shape == (48 * 64, 3) and pts.dtype == np.float32
    # world -> camera -> pixel
    cam = (pts.astype(np.float64) - T[:3, 3]) @ T[:3, :3]
    uv = cam[:, :2] / cam[:, 2:3] * [K.fx, K.fy] + [K.cx, K.cy]
    vv, uu = np.mgrid[0:48, 0:64]
    np.testing.assert_allclose(uv, np.stack([uu.ravel(), vv.ravel()], 1), atol=1e-3)
    np.testing.assert_allclose(cam[:, 2], depth.ravel(), rtol=1e-5)


def test_forward_camera_puts_points_in_front_of_the_robot():
    depth = np.full((48, 64), 2.0, np.float32)
    T = camera_pose_from_base(Pose2D(0.0, 0.0, math.pi / 2), 0.88)  # facing +y
    pts, _ = backproject(depth, K, T)
    assert np.allclose(pts[:, 1], 2.0, atol=1e-5)
    centre = pts[24 * 64 + 32]
    assert abs(centre[0]) < 0.05 and abs(centre[2] - 0.88) < 0.05


def test_invalid_depth_is_ignored_and_counted():
    depth = np.full((48, 64), 2.0, np.float32)
    depth[0, :4] = [np.nan, np.inf, 0.0, -1.0]
    depth[1, 0] = 0.05  # below min_depth
    depth[1, 1] = 9.0  # beyond max_depth
    pts, n_bad = backproject(depth, K, np.eye(4), min_depth=0.1, max_depth=5.0)
    assert n_bad == 6 and pts.shape[0] == 48 * 64 - 6
    assert np.all(np.isfinite(pts))


def test_stride_and_mask():
    depth = np.full((48, 64), 1.0, np.float32)
    pts, n_bad = backproject(depth, K, np.eye(4), stride=4)
    assert pts.shape[0] == 12 * 16 and n_bad == 0
    mask = np.zeros((48, 64), bool)
    mask[10:20, 10:30] = True
    depth[12, 12] = np.nan
    pts, n_bad = backproject(depth, K, np.eye(4), mask=mask)
    assert pts.shape[0] == 10 * 20 - 1 and n_bad == 1


@pytest.mark.parametrize("shape", [(48, 63), (48, 64, 1), (10,)])
def test_wrong_depth_shape_is_a_frame_error(shape):
    with pytest.raises(FrameError, match="depth"):
        backproject(np.ones(shape, np.float32), K, np.eye(4))


def test_missing_or_bad_pose_is_a_frame_error():
    with pytest.raises(FrameError, match="T_world_cam"):
        backproject(np.ones((48, 64), np.float32), K, None)  # type: ignore[arg-type]
    T = np.eye(4)
    T[0, 3] = np.nan
    with pytest.raises(FrameError, match="T_world_cam"):
        backproject(np.ones((48, 64), np.float32), K, T)


def test_voxel_downsample_keeps_one_centroid_per_voxel():
    pts = np.array([[0.01, 0.01, 0.01], [0.03, 0.03, 0.03], [0.51, 0.0, 0.0]], np.float32)
    out = voxel_downsample(pts, 0.1)
    assert out.shape == (2, 3)
    np.testing.assert_allclose(sorted(out[:, 0]), [0.02, 0.51], atol=1e-6)
    assert voxel_downsample(np.zeros((0, 3)), 0.1).shape == (0, 3)


def test_iou3d_of_boxes():
    assert iou3d_aabb([0, 0, 0], [1, 1, 1], [0, 0, 0], [1, 1, 1]) == pytest.approx(1.0)
    assert iou3d_aabb([0, 0, 0], [1, 1, 1], [0.5, 0, 0], [1.5, 1, 1]) == pytest.approx(1 / 3)
    assert iou3d_aabb([0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]) == 0.0
    lo, hi = aabb(np.array([[0, 1, 2], [3, -1, 0]]))
    assert list(lo) == [0, -1, 0] and list(hi) == [3, 1, 2]


def test_voxel_iou():
    a = np.random.default_rng(0).uniform(0, 1, (500, 3))
    assert voxel_iou(a, a, 0.1) == pytest.approx(1.0)
    assert voxel_iou(a, a + 5.0, 0.1) == 0.0


def test_bresenham_matches_endpoints_and_is_connected():
    cells = bresenham(2, 3, 9, -4)
    assert tuple(cells[0]) == (2, 3) and tuple(cells[-1]) == (9, -4)
    assert np.all(np.abs(np.diff(cells, axis=0)).max(axis=1) == 1)


def test_ray_cast_grid_stops_at_walls():
    blocked = np.zeros((50, 50), bool)
    blocked[:, 40] = True  # wall at col 40
    d = ray_cast_grid(blocked, (25.5, 10.5), np.array([0.0, math.pi, math.pi / 2]), 100)
    assert d[0] == pytest.approx(29.5, abs=0.6)  # +x hits the wall
    assert d[1] == pytest.approx(10.5, abs=0.6)  # -x leaves the grid
    assert d[2] == pytest.approx(24.5, abs=0.6)  # +y (rows) leaves the grid
