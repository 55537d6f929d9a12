"""Object nodes of the CMG: detections lifted to 3D and the merge score of eq. (4).

A detection becomes a ``ObjectObservation`` (its masked depth back-projected with
``hiconav.geometry.backproject`` inside its 2D box, background cut by a depth band around the
mask's median depth). An ``ObjectNode`` o_j = {P_j, f_j} (eq. 3) accumulates
observations: voxelised point cloud (capped), robust 3D box, label votes, semantic feature,
observation count and the anchors that observed it.

Merge score, eq. (4): s(o, o') = lambda_1 s_g(o, o') + lambda_2 s_s(o, o') with s_g the 3D
overlap of the padded axis-aligned boxes (intersection over the smaller box by default, or IoU as
the paper words it; see ``MemoryConfig.geometric``) and s_s the cosine of the semantic features,
clipped to [0, 1]. ``merge_scores`` evaluates one observation against all nodes at once.

This module must not decide anchors or pruning, and never stores a frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from hiconav.geometry import backproject, voxel_downsample
from hiconav.memory.config import MemoryConfig
from hiconav.memory.snapshot import ObjectView
from hiconav.types import CameraIntrinsics, Detection, Frame, freeze

__all__ = ["ObjectNode", "ObjectObservation", "box_iou_many", "lift_detection", "merge_scores"]


@dataclass(frozen=True)
class ObjectObservation:
    """One detection in 3D. points: (N, 3) float32 world (not yet voxelised); box_min/box_max: (3,) float64;
    feature: (D,) float32 unit label embedding; embedding: detector's (E,) unit vector or None;
    box_norm: (4,) float32 normalised xyxy in the image; depth: median depth (m)."""

    label: str
    score: float
    points: np.ndarray
    box_min: np.ndarray
    box_max: np.ndarray
    feature: np.ndarray
    embedding: np.ndarray | None
    box_norm: np.ndarray
    depth: float
    instance_id: int | None = None  # oracle diagnostics only


def _normalised_box(box_xyxy: np.ndarray, intr: CameraIntrinsics) -> np.ndarray:
    b = np.asarray(box_xyxy, dtype=np.float64).reshape(4)
    out = np.array([b[0] / intr.width, b[1] / intr.height, b[2] / intr.width, b[3] / intr.height])
    return np.clip(out, 0.0, 1.0).astype(np.float32)


def robust_box(points: np.ndarray, quantile: float) -> tuple[np.ndarray, np.ndarray]:
    """(3,) min and max of (N, 3) points, from the ``quantile`` / 1 - quantile order statistics."""
    n = len(points)
    k = int(quantile * n)
    if k == 0:
        return points.min(axis=0).astype(np.float64), points.max(axis=0).astype(np.float64)
    part = np.partition(points, (k, n - 1 - k), axis=0)
    return part[k].astype(np.float64), part[n - 1 - k].astype(np.float64)


def lift_detection(frame: Frame, det: Detection, cfg: MemoryConfig, feature: np.ndarray
                   ) -> ObjectObservation | None:
    """Back-project ``det`` (mask, else its box) into a voxelised world point cloud.

    Only the pixels of the detection's box are processed (a crop with shifted intrinsics), at
    ``cfg.stride``. Returns None when the detection is beyond ``cfg.max_depth`` or has fewer than
    ``cfg.min_points`` valid points: it then only counts as a label seen.
    """
    intr = frame.intrinsics
    H, W = int(intr.height), int(intr.width)
    b = np.asarray(det.box_xyxy, dtype=np.float64).reshape(4)
    x0, y0 = max(math.floor(b[0]), 0), max(math.floor(b[1]), 0)
    x1, y1 = min(math.ceil(b[2]) + 1, W), min(math.ceil(b[3]) + 1, H)
    if x1 - x0 < 1 or y1 - y0 < 1:
        return None
    depth = np.asarray(frame.depth)[y0:y1, x0:x1]
    mask = None if det.mask is None else np.asarray(det.mask)[y0:y1, x0:x1]
    crop = CameraIntrinsics(x1 - x0, y1 - y0, intr.fx, intr.fy, intr.cx - x0, intr.cy - y0)
    # Adaptive stride: at most ~cfg.max_pixels samples per detection (near, large objects).
    area = (x1 - x0) * (y1 - y0)
    stride = max(cfg.stride, math.ceil(math.sqrt(area / cfg.max_pixels)))
    # Depth band around the mask's median depth: drop background seen through the mask.
    d = depth[::stride, ::stride]
    m = d if mask is None else d[mask[::stride, ::stride]]
    with np.errstate(invalid="ignore"):
        m = m[np.isfinite(m) & (m > cfg.min_depth)]
    if m.size < cfg.min_points:
        return None
    med = float(np.partition(m, m.size // 2)[m.size // 2])
    if med > cfg.max_depth:
        return None
    points, _ = backproject(depth, crop, frame.T_world_cam, stride=stride, mask=mask,
                            min_depth=max(cfg.min_depth, med - cfg.depth_band),
                            max_depth=min(cfg.max_depth, med + cfg.depth_band))
    if points.shape[0] < cfg.min_points:
        return None
    bmin, bmax = robust_box(points, cfg.outlier_quantile)
    emb = None
    if det.embedding is not None:
        e = np.asarray(det.embedding, dtype=np.float32).ravel()
        n = float(np.linalg.norm(e))
        emb = freeze(e / n) if n > 0 else None
    return ObjectObservation(det.label, float(det.score), freeze(points), bmin, bmax,
                             feature, emb, _normalised_box(det.box_xyxy, intr), med, det.instance_id)


def box_iou_many(bmin: np.ndarray, bmax: np.ndarray, mins: np.ndarray, maxs: np.ndarray,
                 pad: float, mode: str = "iou") -> np.ndarray:
    """s_g of one box (3,) against K boxes (K, 3), each padded by ``pad`` m per side.

    mode "iou": intersection / union (paper); "overlap": intersection / smaller volume.
    """
    # called for every observation against every node: np.maximum(x, 0) and explicit products
    # give the same numbers as np.clip(x, 0, None) / np.prod(axis=1) at a fraction of the overhead
    a0, a1 = bmin - pad, bmax + pad
    b0, b1 = mins - pad, maxs + pad
    e = np.maximum(np.minimum(a1, b1) - np.maximum(a0, b0), 0.0)
    inter = e[:, 0] * e[:, 1] * e[:, 2]
    ea = np.maximum(a1 - a0, 0.0)
    va = float(ea[0] * ea[1] * ea[2])
    eb = np.maximum(b1 - b0, 0.0)
    vb = eb[:, 0] * eb[:, 1] * eb[:, 2]
    if mode == "overlap":
        den = np.minimum(va, vb)
    else:
        den = va + vb - inter
    return np.where(den > 0, inter / np.maximum(den, 1e-12), 0.0)


def merge_scores(obs_min: np.ndarray, obs_max: np.ndarray, obs_feature: np.ndarray,
                 obs_embedding: np.ndarray | None, mins: np.ndarray, maxs: np.ndarray,
                 features: np.ndarray, embeddings: list[np.ndarray | None], cfg: MemoryConfig
                 ) -> np.ndarray:
    """Eq. (4) for one observation against K nodes: (K,) s = l1 * s_g + l2 * s_s.

    features: (K, D) unit label features; s_s = clip(cos, 0, 1), averaged with the cosine of the
    detector embeddings when both sides have one of the same size.
    """
    if len(mins) == 0:
        return np.zeros(0)
    s_g = box_iou_many(obs_min, obs_max, mins, maxs, cfg.box_padding, cfg.geometric)
    s_s = np.minimum(np.maximum(features @ obs_feature, 0.0), 1.0)  # = np.clip(., 0, 1), cheaper
    if obs_embedding is not None:
        for i, e in enumerate(embeddings):
            if e is not None and e.shape == obs_embedding.shape:
                s_s[i] = 0.5 * (s_s[i] + float(np.clip(e @ obs_embedding, 0.0, 1.0)))
    return cfg.lambda_1 * s_g + cfg.lambda_2 * s_s


@dataclass
class ObjectNode:
    """Mutable object node owned by the graph (``view()`` gives the frozen ObjectView).

    points: (N, 3) float32 read-only world cloud (replaced, never modified in place, so views
    can share it); label_votes: label -> summed detection score; features: label -> unit
    embedding of that label; label_points: label -> the cloud of that label's observations.

    The node's geometry (``points`` and its box) is its majority label's cloud
    (``MemoryConfig.node_geometry``): eq. (4) also merges observations of another label whose box
    overlaps the node's (a relabelled view of the same object, whose vote the majority outweighs),
    and among those are one-frame spurious boxes of another label, a chunk of wall and floor 1-2 m
    across; the union of the clouds took their extent, and a small plant's node became a 2 m box
    that the robot stopped 0.9 m from, over 1 m from the plant. With ``"all"`` it is every
    observation's cloud, as eq. (3) writes P_j.
    """

    id: int
    points: np.ndarray
    box_min: np.ndarray
    box_max: np.ndarray
    label_votes: dict[str, float]
    label_features: dict[str, np.ndarray]
    n_obs: int
    score_sum: float
    anchor_ids: set[int] = field(default_factory=set)
    embedding: np.ndarray | None = None
    last_seen: float = 0.0
    instance_votes: dict[int, int] = field(default_factory=dict)  # oracle diagnostics only
    # every anchor that ever observed it, pruned ones too: which objects one image showed
    # together (co-visibility) outlives the image
    observed_by: set[int] = field(default_factory=set)
    label_points: dict[str, np.ndarray] = field(default_factory=dict)
    _feature: np.ndarray | None = None
    _view: ObjectView | None = None

    @staticmethod
    def from_observation(node_id: int, obs: ObjectObservation, stamp: float, cfg: MemoryConfig
                         ) -> ObjectNode:
        node = ObjectNode(node_id, obs.points, obs.box_min.copy(), obs.box_max.copy(),
                          {obs.label: obs.score}, {obs.label: obs.feature}, 1, obs.score,
                          set(), obs.embedding, stamp)
        node._set_points(obs.points, cfg)
        if cfg.node_geometry == "majority_label":
            node.label_points[obs.label] = node.points
        if obs.instance_id is not None:
            node.instance_votes[obs.instance_id] = 1
        return node

    @property
    def label(self) -> str:
        """Majority label by summed detection score (ties: alphabetical)."""
        return max(sorted(self.label_votes), key=lambda k: self.label_votes[k])

    @property
    def confidence(self) -> float:
        """Mean detection score times the share of votes of the winning label, in [0, 1]."""
        total = sum(self.label_votes.values())
        share = self.label_votes[self.label] / total if total > 0 else 0.0
        return float(self.score_sum / max(self.n_obs, 1) * share)

    @property
    def feature(self) -> np.ndarray:
        """(D,) float32 unit vote-weighted mean of the label features (f_j of eq. 3)."""
        if self._feature is None:
            f = sum(w * self.label_features[k] for k, w in self.label_votes.items())
            f = np.asarray(f, dtype=np.float32)
            n = float(np.linalg.norm(f))
            self._feature = freeze(f / n if n > 0 else f)
        return self._feature

    @staticmethod
    def _cloud(points: np.ndarray, cfg: MemoryConfig) -> np.ndarray:
        """Voxelised and capped (evenly spaced subsample, deterministic) read-only cloud."""
        points = voxel_downsample(points, cfg.voxel)
        if len(points) > cfg.max_points:
            idx = np.linspace(0, len(points) - 1, cfg.max_points).astype(np.int64)
            points = points[idx]
        return freeze(points)

    def _set_points(self, points: np.ndarray, cfg: MemoryConfig) -> None:
        self._use_cloud(self._cloud(points, cfg), cfg)

    def _use_cloud(self, cloud: np.ndarray, cfg: MemoryConfig) -> None:
        self.points = cloud
        self.box_min, self.box_max = robust_box(cloud, cfg.outlier_quantile)

    def _add_label_cloud(self, label: str, points: np.ndarray, cfg: MemoryConfig) -> None:
        """Grow ``label``'s cloud by ``points``."""
        old = self.label_points.get(label)
        self.label_points[label] = self._cloud(points if old is None else np.concatenate([old, points]), cfg)

    def _use_majority_cloud(self, cfg: MemoryConfig) -> None:
        """Take the majority label's cloud as the node's geometry (after the votes changed)."""
        cloud = self.label_points.get(self.label)
        if cloud is not None and cloud is not self.points:
            self._use_cloud(cloud, cfg)

    def absorb(self, obs: ObjectObservation, stamp: float, cfg: MemoryConfig) -> None:
        """Merge one observation into this node (eq. 4 decided it belongs here)."""
        self.label_votes[obs.label] = self.label_votes.get(obs.label, 0.0) + obs.score
        if cfg.node_geometry == "majority_label":
            self._add_label_cloud(obs.label, obs.points, cfg)
            self._use_majority_cloud(cfg)
        else:
            self._set_points(np.concatenate([self.points, obs.points]), cfg)
        self.label_features.setdefault(obs.label, obs.feature)
        self.n_obs += 1
        self.score_sum += obs.score
        if obs.instance_id is not None:
            self.instance_votes[obs.instance_id] = self.instance_votes.get(obs.instance_id, 0) + 1
        if obs.embedding is not None:
            if self.embedding is None or self.embedding.shape != obs.embedding.shape:
                self.embedding = obs.embedding
            else:
                e = self.embedding * (self.n_obs - 1) + obs.embedding
                self.embedding = freeze(e / max(float(np.linalg.norm(e)), 1e-12))
        self.last_seen = max(self.last_seen, stamp)
        self.touch()

    def absorb_node(self, other: ObjectNode, cfg: MemoryConfig) -> None:
        """Node-node merge: take over ``other``'s points, votes, observations and anchors."""
        for k, w in other.label_votes.items():
            self.label_votes[k] = self.label_votes.get(k, 0.0) + w
            self.label_features.setdefault(k, other.label_features[k])
        if cfg.node_geometry == "majority_label":
            for k, cloud in other.label_points.items():
                self._add_label_cloud(k, cloud, cfg)
            self._use_majority_cloud(cfg)
        else:
            self._set_points(np.concatenate([self.points, other.points]), cfg)
        n0 = self.n_obs
        self.n_obs += other.n_obs
        self.score_sum += other.score_sum
        self.anchor_ids |= other.anchor_ids
        self.observed_by |= other.observed_by
        for k, v in other.instance_votes.items():
            self.instance_votes[k] = self.instance_votes.get(k, 0) + v
        if other.embedding is not None:
            if self.embedding is None or self.embedding.shape != other.embedding.shape:
                self.embedding = other.embedding
            else:
                e = self.embedding * n0 + other.embedding * other.n_obs
                self.embedding = freeze(e / max(float(np.linalg.norm(e)), 1e-12))
        self.last_seen = max(self.last_seen, other.last_seen)
        self.touch()

    @property
    def gt_instance(self) -> int | None:
        """Majority simulator instance of the oracle detections merged here (diagnostics only)."""
        if not self.instance_votes:
            return None
        return max(sorted(self.instance_votes), key=lambda k: self.instance_votes[k])

    def touch(self) -> None:
        """Mark changed: the next snapshot builds a new view of this node."""
        self._feature = None
        self._view = None

    def view(self) -> ObjectView:
        if self._view is None:
            center = 0.5 * (self.box_min + self.box_max)
            self._view = ObjectView(self.id, self.label, self.confidence, freeze(center.copy()),
                                    freeze(self.box_min.copy()), freeze(self.box_max.copy()),
                                    self.n_obs, self.feature, tuple(sorted(self.anchor_ids)),
                                    self.points, self.last_seen, self.gt_instance,
                                    tuple(sorted(self.observed_by)))
        return self._view
