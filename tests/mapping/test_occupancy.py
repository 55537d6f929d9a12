"""hiconav.mapping.OccupancyGrid: free / occupied / unknown from depth, inflation, growth, bad input."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from hiconav.errors import FrameError
from hiconav.geometry import pixel_rays
from hiconav.mapping import FREE, OCCUPIED, UNKNOWN, OccupancyConfig, OccupancyGrid
from hiconav.mapping.occupancy import disk_kernel
from hiconav.types import CameraIntrinsics, Frame, Pose2D, camera_pose_from_base

K = CameraIntrinsics.from_hfov(160, 120, 79.0)


def render_boxes(
    pose: Pose2D, boxes: list[tuple[tuple, tuple]], max_depth: float = 5.0, K: CameraIntrinsics = K
) -> Frame:
    """Analytic depth of a floor (z = 0) and axis-aligned boxes (min xyz, max xyz); 0 beyond max_depth."""
    T = camera_pose_from_base(pose, 0.88)
    xr, yr = pixel_rays(K)
    rays = np.stack([xr, yr, np.ones_like(xr)], -1).astype(np.float64) @ T[:3, :3].T  # z_cam = 1
    o = T[:3, 3]
    t = np.full(xr.shape, np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        tf = np.where(rays[..., 2] < 0, -o[2] / rays[..., 2], np.inf)
        t = np.minimum(t, tf)
        for lo, hi in boxes:
            lo, hi = np.asarray(lo, float), np.asarray(hi, float)
            t1 = (lo - o) / rays
            t2 = (hi - o) / rays
            tmin = np.nanmax(np.minimum(t1, t2), axis=-1)
            tmax = np.nanmin(np.maximum(t1, t2), axis=-1)
            hit = (tmax >= tmin) & (tmax > 0)
            t = np.where(hit, np.minimum(t, np.maximum(tmin, 0)), t)
    depth = np.where(t <= max_depth, t, 0.0).astype(np.float32)
    return Frame(
        rgb=np.zeros(xr.shape + (3,), np.uint8),
        depth=depth,
        intrinsics=K,
        T_world_cam=T,
        base_pose=pose,
        stamp=0.0,
    )


WALL = ((3.02, -2.0, 0.0), (3.2, 2.0, 2.0))  # a wall 3 m ahead of the origin, facing -x


def cell_state(grid: OccupancyGrid, x: float, y: float) -> int:
    r, c = grid.world_to_cell(np.array([x, y]))
    return int(grid.state[r, c])


def test_wall_ahead_is_occupied_and_floor_before_it_is_free():
    grid = OccupancyGrid(OccupancyConfig(depth_stride=1))
    stats = grid.integrate(render_boxes(Pose2D(0, 0, 0), [WALL]))
    assert stats.n_obstacle_points > 0
    assert cell_state(grid, 3.03, 0.0) == OCCUPIED
    for x in (0.5, 1.5, 2.5, 2.85):
        assert cell_state(grid, x, 0.0) == FREE, x
    assert cell_state(grid, 3.6, 0.0) == UNKNOWN  # behind the wall
    assert cell_state(grid, -1.0, 0.0) == UNKNOWN  # behind the robot
    assert cell_state(grid, 1.0, 3.0) == UNKNOWN  # outside the field of view
    r, c = grid.world_to_cell(np.array([2.9, 0.0]))
    assert grid.inflated[r, c]  # within the robot radius of the wall
    r, c = grid.world_to_cell(np.array([2.5, 0.0]))
    assert not grid.inflated[r, c]
    assert grid.explored[grid.state != UNKNOWN].all() and grid.explored_area_m2 > 2.0


def test_height_band_ignores_low_and_high_things():
    low = ((1.5, -0.3, 0.0), (1.8, 0.3, 0.05))  # a 5 cm rug-like slab: traversable
    high = ((1.5, 0.6, 1.7), (1.8, 1.2, 2.0))  # a shelf above the robot
    grid = OccupancyGrid(OccupancyConfig(depth_stride=1))
    grid.integrate(render_boxes(Pose2D(0, 0, 0), [low, high, WALL]))
    assert cell_state(grid, 1.65, 0.0) == FREE
    assert cell_state(grid, 1.65, 0.9) != OCCUPIED


def test_box_on_the_floor_is_an_obstacle_with_unknown_shadow():
    box = ((2.02, -0.3, 0.0), (2.4, 0.3, 0.6))
    grid = OccupancyGrid(OccupancyConfig(depth_stride=2))
    grid.integrate(render_boxes(Pose2D(0, 0, 0), [box, WALL]))
    assert cell_state(grid, 2.03, 0.0) == OCCUPIED
    assert cell_state(grid, 2.8, 0.0) == UNKNOWN  # hidden behind the box
    assert cell_state(grid, 1.5, 0.0) == FREE


def test_cells_keep_the_height_of_their_highest_obstacle_point():
    """A 0.6 m box keeps its top (a camera at 0.88 m sees over it); a wall that leaves the mapped
    band reads as endless; a cell later seen free forgets its height."""
    box = ((2.02, -0.3, 0.0), (2.4, 0.3, 0.6))
    grid = OccupancyGrid(OccupancyConfig(depth_stride=1))
    grid.integrate(render_boxes(Pose2D(0, 0, 0), [box, WALL]))
    r, c = grid.world_to_cell(np.array([2.05, 0.0]))
    assert 0.5 <= grid.top[r, c] <= 0.61
    r, c = grid.world_to_cell(np.array([3.03, 1.5]))
    assert np.isinf(grid.top[r, c])
    assert grid.top[grid.state == FREE].max() == 0.0
    snap = grid.snapshot()
    assert snap.top.shape == snap.state.shape and not snap.top.flags.writeable
    grid.integrate(render_boxes(Pose2D(0, 0, 0), [WALL]))  # the box is gone
    for _ in range(4):
        grid.integrate(render_boxes(Pose2D(0, 0, 0), [WALL]))
    r, c = grid.world_to_cell(np.array([2.05, 0.0]))
    assert cell_state(grid, 2.05, 0.0) == FREE and grid.top[r, c] == 0.0


def test_nan_inf_zero_negative_depth_never_corrupts_the_map():
    frame = render_boxes(Pose2D(0, 0, 0), [WALL])
    clean = OccupancyGrid(OccupancyConfig(depth_stride=1))
    clean.integrate(frame)
    bad_depth = np.array(frame.depth, copy=True)
    rng = np.random.default_rng(0)
    idx = rng.random(bad_depth.shape) < 0.2
    bad_depth[idx] = rng.choice(np.array([np.nan, np.inf, 0.0, -3.0], np.float32), size=int(idx.sum()))
    noisy = OccupancyGrid(OccupancyConfig(depth_stride=1))
    stats = noisy.integrate(
        Frame(
            rgb=frame.rgb,
            depth=bad_depth,
            intrinsics=K,
            T_world_cam=frame.T_world_cam,
            base_pose=frame.base_pose,
            stamp=0.0,
        )
    )
    assert stats.n_invalid >= int(idx.sum())
    assert noisy.n_invalid_total == stats.n_invalid
    # nothing becomes free or occupied that the clean frame did not make so
    assert not np.any((noisy.state == FREE) & (clean.state != FREE))
    assert not np.any((noisy.state == OCCUPIED) & (clean.state != OCCUPIED))
    assert cell_state(noisy, 3.03, 0.0) == OCCUPIED


def test_all_invalid_frame_changes_nothing_but_the_footprint():
    frame = render_boxes(Pose2D(0, 0, 0), [WALL])
    grid = OccupancyGrid()
    grid.integrate(frame)
    before = grid.state.copy()
    nan = np.full_like(np.asarray(frame.depth), np.nan)
    grid.integrate(
        Frame(
            rgb=frame.rgb,
            depth=nan,
            intrinsics=K,
            T_world_cam=frame.T_world_cam,
            base_pose=frame.base_pose,
            stamp=1.0,
        )
    )
    np.testing.assert_array_equal(grid.state, before)


@pytest.mark.parametrize("case", ["shape", "pose", "base_pose", "nonfinite"])
def test_bad_frames_are_rejected_and_leave_the_map_untouched(case):
    frame = render_boxes(Pose2D(0, 0, 0), [WALL])
    grid = OccupancyGrid()
    grid.integrate(frame)
    before = (grid.state.copy(), grid.origin.copy(), grid.version)
    kwargs = dict(
        rgb=frame.rgb,
        depth=frame.depth,
        intrinsics=K,
        T_world_cam=frame.T_world_cam,
        base_pose=frame.base_pose,
        stamp=1.0,
    )
    if case == "shape":
        kwargs["depth"] = np.ones((120, 100), np.float32)
    elif case == "pose":
        kwargs["T_world_cam"] = None
    elif case == "base_pose":
        kwargs["base_pose"] = None
    else:
        kwargs["base_pose"] = Pose2D(float("nan"), 0.0, 0.0)
    with pytest.raises(FrameError):
        grid.integrate(Frame(**kwargs))
    np.testing.assert_array_equal(grid.state, before[0])
    np.testing.assert_array_equal(grid.origin, before[1])
    assert grid.version == before[2]


def test_grid_grows_and_keeps_what_it_knew():
    grid = OccupancyGrid(OccupancyConfig(initial_size_m=4.0, grow_padding_m=1.0))
    grid.integrate(render_boxes(Pose2D(0, 0, 0), [WALL]))
    shape0 = grid.shape
    assert cell_state(grid, 3.03, 0.0) == OCCUPIED
    far_wall = ((20.02, -2.0, 0.0), (20.2, 2.0, 2.0))
    stats = grid.integrate(render_boxes(Pose2D(17.0, 0.0, 0.0), [far_wall]))
    assert stats.grew and grid.shape[1] > shape0[1]
    assert cell_state(grid, 3.03, 0.0) == OCCUPIED  # old knowledge moved with the origin
    assert cell_state(grid, 20.03, 0.0) == OCCUPIED
    # the origin stays on the global lattice of cells
    assert np.allclose(grid.origin / grid.resolution, np.round(grid.origin / grid.resolution))


def test_world_cell_round_trip_and_snapshot_is_read_only():
    grid = OccupancyGrid()
    grid.integrate(render_boxes(Pose2D(0.3, -0.2, 0.5), [WALL]))
    rc = np.array([[10, 20], [5, 7]])
    np.testing.assert_array_equal(grid.world_to_cell(grid.cell_to_world(rc)), rc)
    snap = grid.snapshot()
    assert not snap.state.flags.writeable and not snap.inflated.flags.writeable
    np.testing.assert_array_equal(snap.state, grid.state)
    np.testing.assert_array_equal(
        snap.world_to_cell(np.array([1.0, 2.0])), grid.world_to_cell(np.array([1.0, 2.0]))
    )
    assert snap.version == grid.version == 1


def test_robot_footprint_is_free():
    grid = OccupancyGrid()
    grid.integrate(render_boxes(Pose2D(0.0, 0.0, 0.0), [WALL]))
    assert cell_state(grid, 0.0, 0.0) == FREE
    assert cell_state(grid, -0.1, 0.0) == FREE


def test_obstacle_closer_than_min_depth_stops_clearing():
    # a box 0.3 m ahead reads 0 (closer than the camera's 0.5 m): nothing behind it may become free
    box = ((0.3, -0.4, 0.0), (0.6, 0.4, 1.2))
    frame = render_boxes(Pose2D(0, 0, 0), [box, WALL])
    depth = np.array(frame.depth)
    depth[depth < 0.5] = 0.0
    grid = OccupancyGrid(OccupancyConfig(depth_stride=1))
    grid.integrate(
        Frame(
            rgb=frame.rgb,
            depth=depth,
            intrinsics=K,
            T_world_cam=frame.T_world_cam,
            base_pose=frame.base_pose,
            stamp=0.0,
        )
    )
    for x in (0.35, 0.45, 0.55, 1.0):
        assert cell_state(grid, x, 0.0) != FREE, x


def test_lethal_layer_is_the_robot_radius_alone_and_travels_with_snapshots():
    """``lethal`` (robot radius) lies inside ``inflated`` (radius + margin) and equals the full-grid
    dilation whatever the order of frames and growth; snapshots carry it read-only."""
    grid = OccupancyGrid(OccupancyConfig(initial_size_m=4.0, grow_padding_m=1.0))
    grid.integrate(render_boxes(Pose2D(0, 0, 0), [WALL]))
    grid.integrate(render_boxes(Pose2D(17.0, 0.0, 0.0), [((20.02, -2.0, 0.0), (20.2, 2.0, 2.0))]))
    c = grid.config
    occ = (grid.state == OCCUPIED).astype(np.uint8)
    expected = cv2.dilate(occ, disk_kernel(c.robot_radius / c.resolution - c.obstacle_pad)).astype(bool)
    np.testing.assert_array_equal(grid.lethal, expected)
    assert (grid.inflated | ~grid.lethal).all() and (grid.inflated & ~grid.lethal).any()
    r, c2 = grid.world_to_cell(np.array([2.76, 0.0]))  # 0.26 m from the wall: inside the margin only
    assert grid.inflated[r, c2] and not grid.lethal[r, c2]
    snap = grid.snapshot()
    np.testing.assert_array_equal(snap.lethal, grid.lethal)
    assert not snap.lethal.flags.writeable


@pytest.mark.parametrize("jump_m", [1e6, 400.0])
def test_a_pose_far_off_the_map_is_refused_instead_of_growing_the_grid(jump_m):
    """A localisation jump must not make the grid allocate (1e6 m at 0.05 m: 364 TiB)."""
    grid = OccupancyGrid()
    grid.integrate(render_boxes(Pose2D(0, 0, 0), [WALL]))
    before = (grid.state.copy(), grid.origin.copy(), grid.version, grid.n_invalid_total)
    with pytest.raises(FrameError, match="max_extent_m") as e:
        grid.integrate(render_boxes(Pose2D(jump_m, 0, 0), []))
    assert e.value.field == "frame.T_world_cam"
    assert grid.n_refused_total == 1
    np.testing.assert_array_equal(grid.state, before[0])
    np.testing.assert_array_equal(grid.origin, before[1])
    assert (grid.version, grid.n_invalid_total) == before[2:]


def test_the_grid_grows_up_to_its_max_extent():
    grid = OccupancyGrid(OccupancyConfig(initial_size_m=12.0, grow_padding_m=4.0, max_extent_m=40.0))
    grid.integrate(render_boxes(Pose2D(0, 0, 0), [WALL]))
    grid.integrate(render_boxes(Pose2D(20.0, 0, 0), []))  # x from -6 m to 20 + 5.1 + 4 m: 35.1 m wide
    assert grid.shape[1] * grid.resolution <= 40.0
    with pytest.raises(FrameError, match="max_extent_m"):
        grid.integrate(render_boxes(Pose2D(40.0, 0, 0), []))


def test_max_extent_below_the_first_grid_is_a_config_error():
    with pytest.raises(ValueError, match="initial_size_m"):
        OccupancyConfig(initial_size_m=12.0, max_extent_m=10.0)


def test_the_squeeze_mask_opens_a_corridor_between_thick_obstacles():
    """One cell thinner than the lethal layer, measured from the occupied cells: eroding the
    lethal layer instead freed only its outer shell, and a corridor whose lethal bands overlap
    from both sides (6 cells between two thick blocks, lethal radius 3.1 cells) stayed closed."""
    from corridors import snapshot

    from hiconav.mapping.occupancy import squeeze_mask

    def grid(width: int):
        s = np.zeros((40, 60), np.int8)
        s[:, 20:40] = 1
        s[17:17 + width, 20:40] = 0
        return snapshot(s)

    wide, narrow = grid(6), grid(4)
    assert wide.lethal[17:23, 20:40].all()  # the lethal layer closes the corridor
    sq = squeeze_mask(wide)
    assert not sq[19:21, 20:40].any() and sq[17, 20:40].all()  # its middle two rows open
    assert sq[wide.state == OCCUPIED].all() and not (sq & ~wide.lethal).any()  # only lethal cells freed
    assert squeeze_mask(narrow)[17:21, 20:40].all()  # two cells too narrow: closed
