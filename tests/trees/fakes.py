"""Small fake world pieces (grid, memory, plan) for tree tests: just the fields behaviours read."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from hiconav.messages import PlanMsg, WorldSnapshot
from hiconav.types import CameraIntrinsics, Frontier, Pose2D, camera_pose_from_base


@dataclass
class FakeGrid:
    state: np.ndarray
    inflated: np.ndarray
    origin: np.ndarray = field(default_factory=lambda: np.zeros(2))
    resolution: float = 0.1
    top: np.ndarray | None = None  # obstacle heights (None: a 2D map)


def open_grid(n: int = 100) -> FakeGrid:
    """A 10 m x 10 m free room at 0.1 m, walls on the border."""
    state = np.zeros((n, n), dtype=np.int8)
    state[0, :] = state[-1, :] = state[:, 0] = state[:, -1] = 1
    return FakeGrid(state, state == 1)


@dataclass(frozen=True)
class FakeObject:
    id: int
    label: str
    center: np.ndarray
    box_min: np.ndarray
    box_max: np.ndarray
    confidence: float = 0.9
    n_obs: int = 1
    anchor_ids: tuple = ()
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # (N, 3) world


def obj(oid: int, label: str, x: float, y: float, n_obs: int = 1, conf: float = 0.9) -> FakeObject:
    c = np.array([x, y, 0.4])
    return FakeObject(oid, label, c, c - [0.5, 0.5, 0.4], c + [0.5, 0.5, 0.4], conf, n_obs)


@dataclass(frozen=True)
class FakeAnchor:
    id: int
    T_world_cam: np.ndarray
    object_ids: tuple = ()
    intrinsics: CameraIntrinsics = CameraIntrinsics.from_hfov(640, 480, 79.0)
    labels_seen: tuple = ()


def anchor(aid: int, pose: Pose2D, object_ids: tuple = (), height: float = 0.4, labels_seen: tuple = ()) -> FakeAnchor:
    """An anchor whose camera stands at the pose, ``height`` m up, looking along its yaw;
    ``labels_seen``: labels detected in it, placed on a node or not."""
    return FakeAnchor(aid, camera_pose_from_base(pose, height), tuple(object_ids), labels_seen=tuple(labels_seen))


@dataclass(frozen=True)
class FakeMemory:
    objects: tuple = ()
    anchors: tuple = ()
    version: int = 0  # frames integrated

    def anchor(self, anchor_id: int):
        for a in self.anchors:
            if a.id == anchor_id:
                return a
        raise KeyError(anchor_id)


def world(pose: Pose2D, objects=(), seq: int = 0, grid: FakeGrid | None = None, version: int = 0,
          anchors=()) -> WorldSnapshot:
    """A snapshot; an anchor given no ``labels_seen`` detected the labels of the nodes it observed
    (as the memory records them when each detection matched its node's label)."""
    labels = {o.id: o.label for o in objects}
    anchors = [a if a.labels_seen or not a.object_ids else
               replace(a, labels_seen=tuple(dict.fromkeys(labels[i] for i in a.object_ids if i in labels)))
               for a in anchors]
    return WorldSnapshot(seq, 0.0, pose, grid if grid is not None else open_grid(),
                         FakeMemory(tuple(objects), tuple(anchors), version=version))


@dataclass(frozen=True)
class FakePlan:
    goal: Frontier | None
    order: tuple = ()


def plan(*xy: tuple[float, float]) -> PlanMsg:
    frontiers = tuple(Frontier(i, np.array(p), np.array(p), 10) for i, p in enumerate(xy))
    return PlanMsg(FakePlan(frontiers[0] if frontiers else None, tuple(f.id for f in frontiers)), frontiers, 0.0)
