"""The agent in a house: Habitat-style discrete actions and continuous (v, omega, dt) motion
with collisions against the navigable grid, and RGB-D + instance observations.

Collision model: the robot is a disc of ``robot_radius``; its centre may only be on the cells of
``geodesic.centre_free``: where the cell's clearance is at least the radius, so the disc never
overlaps a wall or object cell (ProcTHOR), or on the data set's own centre space (Gibson's
channel 0, Habitat's navmesh). Motion is integrated in sub-steps of at most half a cell; a sub-step that
would leave free space sets ``collided`` for that step and, with ``allow_sliding`` (Habitat-
Sim's default), slides: the robot takes the sub-step's x or y component alone (the longer one
first) when that stays free, so it glides along a wall met at an angle instead of stopping dead;
otherwise (or without sliding) it stops there. Simulated time advances ``ACTION_SECONDS`` per discrete action and ``dt``
per velocity step. This module moves the robot and renders; it must not plan or decide.
"""

from __future__ import annotations

import math
import threading

import numpy as np

from hiconav.errors import HiconavError
from hiconav.sim.config import SimConfig
from hiconav.sim.geodesic import centre_free, clearance
from hiconav.sim.house import House
from hiconav.sim.viewpoints import MIN_VIEW_PIXELS
from hiconav.types import (
    CameraIntrinsics,
    DiscreteAction,
    Frame,
    Pose2D,
    VelocityCommand,
    camera_pose_from_base,
    wrap_angle,
)

ACTION_SECONDS = 0.5  # simulated seconds per discrete action


class SimulatorError(HiconavError):
    """An invalid request to the simulator (e.g. a start pose inside a wall)."""


class Simulator:
    """One robot in one house. ``reset`` -> ``step`` / ``step_velocity`` -> ``Frame``."""

    def __init__(self, house: House, config: SimConfig | None = None, seed: int = 0) -> None:
        self.house = house
        self.config = config or SimConfig()
        self.seed = seed
        self.rng = np.random.default_rng(seed)
        c = self.config
        self.intrinsics = CameraIntrinsics.from_hfov(c.width, c.height, c.hfov_deg)
        self.clearance = clearance(house.nav)
        self.free = centre_free(house, c.robot_radius)  # (H, W) robot-centre cells
        self._renderer = None
        self.pose = Pose2D(0.0, 0.0, 0.0)
        self.tilt = 0.0  # rad, positive looking up
        self._seq = 0
        # instance id + 1 -> watched (-1, no instance, -> slot 0; larger ids clip to the last, False
        # slot): the goals whose first sighting is recorded, None when none are
        self._watch: np.ndarray | None = None
        self._clear_episode()

    def _clear_episode(self) -> None:
        """Zero what one episode counts (``__init__`` and ``reset``)."""
        self.collided = False
        self.steps = 0
        self.time = 0.0
        self.path_length = 0.0
        self.collisions = 0
        self.turns = 0  # discrete turn actions (TURN_LEFT / TURN_RIGHT) this episode
        self.velocity_steps = 0  # velocity commands integrated this episode (no discrete turns then)
        self.stopped = False
        self.first_in_view: tuple[int, float, float, float] | None = None  # (steps, path m, x, y) then

    # ----------------------------------------------------------------------------- state
    def is_free(self, xy: np.ndarray) -> bool:
        """True where the robot disc centred at world ``xy`` touches no blocked cell."""
        rc = self.house.nav.world_to_cell(np.asarray(xy, dtype=np.float64)[:2])
        h, w = self.free.shape
        return bool(0 <= rc[0] < h and 0 <= rc[1] < w and self.free[rc[0], rc[1]])

    def nearest_free(self, xy: np.ndarray, max_dist: float = 0.3) -> np.ndarray | None:
        """Centre of the nearest free cell within ``max_dist`` m of ``xy``, or None."""
        nav = self.house.nav
        rc = nav.world_to_cell(np.asarray(xy, dtype=np.float64)[:2])
        r = math.ceil(max_dist / nav.resolution)
        h, w = self.free.shape
        r0, r1 = max(rc[0] - r, 0), min(rc[0] + r + 1, h)
        c0, c1 = max(rc[1] - r, 0), min(rc[1] + r + 1, w)
        if r1 <= r0 or c1 <= c0:
            return None
        rr, cc = np.nonzero(self.free[r0:r1, c0:c1])
        if len(rr) == 0:
            return None
        centres = nav.cell_to_world(np.stack([rr + r0, cc + c0], axis=1))
        d = np.linalg.norm(centres - np.asarray(xy)[:2], axis=1)
        k = int(np.argmin(d))
        return centres[k] if d[k] <= max_dist else None

    def reset(self, start: Pose2D, tilt: float = 0.0) -> Frame:
        """Place the robot at ``start`` (snapped to the nearest free cell within 0.3 m)."""
        xy = np.array([start.x, start.y])
        if not self.is_free(xy):
            snapped = self.nearest_free(xy)
            if snapped is None:
                raise SimulatorError(
                    f"start ({start.x:.2f}, {start.y:.2f}) in {self.house.name} is not on free "
                    f"floor (robot radius {self.config.robot_radius} m)", field="start")
            xy = snapped
        self.pose = Pose2D(float(xy[0]), float(xy[1]), wrap_angle(start.yaw))
        self.tilt = float(tilt)
        self._clear_episode()
        return self.observe()

    # ----------------------------------------------------------------------------- motion
    def _move(self, distance: float, yaw: float) -> bool:
        """Translate along ``yaw`` by ``distance`` m; returns True when blocked."""
        if distance == 0.0:
            return False
        n = max(1, math.ceil(abs(distance) / (self.house.nav.resolution / 2.0)))
        d = np.array([math.cos(yaw), math.sin(yaw)]) * (distance / n)
        xy = self.pose.xy
        start = xy
        blocked = False
        for _ in range(n):
            nxt = xy + d
            if not self.is_free(nxt):
                blocked = True
                nxt = self._slide(xy, d) if self.config.allow_sliding else None
                if nxt is None:
                    break
            xy = nxt
        self.path_length += float(np.hypot(*(xy - start)))
        self.pose = Pose2D(float(xy[0]), float(xy[1]), self.pose.yaw)
        return blocked

    def _slide(self, xy: np.ndarray, d: np.ndarray) -> np.ndarray | None:
        """The free point reached by the x or the y component of sub-step ``d`` alone, or None."""
        axes = (0, 1) if abs(d[0]) >= abs(d[1]) else (1, 0)
        for k in axes:
            if abs(d[k]) < 1e-9:
                continue
            nxt = xy.copy()
            nxt[k] += d[k]
            if self.is_free(nxt):
                return nxt
        return None

    def step(self, action: DiscreteAction) -> Frame:
        """Apply one discrete action (Habitat semantics) and return the new observation."""
        c = self.config
        self.collided = False
        if action == DiscreteAction.MOVE_FORWARD:
            self.collided = self._move(c.forward_step, self.pose.yaw)
        elif action == DiscreteAction.TURN_LEFT:
            self.turns += 1
            self.pose = Pose2D(self.pose.x, self.pose.y,
                               wrap_angle(self.pose.yaw + math.radians(c.turn_deg)))
        elif action == DiscreteAction.TURN_RIGHT:
            self.turns += 1
            self.pose = Pose2D(self.pose.x, self.pose.y,
                               wrap_angle(self.pose.yaw - math.radians(c.turn_deg)))
        elif action == DiscreteAction.LOOK_UP:
            self.tilt = min(self.tilt + math.radians(c.tilt_deg), math.radians(c.max_tilt_deg))
        elif action == DiscreteAction.LOOK_DOWN:
            self.tilt = max(self.tilt - math.radians(c.tilt_deg), -math.radians(c.max_tilt_deg))
        elif action == DiscreteAction.STOP:
            self.stopped = True
        else:
            raise SimulatorError(f"unknown action {action!r}", field="action")
        self.collisions += int(self.collided)
        self.steps += 1
        self.time += ACTION_SECONDS
        return self.observe()

    def step_velocity(self, cmd: VelocityCommand, dt: float) -> Frame:
        """Integrate a body-frame velocity (unicycle) for ``dt`` s, with collisions."""
        if not dt > 0.0:
            raise SimulatorError(f"dt must be > 0, got {dt}", field="dt")
        n = max(1, math.ceil(abs(cmd.v) * dt / (self.house.nav.resolution / 2.0)))
        h = dt / n
        self.collided = False
        for _ in range(n):
            yaw_mid = self.pose.yaw + 0.5 * cmd.omega * h
            blocked = self._move(cmd.v * h, yaw_mid)
            self.pose = Pose2D(self.pose.x, self.pose.y, wrap_angle(self.pose.yaw + cmd.omega * h))
            if blocked:
                self.collided = True
        self.collisions += int(self.collided)
        self.steps += 1
        self.velocity_steps += 1
        self.time += dt
        return self.observe()

    # ----------------------------------------------------------------------------- sensing
    @property
    def renderer(self):
        """The renderer of the calling thread (re-created if the simulator changed threads)."""
        if self._renderer is not None and self._renderer.thread != threading.get_ident():
            self._renderer = None  # its GL objects belong to the other thread's context
        if self._renderer is None:
            from hiconav.sim.renderer import Renderer

            c = self.config
            self._renderer = Renderer(c.width, c.height, min_depth=c.min_depth,
                                      max_depth=c.max_depth, noise=c.texture_noise)
            self._renderer.set_house(self.house)
        return self._renderer

    @property
    def T_world_cam(self) -> np.ndarray:
        return camera_pose_from_base(self.pose, self.config.camera_height, self.tilt)

    def watch(self, instance_ids) -> None:
        """Record (``first_in_view``) the first rendered frame in which one of ``instance_ids``
        covers ``MIN_VIEW_PIXELS`` pixels within the depth range (what the robot could map): where
        an episode's path went before its goal was first in view, and after. Scoring only; the
        robot never sees it."""
        ids = np.asarray(sorted({int(i) for i in instance_ids}), dtype=np.int64)
        self._watch = None
        if ids.size:
            self._watch = np.zeros(int(ids.max()) + 3, dtype=bool)
            self._watch[ids + 1] = True
        self.first_in_view = None
        if self._renderer is not None:  # the view the robot stands in now counts too
            _, depth, instances = self._renderer.render(self.T_world_cam, self.intrinsics)
            self._check_in_view(depth, instances)

    def _check_in_view(self, depth: np.ndarray, instances: np.ndarray | None) -> None:
        lut = self._watch
        if lut is None or self.first_in_view is not None or instances is None:
            return
        inst = np.asarray(instances)
        if np.count_nonzero(lut.take(inst[::2, ::2] + 1, mode="clip")) * 4 < MIN_VIEW_PIXELS // 2:
            return  # a quarter of the pixels holds far too few of them
        hit = lut.take(inst + 1, mode="clip")
        if np.count_nonzero(hit) < MIN_VIEW_PIXELS:
            return
        d = depth[hit]
        if np.count_nonzero(np.isfinite(d) & (d > 0) & (d <= self.config.max_depth)) >= MIN_VIEW_PIXELS:
            self.first_in_view = (int(self.steps), float(self.path_length), float(self.pose.x), float(self.pose.y))

    def observe(self) -> Frame:
        """Render the current view (no state change besides the frame counter)."""
        T = self.T_world_cam
        rgb, depth, instances = self.renderer.render(T, self.intrinsics)
        self._check_in_view(depth, instances)
        self._seq += 1
        return Frame(rgb=rgb, depth=depth, intrinsics=self.intrinsics, T_world_cam=T,
                     base_pose=self.pose, stamp=self.time, instances=instances, seq=self._seq)

    def close(self) -> None:
        """Free the renderer's GL objects (only possible from the thread that made them)."""
        if self._renderer is not None and self._renderer.thread == threading.get_ident():
            self._renderer.release()
        self._renderer = None
