"""Frontier utility (paper "Context-Aware Frontier Exploration") and utility-induced weights.

S(f) = lambda1 S_struct(f) + lambda2 S_vis(f)                                   (eq. 9)
S_struct(f) = sum_j s~_j exp(-||p_f - p_j||^2 / (2 sigma_j^2))                   (eq. 10-12)
    s_j: task similarity of object j's label (max over the task's target labels), s~_j =
    gamma s_j for objects whose label is a related object of the task (eq. 11). s_j is the
    similarity above a floor, max(0, similarity - similarity_floor): sentence embedders score
    unrelated labels ~0.4-0.5, and without the floor S_struct counts objects rather than
    relevant ones (measured on ProcTHOR: AUC of S_struct for "within 2 m of a target" 0.58
    without, 0.71 with a floor of 0.45 for MiniLM). sigma_j =
    sigma_scale * mean extent of the object's 3D box, clipped to [sigma_min, sigma_max]. The
    paper writes the peak s_j inside phi_j and s~_j again in the sum; we use the single
    factor s~_j (the brief's and ARCHITECTURE's reading) so the peak equals the boosted
    similarity. p_f is the frontier centroid, p_j the object centre, both in world xy (m).
S_vis(f) = s(a_f, T)                                                            (eq. 13)
    a_f: the latest anchor (by stamp) whose horizontal frustum (camera position and yaw from
    T_world_cam, the intrinsics' hfov, range ``vis_range``) contains the frontier centroid;
    s(a, T) = max over the anchor's labels_seen and the task targets of similarity(label,
    target), above the same similarity floor as s_j. 0 when no anchor saw it. Occlusion is not
    modelled (the frustum is a 2D wedge).
W = exp(beta * minmax(S)) / exp(beta)                                            (eq. 16)

Pure functions on read-only inputs; the objects and anchors come from the memory snapshot via
the small Protocols below. This module must not touch the grid, costs or the solvers.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Sequence
from typing import Protocol

import numpy as np

from hiconav.exploration.config import UtilityConfig
from hiconav.types import TaskSpec, label_key

Similarity = Callable[[str, str], float]


class ObjectLike(Protocol):
    """What utility needs of a memory ObjectView."""

    label: str
    center: np.ndarray  # (3,) world m
    box_min: np.ndarray  # (3,) world m
    box_max: np.ndarray  # (3,) world m


class AnchorLike(Protocol):
    """What utility needs of a memory AnchorView."""

    T_world_cam: np.ndarray  # (4, 4) camera -> world
    stamp: float
    labels_seen: tuple[str, ...]

    @property
    def intrinsics(self): ...  # CameraIntrinsics (hfov)


class LabelScorer:
    """Memoised task similarity of labels: max over the task's targets of similarity(label, t).

    Exact (normalised) label matches with a target score 1.0 without calling the embedder.
    """

    def __init__(self, task: TaskSpec, similarity: Similarity) -> None:
        self.targets = tuple(task.targets)
        self._target_norm = {label_key(t) for t in task.targets}
        self.related = {label_key(r) for r in task.related}
        self._similarity = similarity
        self._cache: dict[str, float] = {}

    def __call__(self, label: str) -> float:
        if label not in self._cache:
            if label_key(label) in self._target_norm:
                value = 1.0
            elif not self.targets:
                value = 0.0
            else:
                value = max(float(self._similarity(label, t)) for t in self.targets)
            self._cache[label] = value
        return self._cache[label]

    def is_related(self, label: str) -> bool:
        return label_key(label) in self.related


def object_sigmas(box_min: np.ndarray, box_max: np.ndarray, config: UtilityConfig) -> np.ndarray:
    """sigma_j (m) of boxes (m, 3): sigma_scale * mean extent of each 3D box, clipped (eq. 10)."""
    extent = np.mean(np.abs(np.asarray(box_max, float) - np.asarray(box_min, float)), axis=-1)
    return np.clip(config.sigma_scale * extent, config.sigma_min, config.sigma_max)


def object_sigma(box_min: np.ndarray, box_max: np.ndarray, config: UtilityConfig) -> float:
    """sigma_j (m) of one box (``object_sigmas``)."""
    return float(object_sigmas(box_min, box_max, config))


def object_peaks(objects: Sequence[ObjectLike], scorer: LabelScorer, config: UtilityConfig,
                 drawn: Collection[int] = ()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per object: centre xy (m, 2) world, boosted peak s~_j (m,) (eq. 11), sigma_j (m,) (eq. 10).

    ``drawn``: ids of target candidates set aside as out of reach (seen, often in part or from
    afar, with no view point on the map yet): their sigma_j is at least ``reach_sigma``, so that
    the frontiers on the way to them weigh, not only those within their box's extent.

    Vectorised over the objects (the planner evaluates this for every plan, with ~100 objects);
    the label terms are scored once per distinct label."""
    m = len(objects)
    if m == 0:
        return np.zeros((0, 2)), np.zeros(0), np.ones(0)
    xy = np.array([np.asarray(o.center, dtype=float)[:2] for o in objects]).reshape(m, 2)
    lo = np.array([np.asarray(o.box_min, dtype=float) for o in objects]).reshape(m, -1)
    hi = np.array([np.asarray(o.box_max, dtype=float) for o in objects]).reshape(m, -1)
    sigma = object_sigmas(lo, hi, config)
    by_label: dict[str, float] = {}
    peak = np.zeros(m)
    if drawn and config.reach_sigma > 0.0:
        pulled = np.array([getattr(o, "id", None) in drawn for o in objects], dtype=bool)
        sigma = np.where(pulled, np.maximum(sigma, config.reach_sigma), sigma)
    for j, o in enumerate(objects):
        s = by_label.get(o.label)
        if s is None:
            s = max(0.0, scorer(o.label) - config.similarity_floor)
            if s < config.min_object_similarity:
                s = 0.0
            s = config.gamma * s if scorer.is_related(o.label) else s  # eq. 11
            by_label[o.label] = s
        peak[j] = s
    return xy, peak, sigma


def structural_utility(points_xy: np.ndarray, objects: Sequence[ObjectLike], scorer: LabelScorer,
                       config: UtilityConfig, drawn: Collection[int] = ()) -> np.ndarray:
    """S_struct at points_xy (n, 2) world m -> (n,) (eq. 10-12); ``drawn``: see ``object_peaks``."""
    points_xy = np.asarray(points_xy, dtype=float).reshape(-1, 2)
    if not objects or points_xy.shape[0] == 0:
        return np.zeros(points_xy.shape[0])
    oxy, peak, sigma = object_peaks(objects, scorer, config, drawn)
    d2 = ((points_xy[:, None, :] - oxy[None, :, :]) ** 2).sum(-1)  # (n, m)
    return (peak[None, :] * np.exp(-d2 / (2.0 * sigma[None, :] ** 2))).sum(axis=1)  # eq. 10, 12


def anchor_similarity(anchor: AnchorLike, scorer: LabelScorer, floor: float = 0.0) -> float:
    """s(a, T) (eq. 13): best task similarity among the labels the anchor's image showed, above
    ``floor`` (max(0, s - floor)); 0 for an anchor that saw no label."""
    return max((max(0.0, scorer(label) - floor) for label in anchor.labels_seen), default=0.0)


def in_frustum(anchor: AnchorLike, points_xy: np.ndarray, vis_range: float, margin_rad: float = 0.0
               ) -> np.ndarray:
    """(n,) bool: points (n, 2) world xy inside the anchor camera's horizontal field of view
    (wedge of half-angle hfov/2 + margin about the optical axis projected on the floor, up to
    vis_range metres)."""
    T = np.asarray(anchor.T_world_cam, dtype=float)
    cam = T[:2, 3]
    axis = T[:2, 2]
    norm = float(np.hypot(*axis))
    pts = np.asarray(points_xy, dtype=float).reshape(-1, 2)
    if norm < 1e-9:  # looking straight up/down: no horizontal view
        return np.zeros(pts.shape[0], dtype=bool)
    axis = axis / norm
    rel = pts - cam
    dist = np.hypot(rel[:, 0], rel[:, 1])
    cosang = (rel @ axis) / np.maximum(dist, 1e-12)
    half = anchor.intrinsics.hfov / 2.0 + margin_rad
    return (dist <= vis_range) & ((cosang >= math.cos(min(half, math.pi))) | (dist < 1e-9))


def visual_utility(points_xy: np.ndarray, anchors: Sequence[AnchorLike], scorer: LabelScorer,
                   config: UtilityConfig) -> np.ndarray:
    """S_vis at points_xy (n, 2) world m -> (n,): similarity of the latest anchor whose frustum
    contains the point, 0 if none (eq. 13)."""
    pts = np.asarray(points_xy, dtype=float).reshape(-1, 2)
    out = np.zeros(pts.shape[0])
    assigned = np.zeros(pts.shape[0], dtype=bool)
    margin = math.radians(config.vis_hfov_margin_deg)
    for anchor in sorted(anchors, key=lambda a: a.stamp, reverse=True):  # latest first
        if assigned.all():
            break
        inside = in_frustum(anchor, pts, config.vis_range, margin) & ~assigned
        if inside.any():
            out[inside] = anchor_similarity(anchor, scorer, config.similarity_floor)
            assigned |= inside
    return out


def frontier_utility(points_xy: np.ndarray, objects: Sequence[ObjectLike], anchors: Sequence[AnchorLike],
                     task: TaskSpec, similarity: Similarity, config: UtilityConfig | None = None,
                     drawn: Collection[int] = ()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """S (eq. 9), S_struct (eq. 12), S_vis (eq. 13) at points_xy (n, 2) -> three (n,) arrays.

    The ablation switches use_struct / use_vis zero the corresponding term. ``drawn``: ids of
    target candidates out of reach (``object_peaks``).
    """
    cfg = config or UtilityConfig()
    scorer = LabelScorer(task, similarity)
    pts = np.asarray(points_xy, dtype=float).reshape(-1, 2)
    s_struct = structural_utility(pts, objects, scorer, cfg, drawn) if cfg.use_struct else np.zeros(len(pts))
    s_vis = visual_utility(pts, anchors, scorer, cfg) if cfg.use_vis else np.zeros(len(pts))
    return cfg.lambda1 * s_struct + cfg.lambda2 * s_vis, s_struct, s_vis  # eq. 9


def utility_weights(S: np.ndarray, beta: float, min_range: float = 0.0) -> np.ndarray:
    """W = exp(beta * S_bar) / exp(beta * max S_bar) (eq. 16), S_bar = (S - S_min) / max(S_max -
    S_min, ``min_range``): with the plain min-max max S_bar = 1, the paper's / exp(beta). W in
    (0, 1], the best frontier's 1; all-equal S gives W = 1.

    The plain min-max (``min_range`` 0) stretches any spread to [0, 1]: utilities 0.02 apart
    weigh 1 and exp(-beta) as surely as ones 1.0 apart. With a floor, a spread below it is
    treated as the evidence's noise: the weights stay near 1 and travel time orders the
    frontiers."""
    S = np.asarray(S, dtype=float)
    if S.size == 0:
        return S.copy()
    lo, hi = float(S.min()), float(S.max())
    if hi - lo <= 1e-12 * max(1.0, abs(hi)):
        return np.ones_like(S)
    s_bar = (S - lo) / max(hi - lo, float(min_range))
    return np.exp(beta * (s_bar - float(s_bar.max())))  # = exp(beta s_bar) / exp(beta max), no overflow
