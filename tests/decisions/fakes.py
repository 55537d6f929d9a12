"""Small hand-built pieces for the decision modules' tests: a grid snapshot, keyframes, a memory."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hiconav.types import CameraIntrinsics


@dataclass
class Grid:
    """A grid snapshot: ``state`` (H, W) int8 (0 free, 1 occupied, -1 unknown), ``inflated`` (H, W)
    bool, ``lethal`` (H, W) bool or None (then the inflated layer is lethal), world origin, metres
    per cell."""

    state: np.ndarray
    inflated: np.ndarray
    origin: np.ndarray = field(default_factory=lambda: np.zeros(2))
    resolution: float = 0.1
    lethal: np.ndarray | None = None


def open_grid(n: int = 100) -> Grid:
    """A 10 m x 10 m free room at 0.1 m, walls on the border."""
    state = np.zeros((n, n), dtype=np.int8)
    state[0, :] = state[-1, :] = state[:, 0] = state[:, -1] = 1
    return Grid(state, state == 1)


@dataclass(frozen=True)
class Anchor:
    """A keyframe: its camera pose (4, 4) world <- camera, what it observed and read."""

    id: int
    T_world_cam: np.ndarray
    object_ids: tuple = ()
    labels_seen: tuple = ()
    intrinsics: CameraIntrinsics = CameraIntrinsics.from_hfov(640, 480, 79.0)
    object_labels: tuple = ()  # row j: the labels placed on object_ids[j] (empty: not recorded)
    stamp: float = 0.0  # clock s the frame was taken


@dataclass
class Memory:
    objects: list
    anchors: list = field(default_factory=list)


@dataclass(frozen=True)
class Node:
    """A memory object node: its id, label, 3D box (world m), confidence and observations."""

    id: int
    label: str
    box_min: np.ndarray
    box_max: np.ndarray
    confidence: float = 0.9
    n_obs: int = 1
