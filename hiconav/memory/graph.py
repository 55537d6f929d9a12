"""The cognitive memory graph (CMG), G = (V_a, V_o, E) of eq. (1): build, merge, prune, snapshot.

``CognitiveMemoryGraph.update(frame, detections)`` lifts detections to 3D, runs the anchor gate
(eq. 2), and for a selected anchor merges every mapped detection into the most similar object
node when s >= tau (eq. 4) or creates a node, adds the bipartite anchor-object edges, then merges
object nodes that have come to overlap (node-node merging as views accumulate).
``prune()`` solves the weighted set multicover of eqs. (5)-(7) with ``setcover.solve_multicover``
and removes the anchors it does not select, with their edges. ``snapshot()`` returns an
immutable ``MemorySnapshot`` that shares every unchanged view with the previous one.

The graph is pure and synchronous: no threads, no actors, no I/O. It is owned by one caller (the
MemoryActor); other actors only ever see snapshots.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from hiconav.errors import FrameError
from hiconav.memory.anchors import Anchor, AnchorGate, downscale_image, image_quality
from hiconav.memory.config import MemoryConfig
from hiconav.memory.objects import ObjectNode, ObjectObservation, lift_detection, merge_scores
from hiconav.memory.setcover import multicover_requirements, solve_multicover
from hiconav.memory.snapshot import MemorySnapshot
from hiconav.types import Detection, Frame, TaskSpec

if TYPE_CHECKING:
    from hiconav.memory.subgraphs import Subgraph
    from hiconav.perception.embedder import Embedder

__all__ = ["CognitiveMemoryGraph", "MemoryUpdate", "PruneResult"]


@dataclass(frozen=True)
class MemoryUpdate:
    """What one ``update`` did.

    reason: the gate's reason ("first", "new_object", "translation", "rotation") or "" when the
    frame was not selected as an anchor. new_object_ids: nodes created; updated_object_ids:
    existing nodes that absorbed a detection; merged: (kept id, removed id) node-node merges.
    n_far: detections kept only as labels (beyond max depth or without valid depth).
    """

    version: int
    stamp: float
    is_anchor: bool
    reason: str
    anchor_id: int | None
    new_object_ids: tuple[int, ...]
    updated_object_ids: tuple[int, ...]
    merged: tuple[tuple[int, int], ...]
    n_detections: int
    n_mapped: int
    n_far: int
    time_ms: float


@dataclass(frozen=True)
class PruneResult:
    """Outcome of one anchor pruning (eqs. 5-7).

    status: ``SetCoverResult.status`` ("optimal", "trivial", "time-limit", "greedy-fallback") or
    "empty"; n_elements: rows of the multicover (objects plus far-evidence labels).
    """

    kept_anchor_ids: tuple[int, ...]
    removed_anchor_ids: tuple[int, ...]
    status: str
    proven_optimal: bool
    cost: float
    n_objects: int
    n_elements: int
    time_ms: float
    solver_ms: float
    message: str = ""

    @property
    def is_fallback(self) -> bool:
        return self.status == "greedy-fallback"


def _normalise(label: str) -> str:
    from hiconav.perception.detector import normalise_label

    return normalise_label(label)


class CognitiveMemoryGraph:
    """The CMG of one episode (bipartite anchors <-> object nodes).

    config: ``MemoryConfig`` (defaults from the paper / issue #5); embedder: an object with
    ``embed(texts) -> (N, D) float32`` unit rows (``hiconav.perception.Embedder``); None loads
    ``get_embedder(config.embedder)`` on first use.
    """

    def __init__(self, config: MemoryConfig | None = None, embedder: Embedder | None = None) -> None:
        self.config = config or MemoryConfig()
        self._embedder = embedder
        self.gate = AnchorGate(self.config.delta_d, self.config.delta_theta_deg)
        self.objects: dict[int, ObjectNode] = {}
        self.anchors: dict[int, Anchor] = {}
        self.version = 0
        self.stamp = 0.0
        self._next_object = 0
        self._next_anchor = 0
        self._known_labels: set[str] = set()
        self._snapshot: MemorySnapshot | None = None
        self._label_cache: dict[str, np.ndarray] = {}
        self._arrays: tuple | None = None  # stacked node boxes/features, None when stale

    # ------------------------------------------------------------------ helpers
    @property
    def embedder(self) -> Embedder:
        if self._embedder is None:
            from hiconav.perception import get_embedder

            self._embedder = get_embedder(self.config.embedder)
        return self._embedder

    def _features(self, labels: Sequence[str]) -> dict[str, np.ndarray]:
        missing = sorted({lab for lab in labels if lab not in self._label_cache})
        if missing:
            vecs = np.asarray(self.embedder.embed(missing), dtype=np.float32)
            for lab, v in zip(missing, vecs):
                v = v / max(float(np.linalg.norm(v)), 1e-12)
                v.flags.writeable = False
                self._label_cache[lab] = v
        return {lab: self._label_cache[lab] for lab in labels}

    def _node_arrays(self, exclude: int | None = None
                     ) -> tuple[list[int], np.ndarray, np.ndarray, np.ndarray, list]:
        """(ids, mins (K, 3), maxs (K, 3), features (K, D), embeddings) of all nodes but
        ``exclude``; the stacked arrays are cached until a node is added, merged or removed
        (``_dirty``); a node that absorbs an observation updates its own row (``_refresh``)."""
        if self._arrays is None:
            ids = list(self.objects)
            nodes = [self.objects[i] for i in ids]
            if nodes:
                self._arrays = (ids, np.stack([n.box_min for n in nodes]),
                                np.stack([n.box_max for n in nodes]),
                                np.stack([n.feature for n in nodes]), [n.embedding for n in nodes])
            else:
                self._arrays = ([], np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 0), np.float32), [])
        ids, mins, maxs, feats, embs = self._arrays
        if exclude is not None and exclude in self.objects:
            i = ids.index(exclude)
            keep = np.arange(len(ids)) != i
            return ids[:i] + ids[i + 1:], mins[keep], maxs[keep], feats[keep], embs[:i] + embs[i + 1:]
        return ids, mins, maxs, feats, embs

    def _dirty(self) -> None:
        self._arrays = None

    def _refresh(self, node_id: int) -> None:
        """Node ``node_id`` changed in place (absorbed an observation): update its row of the
        stacked arrays instead of restacking every node on the next match (every frame absorbs)."""
        if self._arrays is None:
            return
        ids, mins, maxs, feats, embs = self._arrays
        try:
            i = ids.index(node_id)
        except ValueError:
            self._arrays = None
            return
        node = self.objects[node_id]
        if feats.shape[1:] != np.shape(node.feature):
            self._arrays = None
            return
        mins[i], maxs[i], feats[i] = node.box_min, node.box_max, node.feature
        embs[i] = node.embedding

    def _best_match(self, obs: ObjectObservation) -> tuple[int | None, float]:
        ids, mins, maxs, feats, embs = self._node_arrays()
        if not ids:
            return None, 0.0
        s = merge_scores(obs.box_min, obs.box_max, obs.feature, obs.embedding, mins, maxs, feats,
                         embs, self.config)  # eq. (4)
        j = int(np.argmax(s))
        if s[j] >= self.config.tau:
            return ids[j], float(s[j])
        return None, float(s[j])

    # ------------------------------------------------------------------ update
    def update(self, frame: Frame, detections: Sequence[Detection], *, keyframe: bool = False) -> MemoryUpdate:
        """Integrate one frame and its detections (eqs. 2-4); returns what changed.

        frame: RGB-D frame with pose (``Frame``); detections: boxes (pixels), optional (H, W)
        masks and embeddings. Only frames selected as anchors change the graph (paper), unless
        ``config.update_objects_every_frame``. ``keyframe``: a consumer asked for this frame as an
        anchor (``AnchorGate.decide``'s ``requested``).
        """
        t0 = time.perf_counter()
        cfg = self.config
        if frame.depth is None or frame.T_world_cam is None:
            raise FrameError("the memory graph needs depth and T_world_cam", field="frame")
        dets = [d for d in detections if d.score >= cfg.min_score]
        labels = [_normalise(d.label) for d in dets]
        feats = self._features(labels) if labels else {}
        observations: list[ObjectObservation] = []
        far: list[str] = []
        for d, lab in zip(dets, labels):
            if lab != d.label:
                d = Detection(lab, d.score, d.box_xyxy, d.mask, d.embedding, d.source, d.instance_id)
            obs = lift_detection(frame, d, cfg, feats[lab])
            if obs is None:
                far.append(lab)
            else:
                observations.append(obs)
        observations.sort(key=lambda o: -o.score)
        matches = [self._best_match(o)[0] for o in observations]
        new_object = any(m is None for m in matches)
        if cfg.anchor_on_new_label and any(lab not in self._known_labels for lab in far):
            new_object = True
        decision = self.gate.decide(frame.base_pose, new_object, requested=keyframe)  # eq. (2)
        self.stamp = float(frame.stamp)

        new_ids: list[int] = []
        updated: list[int] = []
        merged: list[tuple[int, int]] = []
        anchor_id: int | None = None
        if decision.is_anchor:
            self.gate.accept(frame.base_pose)
            anchor = self._new_anchor(frame, labels, observations, far)
            anchor_id = anchor.id
            touched: list[int] = []
            for obs in observations:
                j, _ = self._best_match(obs)  # again: nodes created from this frame count too
                if j is None:
                    node = ObjectNode.from_observation(self._next_object, obs, self.stamp, cfg)
                    self._next_object += 1
                    self.objects[node.id] = node
                    self._dirty()
                    new_ids.append(node.id)
                    j = node.id
                else:
                    self.objects[j].absorb(obs, self.stamp, cfg)
                    self._refresh(j)
                    updated.append(j)
                node = self.objects[j]
                node.anchor_ids.add(anchor.id)  # bipartite edge (a_i, o_j)
                node.observed_by.add(anchor.id)
                node.touch()
                anchor.add_box(j, obs.box_norm, (obs.label,))
                touched.append(j)
            if cfg.merge_nodes:
                merged = self._merge_nodes(touched)
            self._known_labels.update(labels)
            self.version += 1
        elif cfg.update_objects_every_frame and observations:
            for obs, j in zip(observations, matches):
                if j is not None:
                    self.objects[j].absorb(obs, self.stamp, cfg)
                    self._refresh(j)
                    updated.append(j)
            if updated:
                if cfg.merge_nodes:
                    merged = self._merge_nodes(updated)
                self.version += 1
        removed = {b for _, b in merged}
        return MemoryUpdate(self.version, self.stamp, decision.is_anchor, decision.reason, anchor_id,
                            tuple(i for i in new_ids if i not in removed),
                            tuple(sorted(set(updated) - removed)), tuple(merged), len(dets),
                            len(observations), len(far), 1e3 * (time.perf_counter() - t0))

    def _new_anchor(self, frame: Frame, labels: list[str], observations: list[ObjectObservation],
                    far: list[str]) -> Anchor:
        cfg = self.config
        image = downscale_image(frame.rgb, cfg.image_width, cfg.image_height)
        seen = tuple(dict.fromkeys(labels))
        if seen:
            f = np.mean(np.stack([self._label_cache[lab] for lab in seen]), axis=0)
            desc = f / max(float(np.linalg.norm(f)), 1e-12)
        else:
            desc = np.zeros(0, dtype=np.float32)
        quality = image_quality(image) if cfg.anchor_cost == "quality" else 1.0
        anchor = Anchor.from_frame(self._next_anchor, frame, image, seen, desc, quality)
        mapped = {o.label for o in observations}
        anchor.far_labels = tuple(dict.fromkeys(lab for lab in far if lab not in mapped))
        self._next_anchor += 1
        self.anchors[anchor.id] = anchor
        return anchor

    def _co_observed(self, a: ObjectNode, b: ObjectNode) -> bool:
        return bool(a.anchor_ids & b.anchor_ids)

    def _merge_nodes(self, touched: Sequence[int]) -> list[tuple[int, int]]:
        """Node-node merging (eq. 4 between nodes): a touched node that now scores >= tau
        against another node is merged into the older one. Nodes observed as separate
        detections by one anchor are never merged (that image shows them apart)."""
        merged: list[tuple[int, int]] = []
        queue = list(dict.fromkeys(touched))
        while queue:
            t = queue.pop(0)
            node = self.objects.get(t)
            if node is None:
                continue
            ids, mins, maxs, feats, embs = self._node_arrays(exclude=t)
            if not ids:
                continue
            s = merge_scores(node.box_min, node.box_max, node.feature, node.embedding, mins, maxs,
                             feats, embs, self.config)
            for j in np.argsort(-s):
                if s[j] < self.config.tau:
                    break
                other = self.objects[ids[int(j)]]
                if self._co_observed(node, other):
                    continue
                keep, drop = (node, other) if node.id < other.id else (other, node)
                keep.absorb_node(drop, self.config)
                for aid in drop.anchor_ids:
                    self.anchors[aid].replace_object(drop.id, keep.id)
                del self.objects[drop.id]
                self._dirty()
                merged.append((keep.id, drop.id))
                queue.append(keep.id)  # it grew: check it again
                break
        return merged

    # ------------------------------------------------------------------ pruning
    def cover_matrix(self) -> tuple[list[int], list[int], sp.csr_matrix]:
        """(object ids, anchor ids, (n_objects, n_anchors) 0/1 CSR incidence of edges E)."""
        oids = list(self.objects)
        aids = list(self.anchors)
        orow = {o: i for i, o in enumerate(oids)}
        rows, cols = [], []
        for c, aid in enumerate(aids):
            for oid in self.anchors[aid].boxes:
                rows.append(orow[oid])
                cols.append(c)
        A = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(oids), len(aids)))
        return oids, aids, A

    def prune(self, time_limit: float | None = None) -> PruneResult:
        """Anchor pruning, eqs. (5)-(7): keep a min-cost set of anchors covering every object
        node r_j = min(r, deg(o_j)) times; remove the other anchors and their edges.

        Far-evidence labels (``config.keep_far_evidence``) add one row each (r_j = 1). The newest
        anchor is kept when ``config.keep_latest_anchor`` (cost 0, so forced).
        """
        t0 = time.perf_counter()
        cfg = self.config
        oids, aids, A = self.cover_matrix()
        if not aids:
            return PruneResult((), (), "empty", True, 0.0, 0, 0, 1e3 * (time.perf_counter() - t0), 0.0)
        req = multicover_requirements(A, cfg.r)  # eq. (7)
        if cfg.keep_far_evidence:
            object_labels = {n.label for n in self.objects.values()}
            far_rows: dict[str, list[int]] = {}
            for c, aid in enumerate(aids):
                for lab in self.anchors[aid].far_labels:
                    if lab not in object_labels:
                        far_rows.setdefault(lab, []).append(c)
            if far_rows:
                r_idx = [i for i, cs in enumerate(far_rows.values()) for _ in cs]
                c_idx = [c for cs in far_rows.values() for c in cs]
                F = sp.csr_matrix((np.ones(len(r_idx)), (r_idx, c_idx)), shape=(len(far_rows), len(aids)))
                A = sp.vstack([A, F]).tocsr()
                req = np.concatenate([req, np.ones(len(far_rows), dtype=np.int64)])
        if cfg.anchor_cost == "quality":
            costs = np.array([1.0 + cfg.quality_weight * (1.0 - self.anchors[a].quality) for a in aids])
        else:
            costs = np.ones(len(aids))  # c_i = 1: minimise the number of anchors
        if cfg.keep_latest_anchor:
            costs[len(aids) - 1] = 0.0  # dict order: the newest anchor is last
        res = solve_multicover(costs, A, req, time_limit=time_limit or cfg.prune_time_limit_s)
        keep = {aids[i] for i in res.selected}
        removed = tuple(a for a in aids if a not in keep)
        for aid in removed:
            anchor = self.anchors.pop(aid)
            for oid in anchor.boxes:
                node = self.objects[oid]
                node.anchor_ids.discard(aid)
                node.touch()
        if removed:
            self.version += 1
        return PruneResult(tuple(a for a in aids if a in keep), removed, res.status, res.proven_optimal,
                           float(sum(costs[i] for i in res.selected)), len(oids), A.shape[0],
                           1e3 * (time.perf_counter() - t0), 1e3 * res.time_s, res.message)

    # ------------------------------------------------------------------ views
    def snapshot(self) -> MemorySnapshot:
        """Immutable state for other actors; unchanged object/anchor views are shared with the
        previous snapshot, and the same snapshot object is returned while nothing changed."""
        snap = self._snapshot
        if snap is not None and snap.version == self.version and snap.stamp == self.stamp:
            return snap
        snap = MemorySnapshot(self.version, self.stamp,
                              tuple(n.view() for n in self.objects.values()),
                              tuple(a.view() for a in self.anchors.values()))
        self._snapshot = snap
        return snap

    def decompose(self, snapshot: MemorySnapshot, task: TaskSpec,
                  similarity: Callable[[str, str], float], k: int | None = None) -> list[Subgraph]:
        """Subgraph decomposition (eqs. 8-11); see ``hiconav.memory.subgraphs.decompose``."""
        from hiconav.memory.subgraphs import decompose

        return decompose(snapshot, task, similarity, k=k or self.config.k,
                         label_match_threshold=self.config.label_match_threshold,
                         far_evidence_weight=self.config.far_evidence_weight)

    @property
    def n_objects(self) -> int:
        return len(self.objects)

    @property
    def n_anchors(self) -> int:
        return len(self.anchors)
