"""The 2D occupancy grid of the fast layer: free / occupied / unknown from depth, inflation.

Each depth frame is back-projected (every ``depth_stride``-th pixel), split by a height band
relative to the floor into obstacle points and floor/other points, and turned into a
pseudo laser scan: per angular bin around the camera, the nearest obstacle range and the
farthest observed range. The free-space fan (camera -> min(obstacle - margin, farthest)) is
rasterised with cv2.fillPoly (ray clearing), obstacle cells get log-odds hits, and the
obstacles are inflated by the robot radius with cv2.dilate. Only a window around the camera is
touched per frame; the grid grows (re-allocated with padding) when the robot sees past its edge,
never beyond ``max_extent_m`` a side: a frame that would need more (a pose kilometres off) is
refused with a FrameError before anything is allocated.

Two details keep free cells honest (>= 99% navigable in the simulator's ground truth): a pixel
that reads no depth although its ray would meet the floor within range means something closer
than the camera's min depth, so its angular bin is not cleared at all; and an obstacle point
marks every cell within half a cell of it, so a wall lying on a cell boundary marks both sides
whatever the grid's phase.

It must not plan, detect or keep object semantics; it must never let a bad frame corrupt it:
frames are validated before any state changes (FrameError), invalid depth is ignored and
counted.
"""

from __future__ import annotations

import math
import time
from typing import Protocol
from dataclasses import dataclass

import cv2
import numba
import numpy as np

from hiconav.errors import FrameError
from hiconav.geometry import GridFrame, pixel_rays, validate_depth
from hiconav.mapping.config import OccupancyConfig
from hiconav.types import Frame, freeze

__all__ = ["FREE", "OCCUPIED", "UNKNOWN", "GridSnapshot", "IntegrationStats", "OccupancyGrid", "disk_kernel",
           "lethal_mask", "squeeze_mask"]

UNKNOWN, FREE, OCCUPIED = -1, 0, 1


@numba.njit(cache=True, nogil=True)
def _scan_bins(
    bins: np.ndarray,
    ranges: np.ndarray,
    is_obstacle: np.ndarray,
    horizon: float,
    farthest: np.ndarray,
    nearest_obstacle: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Per angular bin: farthest observed range (capped at horizon) and nearest obstacle range."""
    for i in range(bins.shape[0]):
        b = bins[i]
        r = ranges[i]
        rf = min(r, horizon)
        farthest[b] = max(farthest[b], rf)
        if is_obstacle[i] and r < nearest_obstacle[b]:
            nearest_obstacle[b] = r


def disk_kernel(radius_cells: float) -> np.ndarray:
    """(2r+1, 2r+1) uint8 disk of the given radius in cells (centre-to-centre distance <= r)."""
    r = int(math.ceil(radius_cells - 1e-9))
    yy, xx = np.mgrid[-r : r + 1, -r : r + 1]
    return (xx * xx + yy * yy <= radius_cells * radius_cells + 1e-9).astype(np.uint8)


class GridLike(Protocol):
    """What consumers (frontiers, planning, exploration costs) need of an OccupancyGrid / GridSnapshot."""

    state: np.ndarray  # (H, W) int8: -1 unknown, 0 free, 1 occupied
    inflated: np.ndarray  # (H, W) bool: occupied dilated by the robot radius + inflation margin
    lethal: np.ndarray  # (H, W) bool: occupied dilated by the robot radius alone (no margin, less the pad)
    origin: np.ndarray  # (2,) world xy of the corner of cell (0, 0)
    resolution: float  # m per cell

    def world_to_cell(self, xy: np.ndarray) -> np.ndarray: ...
    def cell_to_world(self, rc: np.ndarray) -> np.ndarray: ...


def lethal_mask(grid: GridLike) -> np.ndarray:
    """(H, W) bool cells the robot centre cannot occupy at all (``grid.inflated`` for grid-likes
    without a ``lethal`` layer, e.g. hand-made test grids: then there are no tight passages)."""
    lethal = getattr(grid, "lethal", None)
    return np.asarray(grid.inflated if lethal is None else lethal, dtype=bool)


def squeeze_mask(grid: GridLike) -> np.ndarray:
    """(H, W) bool: the lethal layer one cell thinner (occupied cells grown by the lethal radius
    less one cell), occupied cells kept; it only ever frees lethal cells.

    The map marks an obstacle point on the cells within half a cell of it, so an occupied cell
    reaches 0.5-1.5 cells past the surface depending on where the grid's lines fall, and the
    lethal layer grows that by the robot radius less half a cell: in the scanned Gibson floors a
    passage the robot fits through (0.45 m, robot 0.36 m) lost its last free cell to that phase
    error, and a goal beyond it became unreachable. One cell less leaves the
    robot a few centimetres too close at worst; the simulator slides it along the wall, as a
    bumper-driven robot squeezes through a door.

    The radius is measured on the layer itself (the farthest lethal cell from an occupied one), and
    the thinner layer is grown again from the occupied cells: eroding the lethal layer instead
    frees only its outer shell, so a corridor between two thick obstacles, where both sides'
    lethal bands overlap, stayed closed."""
    lethal = lethal_mask(grid)
    occ = np.asarray(grid.state) == OCCUPIED
    band = lethal & ~occ
    if not occ.any() or not band.any():
        return lethal | occ
    dist = cv2.distanceTransform((~occ).astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    radius = float(dist[band].max())
    return occ | (lethal & (dist <= radius - 1.0 + 1e-3))


class _OccupancyFields(GridFrame):
    """Properties shared by the live grid and its snapshots (both hold state/explored arrays)."""

    state: np.ndarray
    explored: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        return self.state.shape  # type: ignore[return-value]

    @property
    def origin_cells(self) -> np.ndarray:
        """(2,) int (row, col) offset of this grid in the global cell lattice (origin / res)."""
        return np.array(
            [round(self.origin[1] / self.resolution), round(self.origin[0] / self.resolution)], dtype=np.int64
        )

    @property
    def explored_area_m2(self) -> float:
        return float(np.count_nonzero(self.explored)) * self.resolution**2


@dataclass(frozen=True)
class GridSnapshot(_OccupancyFields):
    """Read-only copy of the grid for other actors.

    state: (H, W) int8 (-1 unknown, 0 free, 1 occupied); inflated: (H, W) bool (occupied
    dilated by the robot radius + inflation margin); lethal: (H, W) bool (dilated by the robot
    radius alone: the tight passages only a fallback plan may use; ``inflated`` when not given,
    i.e. no tight passages); explored: (H, W) bool (ever observed); origin: (2,) world xy
    of the corner of cell (0, 0); resolution: m per cell; version: number of integrated frames;
    top: (H, W) float32 or None, metres above the floor of the highest obstacle point seen in
    each cell since it was last seen free (0 where none; inf where the points reach the top of
    the mapped band, as a wall's do; None: heights not kept).
    """

    state: np.ndarray
    inflated: np.ndarray
    explored: np.ndarray
    origin: np.ndarray
    resolution: float
    version: int
    stamp: float
    lethal: np.ndarray | None = None  # type: ignore[assignment]  # filled in __post_init__
    top: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.lethal is None:
            object.__setattr__(self, "lethal", self.inflated)
        for name in ("state", "inflated", "lethal", "explored", "origin", "top"):
            if getattr(self, name) is not None:
                freeze(getattr(self, name))



@dataclass(frozen=True)
class IntegrationStats:
    """What one ``integrate`` call did (for logs and benchmarks)."""

    n_points: int  # valid back-projected points
    n_invalid: int  # sampled depth pixels ignored (NaN, inf, <= 0, out of range)
    n_obstacle_points: int
    n_free_cells: int  # cells inside this frame's free-space fan
    grew: bool
    elapsed_ms: float


class OccupancyGrid(_OccupancyFields):
    """Growing log-odds occupancy grid at ``config.resolution`` m per cell.

    Public attributes (read them, do not write them): state (H, W) int8 (-1 unknown, 0 free,
    1 occupied), inflated (H, W) bool (robot radius + margin), lethal (H, W) bool (robot radius
    only, less the ``obstacle_pad`` the marking already adds: the robot centre cannot be there at
    all), explored (H, W) bool, origin (2,) world xy of the corner of
    cell (0, 0), resolution (m). Cell (i, j) has its centre at x = ox + (j + 0.5) * res,
    y = oy + (i + 0.5) * res.
    """

    def __init__(self, config: OccupancyConfig | None = None) -> None:
        self.config = config or OccupancyConfig()
        self.resolution = float(self.config.resolution)
        self.origin = np.zeros(2, dtype=np.float64)
        self.logodds = np.zeros((0, 0), dtype=np.int8)
        self.state = np.zeros((0, 0), dtype=np.int8)
        self.inflated = np.zeros((0, 0), dtype=bool)
        self.lethal = np.zeros((0, 0), dtype=bool)
        self.explored = np.zeros((0, 0), dtype=bool)
        # metres above the floor of the highest obstacle point in each cell since it was last seen
        # free: the 2D map alone cannot tell a 0.8 m table, which a camera sees over, from a wall
        self.top = np.zeros((0, 0), dtype=np.float32)
        self.version = 0
        self.stamp = 0.0
        self.n_invalid_total = 0
        self.n_refused_total = 0  # frames refused because the grid would outgrow max_extent_m
        c = self.config
        self._inflate_cells = (c.robot_radius + c.inflation_margin) / self.resolution
        self._kernel = disk_kernel(self._inflate_cells)
        # an obstacle point already marks the cells within obstacle_pad cells of it, so marked cells
        # reach that far past the surface: the lethal layer grows them by the rest of the radius only
        self._lethal_kernel = disk_kernel(max(c.robot_radius / self.resolution - c.obstacle_pad, 0.0))
        self._footprint = disk_kernel(0.8 * c.robot_radius / self.resolution).astype(bool)

    # ------------------------------------------------------------------ grid geometry

    def _grown_bounds(self, xmin: float, ymin: float, xmax: float, ymax: float
                      ) -> tuple[float, float, int, int] | None:
        """(origin x, origin y, width, height in cells) of the grid that covers [xmin, xmax] x
        [ymin, ymax]; None when the grid already does."""
        res = self.resolution
        h, w = self.state.shape
        if h > 0:
            gx0, gy0 = self.origin
            gx1, gy1 = gx0 + w * res, gy0 + h * res
            if xmin >= gx0 and ymin >= gy0 and xmax <= gx1 and ymax <= gy1:
                return None
            pad = self.config.grow_padding_m
            nx0 = min(gx0, xmin - pad) if xmin < gx0 else gx0
            ny0 = min(gy0, ymin - pad) if ymin < gy0 else gy0
            nx1 = max(gx1, xmax + pad) if xmax > gx1 else gx1
            ny1 = max(gy1, ymax + pad) if ymax > gy1 else gy1
        else:
            half = self.config.initial_size_m / 2.0
            cx, cy = (xmin + xmax) / 2.0, (ymin + ymax) / 2.0
            nx0, ny0 = min(cx - half, xmin), min(cy - half, ymin)
            nx1, ny1 = max(cx + half, xmax), max(cy + half, ymax)
        # keep the origin on the global lattice (multiples of res) so that cells never shift
        ox = math.floor(nx0 / res + 1e-9) * res
        oy = math.floor(ny0 / res + 1e-9) * res
        # in metres first: a far pose must not overflow the cell count before the extent check
        width_m, height_m = nx1 - ox, ny1 - oy
        limit = self.config.max_extent_m
        if not (width_m <= limit + 1e-6 and height_m <= limit + 1e-6):
            self.n_refused_total += 1
            raise FrameError(
                f"the grid would grow to {width_m:.4g} m x {height_m:.4g} m to reach the camera at "
                f"({(xmin + xmax) / 2.0:.4g}, {(ymin + ymax) / 2.0:.4g}), beyond mapping.occupancy.max_extent_m = "
                f"{limit:g} m: a pose this far from the map is a localisation jump; frame refused, map unchanged",
                field="frame.T_world_cam",
            )
        nw = int(math.ceil(width_m / res - 1e-9))
        nh = int(math.ceil(height_m / res - 1e-9))
        return ox, oy, nw, nh

    def _ensure_bounds(self, xmin: float, ymin: float, xmax: float, ymax: float) -> bool:
        """Grow the grid so that it covers [xmin, xmax] x [ymin, ymax]; True if it grew.

        Raises ``FrameError`` (nothing allocated or changed) when the grid would outgrow
        ``config.max_extent_m``."""
        bounds = self._grown_bounds(xmin, ymin, xmax, ymax)
        if bounds is None:
            return False
        ox, oy, nw, nh = bounds
        res = self.resolution
        h, w = self.state.shape
        logodds = np.zeros((nh, nw), dtype=np.int8)
        explored = np.zeros((nh, nw), dtype=bool)
        top = np.zeros((nh, nw), dtype=np.float32)
        if h > 0:
            r0 = int(round((self.origin[1] - oy) / res))
            c0 = int(round((self.origin[0] - ox) / res))
            logodds[r0 : r0 + h, c0 : c0 + w] = self.logodds
            explored[r0 : r0 + h, c0 : c0 + w] = self.explored
            top[r0 : r0 + h, c0 : c0 + w] = self.top
        self.origin = np.array([ox, oy], dtype=np.float64)
        self.logodds, self.explored, self.top = logodds, explored, top
        self.state = np.where(explored, (logodds > 0).astype(np.int8), np.int8(UNKNOWN)).astype(np.int8)
        occ = (self.state == OCCUPIED).astype(np.uint8)
        self.inflated = cv2.dilate(occ, self._kernel).astype(bool)
        self.lethal = cv2.dilate(occ, self._lethal_kernel).astype(bool)
        return True

    # ------------------------------------------------------------------ integration
    def _validate(self, frame: Frame) -> np.ndarray:
        if frame is None:
            raise FrameError("no frame given", field="frame")
        if frame.intrinsics is None:
            raise FrameError("frame has no camera intrinsics", field="frame.intrinsics")
        if frame.base_pose is None:
            raise FrameError("frame has no base pose", field="frame.base_pose")
        bp = frame.base_pose
        if not all(math.isfinite(v) for v in (bp.x, bp.y, bp.yaw)):
            raise FrameError(f"base pose is not finite: {bp}", field="frame.base_pose")
        if frame.depth is None:
            raise FrameError("frame has no depth image", field="frame.depth")
        return validate_depth(frame.depth, frame.intrinsics, frame.T_world_cam)

    def integrate(self, frame: Frame) -> IntegrationStats:
        """Fuse one RGB-D frame. Raises FrameError (and leaves the map untouched) for bad frames."""
        t0 = time.perf_counter()
        depth = self._validate(frame)
        c = self.config
        res = self.resolution
        stride = c.depth_stride
        T = np.asarray(frame.T_world_cam, dtype=np.float64)
        cam_xy = T[:2, 3].copy()
        # window touched by this frame: the mapping range around the camera; a frame that would make
        # the grid outgrow its bound is refused here, before anything changes
        reach = c.max_depth + 2 * res
        window = (cam_xy[0] - reach, cam_xy[1] - reach, cam_xy[0] + reach, cam_xy[1] + reach)
        self._grown_bounds(*window)
        # classify the strided pixels: valid returns, "far" returns (at the sensor's clip depth:
        # free space, no obstacle) and invalid ones (NaN, inf, <= 0, out of range: ignored, counted)
        far_depth = min(c.max_depth, c.sensor_max_depth) - 1e-3
        d = depth[::stride, ::stride]
        xr, yr = pixel_rays(frame.intrinsics, stride)
        with np.errstate(invalid="ignore"):
            valid = (d >= max(c.min_depth, 1e-6)) & (d < far_depth)
            far = (d >= far_depth) & np.isfinite(d) if c.clear_at_max_range else np.zeros_like(valid)
        invalid = ~(valid | far)
        n_invalid = int(np.count_nonzero(invalid))
        self.n_invalid_total += n_invalid
        R = T[:3, :3]
        t_cam = T[:3, 3]
        z = d[valid]
        xv, yv = xr[valid], yr[valid]
        # world-frame points (N,) float32 per axis (kept as separate contiguous columns: selecting
        # from them is several times cheaper than selecting rows of an (N, 3) array)
        px, py, pz = ((R[k, 0] * xv + R[k, 1] * yv + R[k, 2]) * z + t_cam[k] for k in range(3))
        px, py, pz = px.astype(np.float32), py.astype(np.float32), pz.astype(np.float32)
        xf, yf = xr[far], yr[far]
        fx, fy = ((R[k, 0] * xf + R[k, 1] * yf + R[k, 2]) * c.max_depth + t_cam[k] for k in range(2))
        fx, fy = fx.astype(np.float32), fy.astype(np.float32)

        rel_z = pz - c.floor_z
        is_obs = (rel_z >= c.obstacle_min_height) & (rel_z <= c.obstacle_max_height)
        obs_x, obs_y, obs_z = px[is_obs], py[is_obs], rel_z[is_obs]

        grew = self._ensure_bounds(*window)
        h, w = self.state.shape
        r0 = max(0, int(math.floor((cam_xy[1] - reach - self.origin[1]) / res)))
        c0 = max(0, int(math.floor((cam_xy[0] - reach - self.origin[0]) / res)))
        r1 = min(h, int(math.ceil((cam_xy[1] + reach - self.origin[1]) / res)) + 1)
        c1 = min(w, int(math.ceil((cam_xy[0] + reach - self.origin[0]) / res)) + 1)
        wh, ww = r1 - r0, c1 - c0
        wox = self.origin[0] + c0 * res  # window origin (world)
        woy = self.origin[1] + r0 * res

        # pseudo laser scan in angular bins around the camera
        nbins = int(round(360.0 / c.angle_bin_deg))
        bin_scale = nbins / (2 * math.pi)

        def bins_of(dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
            b = ((np.arctan2(dy, dx) + math.pi) * bin_scale).astype(np.int64)
            return np.clip(b, 0, nbins - 1, out=b)

        dx = (np.concatenate([px, fx]) if fx.size else px) - np.float32(cam_xy[0])
        dy = (np.concatenate([py, fy]) if fy.size else py) - np.float32(cam_xy[1])
        rng_all = np.hypot(dx, dy)
        bin_all = bins_of(dx, dy)
        horizon = min(c.max_depth, reach)
        farthest = np.zeros(nbins, dtype=np.float64)
        nearest_obs = np.full(nbins, np.inf)
        n_pts = px.shape[0]
        obs_flag = np.zeros(rng_all.shape[0], dtype=np.bool_)
        obs_flag[:n_pts] = is_obs
        _scan_bins(bin_all, rng_all, obs_flag, horizon, farthest, nearest_obs)
        # an invalid pixel whose ray would meet the floor within range is something closer than the
        # sensor's min depth (the camera reads 0 there): do not clear that bin at all
        if n_invalid and c.sensor_min_depth > 0:
            xi, yi = xr[invalid], yr[invalid]
            dz = R[2, 0] * xi + R[2, 1] * yi + R[2, 2]
            height = t_cam[2] - c.floor_z
            with np.errstate(divide="ignore", invalid="ignore"):
                t_floor = np.where(dz < -1e-6, height / -dz, np.inf)
            near = t_floor < far_depth
            if near.any():
                ddx = (R[0, 0] * xi + R[0, 1] * yi + R[0, 2])[near]
                ddy = (R[1, 0] * xi + R[1, 1] * yi + R[1, 2])[near]
                # the obstacle may be anywhere closer than the min depth: clear nothing in that bin
                r_near = np.zeros(ddx.shape[0])
                _scan_bins(
                    bins_of(ddx, ddy),
                    r_near,
                    np.ones(r_near.shape[0], dtype=np.bool_),
                    0.0,
                    np.zeros(nbins),
                    nearest_obs,
                )
        radius = np.minimum(farthest, nearest_obs - c.free_margin)
        radius = np.clip(radius, 0.0, None)
        # fill isolated empty bins (angular aliasing of the strided pixels) from their neighbours
        seen = farthest > 0
        # circular neighbours (np.roll(a, 1) / np.roll(a, -1), without its per-call overhead)
        left, right = np.concatenate([radius[-1:], radius[:-1]]), np.concatenate([radius[1:], radius[:1]])
        gap = ~seen & np.concatenate([seen[-1:], seen[:-1]]) & np.concatenate([seen[1:], seen[:1]])
        radius[gap] = np.minimum(left, right)[gap]

        n_free = 0
        fan = np.zeros((wh, ww), dtype=np.uint8)
        active = np.flatnonzero(radius > 0)
        if active.size:
            a0 = active * (2 * math.pi / nbins) - math.pi
            a1 = a0 + 2 * math.pi / nbins
            rr = radius[active]
            px = np.stack([cam_xy[0] + rr * np.cos(a0), cam_xy[0] + rr * np.cos(a1)], axis=1).ravel()
            py = np.stack([cam_xy[1] + rr * np.sin(a0), cam_xy[1] + rr * np.sin(a1)], axis=1).ravel()
            shift = 3
            scale = (1 << shift) / res
            # triangles camera -> (a0, r) -> (a1, r): robust to gaps and non-convex scans
            cx = (cam_xy[0] - wox) * scale - 0.5 * (1 << shift)
            cy = (cam_xy[1] - woy) * scale - 0.5 * (1 << shift)
            tx = (px - wox) * scale - 0.5 * (1 << shift)
            ty = (py - woy) * scale - 0.5 * (1 << shift)
            tri = np.empty((active.size, 3, 2), dtype=np.int32)
            tri[:, 0, 0], tri[:, 0, 1] = int(round(cx)), int(round(cy))
            tri[:, 1, 0], tri[:, 1, 1] = np.round(tx[0::2]), np.round(ty[0::2])
            tri[:, 2, 0], tri[:, 2, 1] = np.round(tx[1::2]), np.round(ty[1::2])
            cv2.fillPoly(fan, list(tri), 1, lineType=cv2.LINE_8, shift=shift)
        free_mask = fan.astype(bool)
        n_free = int(np.count_nonzero(free_mask))

        # obstacle hits in the window
        # each point marks the cells its (2 * obstacle_pad)-wide square touches, so that a surface
        # lying near a cell boundary marks the cells on both sides (grid-phase independent)
        hit = np.zeros((wh, ww), dtype=bool)
        hit_top = np.zeros(wh * ww, dtype=np.float32)  # highest point marking each cell this frame
        if obs_x.shape[0]:
            pad = c.obstacle_pad * res
            shifts = (-pad, pad) if pad > 0 else (0.0,)
            # the cells of each shifted copy, per axis (the corners combine a column and a row shift)
            cols = [np.floor((obs_x + sx - wox) / res).astype(np.int64) for sx in shifts]
            rows = [np.floor((obs_y + sy - woy) / res).astype(np.int64) for sy in shifts]
            col_ok = [(oc >= 0) & (oc < ww) for oc in cols]
            row_ok = [(orow >= 0) & (orow < wh) for orow in rows]
            flat = hit.reshape(-1)
            marked, marked_z = [], []
            for oc, cok in zip(cols, col_ok):
                for orow, rok in zip(rows, row_ok):
                    ok = cok & rok
                    flat[orow[ok] * ww + oc[ok]] = True
                    marked.append(orow[ok] * ww + oc[ok])
                    marked_z.append(obs_z[ok])
            np.maximum.at(hit_top, np.concatenate(marked), np.concatenate(marked_z))
            # points above the band are not mapped: a cell marked up to its top may go on up (a wall)
            hit_top[hit_top >= c.obstacle_max_height - 2 * res] = np.inf

        # log-odds update (hits after misses so that a cell seen both ways leans occupied)
        lo = self.logodds[r0:r1, c0:c1].astype(np.int16)
        lo[free_mask] -= c.miss_weight
        lo[hit] += c.hit_weight
        np.clip(lo, -c.logodds_clamp, c.logodds_clamp, out=lo)
        expl = self.explored[r0:r1, c0:c1]
        expl |= free_mask | hit
        if c.mark_footprint_free:
            rc = np.floor((frame.base_pose.y - woy) / res), np.floor((frame.base_pose.x - wox) / res)
            k = self._footprint
            kr = k.shape[0] // 2
            fr0, fc0 = int(rc[0]) - kr, int(rc[1]) - kr
            if 0 <= fr0 and 0 <= fc0 and fr0 + k.shape[0] <= wh and fc0 + k.shape[1] <= ww:
                sub = lo[fr0 : fr0 + k.shape[0], fc0 : fc0 + k.shape[1]]
                sub[k] = np.minimum(sub[k], -1)
                expl[fr0 : fr0 + k.shape[0], fc0 : fc0 + k.shape[1]] |= k
        self.logodds[r0:r1, c0:c1] = lo.astype(np.int8)
        top = self.top[r0:r1, c0:c1]
        top[free_mask & ~hit] = 0.0  # seen free: what stood there is gone
        np.maximum(top, hit_top.reshape(wh, ww), out=top)
        self.state[r0:r1, c0:c1] = np.where(expl, (lo > 0).astype(np.int8), np.int8(UNKNOWN))

        # inflation of the touched region (dilate a margin larger by the kernel radius)
        kr = self._kernel.shape[0] // 2
        er0, ec0 = max(0, r0 - kr), max(0, c0 - kr)
        er1, ec1 = min(h, r1 + kr), min(w, c1 + kr)
        dr0, dc0 = max(0, er0 - kr), max(0, ec0 - kr)
        dr1, dc1 = min(h, er1 + kr), min(w, ec1 + kr)
        occ = (self.state[dr0:dr1, dc0:dc1] == OCCUPIED).astype(np.uint8)
        for layer, kernel in ((self.inflated, self._kernel), (self.lethal, self._lethal_kernel)):
            dil = cv2.dilate(occ, kernel, borderType=cv2.BORDER_CONSTANT, borderValue=0)
            layer[er0:er1, ec0:ec1] = dil[er0 - dr0 : er1 - dr0, ec0 - dc0 : ec1 - dc0].astype(bool)

        self.version += 1
        self.stamp = float(frame.stamp)
        return IntegrationStats(
            n_points=int(n_pts),
            n_invalid=int(n_invalid),
            n_obstacle_points=int(obs_x.shape[0]),
            n_free_cells=n_free,
            grew=grew,
            elapsed_ms=(time.perf_counter() - t0) * 1e3,
        )

    # ------------------------------------------------------------------ queries
    def snapshot(self) -> GridSnapshot:
        """An immutable copy (arrays read-only) to hand to other actors."""
        return GridSnapshot(
            state=self.state.copy(),
            inflated=self.inflated.copy(),
            lethal=self.lethal.copy(),
            explored=self.explored.copy(),
            top=self.top.copy(),
            origin=self.origin.copy(),
            resolution=self.resolution,
            version=self.version,
            stamp=self.stamp,
        )

    def free_mask(self) -> np.ndarray:
        """(H, W) bool: cells known free and not inflated (traversable by the robot centre)."""
        return (self.state == FREE) & ~self.inflated
