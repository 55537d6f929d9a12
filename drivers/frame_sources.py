"""RGB-D frame sources for drivers whose link carries no images (MAVLink): the simulator's
renderer at the robot's pose, a recorded folder (``replay_driver.ReplayFrameSource``), or an
OpenCV capture (a camera index, a video file or a stream URL).

A frame source only produces frames; it never commands the robot and never changes a driver's
pose. The simulator renderer holds an OpenGL context: call ``frame_at`` from one thread.
"""

from __future__ import annotations

import dataclasses
import math
import threading
from typing import Any

import numpy as np
from hiconav.drivers.base import DriverError, FrameSource
from hiconav.drivers.profiles import CameraProfile, RobotProfile

from hiconav.types import Frame, Pose2D

__all__ = ["OpenCVCaptureSource", "SimRendererSource", "make_frame_source"]


class SimRendererSource:
    """Frames rendered by a ``hiconav.sim.Simulator`` at the pose the driver reports.

    The simulator's own pose is overwritten on each call (it is only a camera here; the
    vehicle owns the motion). ``Frame.stamp`` is the driver's pose stamp.
    """

    def __init__(self, simulator: Any) -> None:
        self.simulator = simulator
        self._lock = threading.Lock()

    @staticmethod
    def from_house(spec: Any, sim_config: Any = None, seed: int = 0) -> SimRendererSource:
        """``spec``: a house spec (``procthor:val/3``, a path) or an already loaded ``House``."""
        from hiconav.sim import Simulator, load_house

        house = load_house(spec) if isinstance(spec, str) else spec
        return SimRendererSource(Simulator(house, sim_config, seed))

    def frame_at(self, pose: Pose2D, stamp: float) -> Frame | None:
        with self._lock:
            self.simulator.pose = pose
            frame = self.simulator.observe()
        return dataclasses.replace(frame, stamp=stamp)

    def close(self) -> None:
        close = getattr(self.simulator, "close", None)
        if close is not None:
            close()


class OpenCVCaptureSource:
    """RGB from ``cv2.VideoCapture(device)``; depth from a second capture of raw 16-bit depth
    (``depth_device``, scaled by ``camera.depth_scale``) when given.

    Fallback, clearly labelled: without a depth device the depth image is all NaN ("no return"),
    so the mapper sees no obstacles from this camera; use it for detection-only debugging.
    Intrinsics and the mount come from the robot profile's ``camera`` section.
    """

    def __init__(self, device: int | str, camera: CameraProfile, depth_device: int | str | None = None) -> None:
        import cv2

        self._cv2 = cv2
        self.camera = camera
        self.intrinsics = camera.intrinsics()
        self._rgb = cv2.VideoCapture(device)
        if not self._rgb.isOpened():
            raise DriverError(f"OpenCV cannot open camera {device!r}", field="frames.device")
        self._depth = None
        if depth_device is not None:
            self._depth = cv2.VideoCapture(depth_device)
            if not self._depth.isOpened():
                raise DriverError(f"OpenCV cannot open depth camera {depth_device!r}", field="frames.depth_device")
            self._depth.set(cv2.CAP_PROP_CONVERT_RGB, 0)
        self.depth_is_fallback = self._depth is None
        self._seq = 0
        self._lock = threading.Lock()

    def frame_at(self, pose: Pose2D, stamp: float) -> Frame | None:
        cv2 = self._cv2
        with self._lock:
            ok, bgr = self._rgb.read()
            if not ok or bgr is None:
                return None
            h, w = self.intrinsics.height, self.intrinsics.width
            if bgr.shape[:2] != (h, w):
                bgr = cv2.resize(bgr, (w, h), interpolation=cv2.INTER_AREA)
            rgb = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
            if self._depth is not None:
                ok, raw = self._depth.read()
                if not ok or raw is None:
                    return None
                if raw.ndim == 3:
                    raw = raw[..., 0]
                depth = raw.astype(np.float32) * np.float32(self.camera.depth_scale)
                if depth.shape != (h, w):
                    depth = cv2.resize(depth, (w, h), interpolation=cv2.INTER_NEAREST)
                depth[(depth < self.camera.min_depth) | (depth > self.camera.max_depth)] = 0.0
            else:
                depth = np.full((h, w), np.nan, dtype=np.float32)
            self._seq += 1
            return Frame(rgb=rgb, depth=depth, intrinsics=self.intrinsics,
                         T_world_cam=self.camera.T_world_cam(pose), base_pose=pose, stamp=stamp, seq=self._seq)

    def close(self) -> None:
        self._rgb.release()
        if self._depth is not None:
            self._depth.release()


def make_frame_source(profile: RobotProfile, **options: Any) -> FrameSource | None:
    """The frame source the profile's ``frames`` section names (None for ``source: none``).

    Options: ``house`` (a spec or a loaded House; overrides ``frames.house``), ``sim_config``.
    """
    f = profile.frames
    if f.source == "sim":
        from hiconav.sim import SimConfig

        cam = profile.camera
        sim_config = options.get("sim_config") or SimConfig(
            width=cam.width, height=cam.height,
            hfov_deg=cam.hfov_deg if cam.hfov_deg is not None else math.degrees(cam.intrinsics().hfov),
            camera_height=cam.extrinsics.height, robot_radius=profile.footprint.radius,
            min_depth=cam.min_depth, max_depth=cam.max_depth)
        return SimRendererSource.from_house(options.get("house") or f.house, sim_config)  # type: ignore[arg-type]
    if f.source == "replay":
        from hiconav.drivers.replay_driver import ReplayFrameSource

        return ReplayFrameSource(f.path)  # type: ignore[arg-type]
    if f.source == "opencv":
        return OpenCVCaptureSource(f.device, profile.camera, f.depth_device)  # type: ignore[arg-type]
    return None
