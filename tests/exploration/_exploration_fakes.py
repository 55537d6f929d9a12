"""Small stand-ins for the grid and memory views (the real ones live in other areas).

Imported by the exploration tests as a plain module (pytest puts this folder on sys.path)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hiconav.types import CameraIntrinsics, Pose2D, camera_pose_from_base


@dataclass
class FakeGrid:
    """Grid with the GridSnapshot fields the exploration code reads."""

    state: np.ndarray
    inflated: np.ndarray
    origin: np.ndarray = field(default_factory=lambda: np.zeros(2))
    resolution: float = 0.1

    def world_to_cell(self, xy: np.ndarray) -> np.ndarray:
        xy = np.asarray(xy, dtype=float)
        col = np.floor((xy[..., 0] - self.origin[0]) / self.resolution)
        row = np.floor((xy[..., 1] - self.origin[1]) / self.resolution)
        return np.stack([row, col], axis=-1).astype(np.int64)

    def cell_to_world(self, rc: np.ndarray) -> np.ndarray:
        rc = np.asarray(rc, dtype=float)
        return np.stack([self.origin[0] + (rc[..., 1] + 0.5) * self.resolution,
                         self.origin[1] + (rc[..., 0] + 0.5) * self.resolution], axis=-1)


@dataclass(frozen=True)
class FakeObject:
    label: str
    center: np.ndarray
    box_min: np.ndarray
    box_max: np.ndarray


@dataclass(frozen=True)
class FakeAnchor:
    T_world_cam: np.ndarray
    intrinsics: CameraIntrinsics
    stamp: float
    labels_seen: tuple[str, ...]


def make_object(label: str, xy: tuple[float, float], extent: tuple[float, float, float]) -> FakeObject:
    c = np.array([xy[0], xy[1], extent[2] / 2])
    e = np.asarray(extent, float)
    return FakeObject(label, c, c - e / 2, c + e / 2)


def make_anchor(x: float, y: float, yaw: float, stamp: float, labels: tuple[str, ...],
                hfov_deg: float = 90.0) -> FakeAnchor:
    T = camera_pose_from_base(Pose2D(x, y, yaw), 0.88)
    return FakeAnchor(T, CameraIntrinsics.from_hfov(640, 480, hfov_deg), stamp, labels)


SIM = {("bed", "bed"): 1.0, ("nightstand", "bed"): 0.6, ("sofa", "bed"): 0.3, ("toilet", "bed"): 0.1,
       ("lamp", "bed"): 0.4}


def similarity(a: str, b: str) -> float:
    return SIM.get((a, b), 0.0)

