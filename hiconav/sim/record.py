"""Rerun logging of simulator runs: RGB, depth, instances, camera pose, robot pose and the
top-down map, one time step per frame, saved to an ``.rrd`` file.

Entity layout: ``world/camera`` (Transform3D + Pinhole, OpenCV RDF) with ``rgb``, ``depth`` and
``instances`` images under it; ``world/robot`` (3D points of the trajectory); ``map`` (the
navigable grid as an image, north up) with ``map/robot`` and ``map/path`` in map pixels. This
module only records; it must not change the simulation.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hiconav.errors import HiconavError
from hiconav.sim.house import House
from hiconav.types import Frame


class SimRecorder:
    """Writes a Rerun recording of one house run to ``path`` (created on construction)."""

    def __init__(self, path: str | Path, house: House, application_id: str = "hiconav_sim"
                 ) -> None:
        import rerun as rr

        self.rr = rr
        self.path = Path(path)
        if self.path.parent and not self.path.parent.exists():
            raise HiconavError(f"folder {self.path.parent} does not exist", field="record")
        self.rec = rr.RecordingStream(application_id)
        self.rec.save(str(self.path))
        self.house = house
        self.trajectory: list[tuple[float, float]] = []
        nav = house.nav
        h, w = nav.shape
        img = np.full((h, w, 3), 40, dtype=np.uint8)
        img[nav.navigable] = (200, 200, 200)
        for o in house.objects:
            cells = house.footprint(o.instance_id)
            if len(cells):
                img[cells[:, 0], cells[:, 1]] = (90, 140, 220)
        # Row 0 of the grid is the southern edge; flip so that north is up in the viewer.
        self._map_h = h
        self.rec.log("map", rr.Image(img[::-1].copy()), static=True)
        self.rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)

    def _map_px(self, xy: np.ndarray) -> np.ndarray:
        nav = self.house.nav
        col = (xy[..., 0] - nav.origin[0]) / nav.resolution
        row = (xy[..., 1] - nav.origin[1]) / nav.resolution
        return np.stack([col, self._map_h - row], axis=-1)

    def log_frame(self, frame: Frame, step: int) -> None:
        """Log one observation and the robot pose at time step ``step``."""
        rr, rec = self.rr, self.rec
        rec.set_time("step", sequence=step)
        T = frame.T_world_cam
        K = frame.intrinsics
        rec.log("world/camera", rr.Transform3D(translation=T[:3, 3], mat3x3=T[:3, :3]))
        rec.log("world/camera", rr.Pinhole(image_from_camera=K.K, resolution=[K.width, K.height],
                                            camera_xyz=rr.ViewCoordinates.RDF))
        rec.log("world/camera/rgb", rr.Image(frame.rgb))
        rec.log("world/camera/depth", rr.DepthImage(frame.depth, meter=1.0))
        if frame.instances is not None:
            seg = (frame.instances + 1).astype(np.uint16)  # 0 = none
            rec.log("world/camera/instances", rr.SegmentationImage(seg))
        pose = frame.base_pose
        self.trajectory.append((pose.x, pose.y))
        traj = np.array(self.trajectory)
        rec.log("world/robot", rr.Points3D([[pose.x, pose.y, 0.05]], radii=0.18))
        rec.log("world/trajectory", rr.LineStrips3D([np.c_[traj, np.full(len(traj), 0.05)]]))
        px = self._map_px(traj)
        rec.log("map/robot", rr.Points2D(px[-1:], radii=3.0, colors=[(230, 60, 40)]))
        rec.log("map/path", rr.LineStrips2D([px], colors=[(230, 160, 40)]))
        rec.log("pose/x", rr.Scalars(pose.x))
        rec.log("pose/y", rr.Scalars(pose.y))
        rec.log("pose/yaw", rr.Scalars(pose.yaw))

    def close(self) -> None:
        self.rec.flush()
        self.rec.disconnect()
