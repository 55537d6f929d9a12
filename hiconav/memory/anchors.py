"""Visual anchors of the CMG: the keyframe gate of eq. (2) and the anchor record.

A frame becomes a visual anchor when (i) it observes a new object, or (ii) the camera moved more
than delta_d or turned more than delta_theta since the last selected anchor (eq. 2). An anchor
keeps what the VLM needs later: pose, time, a downscaled image, the objects it observed with
their normalised 2D boxes, every label seen in the image, and a descriptor.

This module must not associate detections with object nodes (that is ``objects.py``) nor
decide pruning (that is ``graph.py`` with ``setcover.py``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import cv2
import numpy as np

from hiconav.memory.snapshot import AnchorView
from hiconav.types import CameraIntrinsics, Frame, Pose2D, freeze, wrap_angle

__all__ = ["Anchor", "AnchorGate", "GateDecision", "KeyframeSchedule", "downscale_image", "image_quality"]


@dataclass(frozen=True)
class GateDecision:
    """Outcome of the anchor gate for one frame (eq. 2).

    reason: "first" | "new_object" | "translation" | "rotation" | "requested" | "" (not an anchor);
    translation (m) and rotation (rad) are measured against the last selected anchor.
    """

    is_anchor: bool
    reason: str
    translation: float
    rotation: float


class AnchorGate:
    """Eq. (2): select a frame as anchor on a new object, ||dt|| > delta_d or |dtheta| > delta_theta.

    The reference is the pose of the last *selected* anchor, kept here even when pruning later
    removes that anchor from the graph.
    """

    def __init__(self, delta_d: float = 1.0, delta_theta_deg: float = 45.0) -> None:
        self.delta_d = float(delta_d)
        self.delta_theta = math.radians(delta_theta_deg)
        self.last_pose: Pose2D | None = None

    def decide(self, pose: Pose2D, new_object: bool, requested: bool = False) -> GateDecision:
        """Decision for a frame at base ``pose``; ``new_object`` is condition (i); ``requested``: a
        consumer asked for this frame as an anchor (``KeyframeRequest``: verification judges
        anchors, and a robot glancing at a candidate from one spot moves less than delta_d and
        turns less than delta_theta from its last anchor, so eq. 2 alone makes none)."""
        if self.last_pose is None:
            return GateDecision(True, "first", 0.0, 0.0)
        dt = pose.distance_to(self.last_pose)
        dth = abs(wrap_angle(pose.yaw - self.last_pose.yaw))
        if new_object:
            return GateDecision(True, "new_object", dt, dth)
        if dt > self.delta_d:
            return GateDecision(True, "translation", dt, dth)
        if dth > self.delta_theta:
            return GateDecision(True, "rotation", dt, dth)
        if requested:
            return GateDecision(True, "requested", dt, dth)
        return GateDecision(False, "", dt, dth)

    def accept(self, pose: Pose2D) -> None:
        """Record ``pose`` as the last selected anchor."""
        self.last_pose = pose


class KeyframeSchedule:
    """Which frames a consumer asked to be anchors (``KeyframeRequest``): those integrated up to
    clock time ``until``, one at least every ``every_s`` seconds; the newest request replaces the
    last. Times are the clock's (the request's), not the sensor's stamps."""

    def __init__(self) -> None:
        self.until: float | None = None
        self.every_s = 0.0
        self.last: float | None = None  # clock time of the newest frame made an anchor on request

    def request(self, until: float, every_s: float = 0.0) -> None:
        self.until, self.every_s = float(until), max(float(every_s), 0.0)

    def due(self, now: float) -> bool:
        """Whether the frame integrated at clock time ``now`` is one asked for (counted as made)."""
        if self.until is None or now > self.until:
            return False
        if self.last is not None and 0.0 <= now - self.last < self.every_s:
            return False
        self.last = now
        return True


def downscale_image(rgb: np.ndarray, width: int, height: int) -> np.ndarray:
    """(H, W, 3) RGB (uint8, or float in [0, 1]) -> (height, width, 3) uint8, area-averaged."""
    rgb = np.asarray(rgb)
    if rgb.dtype != np.uint8:
        scale = 255.0 if float(np.nanmax(rgb, initial=0.0)) <= 1.0 + 1e-6 else 1.0
        rgb = np.clip(np.nan_to_num(rgb) * scale, 0, 255).astype(np.uint8)
    if rgb.shape[1] == width and rgb.shape[0] == height:
        return rgb.copy()
    return cv2.resize(rgb, (width, height), interpolation=cv2.INTER_AREA)


def image_quality(image: np.ndarray) -> float:
    """Image quality in [0, 1] from sharpness: v / (v + 100), v = variance of the Laplacian.

    image: (h, w, 3) uint8. Used for the optional anchor cost c_i = 1 + w (1 - quality).
    """
    gray = cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2GRAY)
    v = float(cv2.Laplacian(gray, cv2.CV_64F).var())
    return v / (v + 100.0)


@dataclass
class Anchor:
    """Mutable anchor record owned by the graph (``view()`` gives the frozen AnchorView).

    boxes maps object id -> (4,) normalised xyxy; box_labels object id -> the labels of the
    detections placed on it; labels_seen keeps first-seen order.
    """

    id: int
    base_pose: Pose2D
    T_world_cam: np.ndarray
    intrinsics: CameraIntrinsics
    stamp: float
    image: np.ndarray
    labels_seen: tuple[str, ...]
    descriptor: np.ndarray
    quality: float
    boxes: dict[int, np.ndarray] = field(default_factory=dict)
    box_labels: dict[int, tuple[str, ...]] = field(default_factory=dict)
    far_labels: tuple[str, ...] = ()  # labels seen only beyond max_depth / without 3D
    _view: AnchorView | None = None

    @staticmethod
    def from_frame(anchor_id: int, frame: Frame, image: np.ndarray, labels_seen: tuple[str, ...],
                   descriptor: np.ndarray, quality: float) -> Anchor:
        return Anchor(anchor_id, frame.base_pose, freeze(np.array(frame.T_world_cam, dtype=np.float64)),
                      frame.intrinsics, float(frame.stamp), freeze(image), labels_seen,
                      freeze(np.asarray(descriptor, dtype=np.float32)), float(quality))

    def add_box(self, object_id: int, box: np.ndarray, labels: Iterable[str] = ()) -> None:
        """Edge (a_i, o_j) with its 2D box and the ``labels`` of the detections placed on it; a
        second box for the same object becomes the union."""
        box = np.asarray(box, dtype=np.float32)
        held = self.box_labels.get(object_id, ())
        self.box_labels[object_id] = held + tuple(lab for lab in labels if lab not in held)
        old = self.boxes.get(object_id)
        if old is not None:
            box = np.concatenate([np.minimum(old[:2], box[:2]), np.maximum(old[2:], box[2:])])
        self.boxes[object_id] = box
        self._view = None

    def replace_object(self, old_id: int, new_id: int) -> None:
        """Rewire the edge of a merged-away object ``old_id`` to ``new_id``."""
        box = self.boxes.pop(old_id, None)
        labels = self.box_labels.pop(old_id, ())
        if box is not None:
            self.add_box(new_id, box, labels)
        self._view = None

    def view(self) -> AnchorView:
        """The frozen view, rebuilt only when this anchor changed since the last call."""
        if self._view is None:
            ids = tuple(sorted(self.boxes))
            boxes = (np.stack([self.boxes[i] for i in ids]).astype(np.float32) if ids
                     else np.zeros((0, 4), dtype=np.float32))
            self._view = AnchorView(self.id, self.base_pose, self.T_world_cam, self.intrinsics,
                                    self.stamp, self.image, ids, freeze(boxes), self.labels_seen,
                                    self.descriptor, self.quality,
                                    tuple(self.box_labels.get(i, ()) for i in ids))
        return self._view
