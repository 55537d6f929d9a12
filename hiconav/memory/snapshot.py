"""Immutable views of the cognitive memory graph for the other actors.

Views compare by identity (``eq=False``): they hold arrays, and an unchanged node keeps the very
same view object from one snapshot to the next.

``ObjectView``, ``AnchorView`` and ``MemorySnapshot`` are frozen dataclasses whose arrays are
read-only, so a snapshot can cross threads without copies or locks. The graph builds a new view
only for a node that changed since the last snapshot and shares every other view object (and its
arrays) between snapshots: taking a snapshot is O(number of nodes) tuple building, never a deep
copy of point clouds. This module holds data only: it must not modify or compute the graph.
"""

from __future__ import annotations

import types
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from hiconav.types import CameraIntrinsics, Pose2D, freeze

__all__ = ["AnchorView", "MemorySnapshot", "ObjectView"]

_EMPTY_F32 = freeze(np.zeros(0, dtype=np.float32))
_EMPTY_PTS = freeze(np.zeros((0, 3), dtype=np.float32))


@dataclass(frozen=True, eq=False)
class ObjectView:
    """An object node o_j = {P_j, f_j} (eq. 3) as seen by other actors.

    center, box_min, box_max: (3,) float64 world metres (robust axis-aligned box of the points);
    feature: (D,) float32 unit semantic feature; anchor_ids: anchors observing it (edges E);
    points: (N, 3) float32 world voxelised point cloud (shared, read-only); last_seen: stamp (s);
    gt_instance: majority simulator instance id of oracle detections merged into it, for
    evaluation diagnostics only (None with real detectors); the method never reads it.
    """

    id: int
    label: str
    confidence: float
    center: np.ndarray
    box_min: np.ndarray
    box_max: np.ndarray
    n_obs: int
    feature: np.ndarray
    anchor_ids: tuple[int, ...]
    points: np.ndarray = field(default_factory=lambda: _EMPTY_PTS, repr=False, compare=False)
    last_seen: float = 0.0
    gt_instance: int | None = None
    observed_by: tuple[int, ...] = ()  # every anchor that ever observed it, pruned ones included

    def __post_init__(self) -> None:
        for name in ("center", "box_min", "box_max", "feature", "points"):
            freeze(getattr(self, name))

    @property
    def size(self) -> np.ndarray:
        """(3,) box extent in metres."""
        return self.box_max - self.box_min


@dataclass(frozen=True, eq=False)
class AnchorView:
    """A visual anchor (keyframe) a_i as seen by other actors.

    T_world_cam: (4, 4) camera-to-world; image: (h, w, 3) uint8 RGB downscaled; object_ids: the
    object nodes it observes; boxes: (n, 4) float32 normalised [0, 1] xyxy, row j for
    object_ids[j]; labels_seen: every label detected in the image, including detections beyond
    the mapping depth (out-of-boundary evidence); descriptor: (D,) float32 unit mean of the
    label features of labels_seen ((0,) when no label was seen); quality: image quality in [0, 1];
    object_labels: row j the labels of the detections this image placed on object_ids[j] (empty
    for views built without them).
    """

    id: int
    base_pose: Pose2D
    T_world_cam: np.ndarray
    intrinsics: CameraIntrinsics
    stamp: float
    image: np.ndarray
    object_ids: tuple[int, ...]
    boxes: np.ndarray
    labels_seen: tuple[str, ...]
    descriptor: np.ndarray = field(default_factory=lambda: _EMPTY_F32, repr=False, compare=False)
    quality: float = 1.0
    object_labels: tuple[tuple[str, ...], ...] = ()

    def __post_init__(self) -> None:
        for name in ("T_world_cam", "image", "boxes", "descriptor"):
            freeze(getattr(self, name))

    def box_of(self, object_id: int) -> np.ndarray | None:
        """(4,) normalised xyxy box of ``object_id`` in this anchor's image, or None."""
        try:
            return self.boxes[self.object_ids.index(object_id)]
        except ValueError:
            return None


@dataclass(frozen=True, eq=False)
class MemorySnapshot:
    """An immutable state of the CMG: object nodes, anchors and their edges.

    version increases with every change of the graph; stamp is the time of the last integrated
    frame (s). Look-ups by id are O(1).
    """

    version: int
    stamp: float
    objects: tuple[ObjectView, ...]
    anchors: tuple[AnchorView, ...]
    _objects_by_id: Mapping[int, ObjectView] = field(init=False, repr=False, compare=False)
    _anchors_by_id: Mapping[int, AnchorView] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "objects", tuple(self.objects))
        object.__setattr__(self, "anchors", tuple(self.anchors))
        object.__setattr__(self, "_objects_by_id",
                           types.MappingProxyType({o.id: o for o in self.objects}))
        object.__setattr__(self, "_anchors_by_id",
                           types.MappingProxyType({a.id: a for a in self.anchors}))

    @staticmethod
    def empty() -> MemorySnapshot:
        return MemorySnapshot(0, 0.0, (), ())

    def object(self, object_id: int) -> ObjectView:
        """The object node ``object_id``; KeyError naming the id when absent (e.g. merged away)."""
        try:
            return self._objects_by_id[object_id]
        except KeyError:
            raise KeyError(f"object {object_id} not in memory snapshot v{self.version}") from None

    def anchor(self, anchor_id: int) -> AnchorView:
        """The anchor ``anchor_id``; KeyError naming the id when absent (e.g. pruned)."""
        try:
            return self._anchors_by_id[anchor_id]
        except KeyError:
            raise KeyError(f"anchor {anchor_id} not in memory snapshot v{self.version}") from None

    def has_object(self, object_id: int) -> bool:
        return object_id in self._objects_by_id

    def has_anchor(self, anchor_id: int) -> bool:
        return anchor_id in self._anchors_by_id

    def objects_with_label(self, label: str) -> tuple[ObjectView, ...]:
        from hiconav.perception.detector import normalise_label

        key = normalise_label(label)
        return tuple(o for o in self.objects if o.label == key)

    @property
    def n_edges(self) -> int:
        return sum(len(a.object_ids) for a in self.anchors)
