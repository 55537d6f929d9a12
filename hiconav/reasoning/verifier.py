"""Subgraph verification: is the target in this subgraph, and where? (VLM or offline).

Paper, section "Deep Reasoning", paragraph "VLM Reasoning". ``VLMVerifier`` sends one request per
subgraph (<= k anchor images with their object lists, the three-step prompt of ``prompts.py``)
and validates the reply (``replies.py``). ``OfflineVerifier`` answers the same question from the
memory graph alone (labels, similarity, detector confidence, observation count) and labels its
hypotheses source="offline".

Contract: ``verify`` never raises and never returns anything but a ``VerifyResult``; anything
invalid, truncated, oversized, late or instruction-like, and a reply that found something other
than the task's target, becomes "not found" with a reason code (logged). No result carries a
motion command.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Protocol, runtime_checkable

import numpy as np

from hiconav.reasoning.grounding import ground, infer_rooms, target_relations
from hiconav.reasoning.room_prior import load as load_room_prior
from hiconav.reasoning.room_prior import log_ratios
from hiconav.reasoning.size_prior import default_sizes
from hiconav.reasoning.size_prior import load as load_size_prior

from hiconav.reasoning import replies
from hiconav.reasoning.config import ReasoningConfig
from hiconav.reasoning.hypothesis import TargetHypothesis
from hiconav.reasoning.prompts import ViewIndex, verification_messages
from hiconav.registry import Registry
from hiconav.types import TaskSpec, label_key

log = logging.getLogger(__name__)

VERIFIERS: Registry = Registry("verifier")

FOUND = "ok"
EMPTY_SUBGRAPH = "empty_subgraph"
LATE = "late"
INTERNAL = "internal_error"
NO_MATCH = "no_matching_object"
FEW_OBSERVATIONS = "insufficient_observations"
LOW_CONFIDENCE = "low_confidence"
RELATION_FAILED = "relation_failed"  # a described instance: another instance, or the description does not fit
RELATION_UNKNOWN = "relation_unverified"  # a described instance: the related objects or room not seen yet
# Failures of the transport rather than of the answer: the reasoner may ask again.
TRANSIENT = frozenset({"timeout", "transport", "truncated", "cancelled", "late", "http_408", "http_409",
                       "http_425", "http_429", "http_500", "http_502", "http_503", "http_504"})


# ------------------------------------------------------------------ what we read from memory
class ObjectLike(Protocol):
    """The fields of ``hiconav.memory.ObjectView`` used here."""

    id: int
    label: str
    confidence: float
    n_obs: int
    anchor_ids: tuple[int, ...]


class AnchorLike(Protocol):
    """The fields of ``hiconav.memory.AnchorView`` used here."""

    id: int
    image: np.ndarray  # (h, w, 3) uint8 RGB
    object_ids: tuple[int, ...]
    boxes: np.ndarray  # (n, 4) normalised xyxy, row j for object_ids[j]
    labels_seen: tuple[str, ...]


class SubgraphLike(Protocol):
    """The fields of ``hiconav.memory.Subgraph`` used here."""

    kind: str
    anchors: Sequence[AnchorLike]
    objects: Sequence[ObjectLike]
    priority: float
    signature: tuple


@dataclass(frozen=True)
class VerifyResult:
    """The answer for one subgraph.

    found: a hypothesis was produced; reason: "ok" when found, "not_visible" when a valid answer
    says no, else the rejection code (replies.* codes, transport errors like "timeout",
    "http_500", "oversized", or "late"); detail: human-readable; latency_s: request wall time.
    """

    found: bool
    hypothesis: TargetHypothesis | None
    reason: str
    detail: str
    latency_s: float
    source: str
    subgraph_signature: tuple
    # object id -> "holds" | "fails" | "unknown": the grounding of a described instance's
    # relations on each candidate node the verifier judged (empty when it judged none)
    verdicts: Mapping[int, str] = field(default_factory=dict)

    @property
    def rejected(self) -> bool:
        """The answer could not be used (as opposed to a valid "found" or "not visible")."""
        return self.reason not in (FOUND, replies.NOT_VISIBLE, NO_MATCH, FEW_OBSERVATIONS,
                                   LOW_CONFIDENCE, EMPTY_SUBGRAPH)

    @property
    def transient(self) -> bool:
        return self.reason in TRANSIENT or self.reason.startswith("http_5")


@runtime_checkable
class Verifier(Protocol):
    source: str

    def verify(self, subgraph: SubgraphLike, task: TaskSpec) -> VerifyResult:
        ...


def _not_found(subgraph: Any, source: str, reason: str, detail: str, latency: float) -> VerifyResult:
    # a VLM reply that was rejected (malformed, out of range, late...) is worth a warning; "not there
    # yet" answers, and every answer of the offline verifier, are the normal course of a search
    normal = reason in (replies.NOT_VISIBLE, NO_MATCH) or source != "vlm"
    level = logging.INFO if normal else logging.WARNING
    log.log(level, "%s verifier: not found (%s): %s", source, reason, detail[:300])
    signature = tuple(getattr(subgraph, "signature", ()))
    return VerifyResult(False, None, reason, detail, latency, source, signature)


@VERIFIERS.register("vlm")
class VLMVerifier:
    """Asks the VLM about one subgraph per call (``client``: a ``VLMClient``)."""

    source = "vlm"

    def __init__(self, client: Any, config: ReasoningConfig | None = None) -> None:
        self.client = client
        self.config = config or ReasoningConfig()

    def cancel(self) -> None:
        self.client.cancel()

    def verify(self, subgraph: SubgraphLike, task: TaskSpec) -> VerifyResult:
        t0 = time.monotonic()
        try:
            return self._verify(subgraph, task, t0)
        except Exception as exc:
            log.exception("VLM verifier internal error")
            return _not_found(subgraph, self.source, INTERNAL, f"{type(exc).__name__}: {exc}",
                              time.monotonic() - t0)

    def _verify(self, subgraph: SubgraphLike, task: TaskSpec, t0: float) -> VerifyResult:
        cfg = self.config
        if not subgraph.anchors:
            return _not_found(subgraph, self.source, EMPTY_SUBGRAPH, "subgraph has no anchors", 0.0)
        messages, index = verification_messages(
            task, subgraph, k=cfg.k, max_objects=cfg.max_objects_per_anchor, images=cfg.vlm.vision,
            image_format=cfg.vlm.image_format, image_max_side=cfg.vlm.image_max_side,
            jpeg_quality=cfg.vlm.jpeg_quality)
        result = self.client.chat(messages)
        latency = result.latency_s
        if not result.ok:
            return _not_found(subgraph, self.source, result.error or "transport", result.detail, latency)
        if cfg.max_latency_s is not None and latency > cfg.max_latency_s:
            return _not_found(subgraph, self.source, LATE,
                              f"reply after {latency:.2f} s > max_latency_s {cfg.max_latency_s}", latency)
        try:
            reply = replies.parse_verification(result.content, index.objects_per_view,
                                               finish_reason=result.finish_reason, message=result.message,
                                               labels=index.labels, targets=task.targets)
        except replies.ReplyError as exc:
            return _not_found(subgraph, self.source, exc.reason, exc.detail, latency)
        if not reply.visible:
            return _not_found(subgraph, self.source, replies.NOT_VISIBLE,
                              reply.evidence or "the VLM says the target is not visible", latency)
        return self._hypothesis(subgraph, task, index, reply, latency)

    def _hypothesis(self, subgraph: SubgraphLike, task: TaskSpec, index: ViewIndex,
                    reply: replies.VerificationReply, latency: float) -> VerifyResult:
        assert reply.view is not None and reply.bbox is not None  # parse_verification guarantees
        anchor_id = index.anchor_ids[reply.view]
        object_id = None if reply.object is None else index.object_ids[reply.view][reply.object]
        confidence = reply.confidence if reply.confidence is not None else self.config.default_vlm_confidence
        label = reply.target or (task.targets[0] if task.targets else "")
        hyp = TargetHypothesis(anchor_id=anchor_id, object_id=object_id, bbox=np.asarray(reply.bbox),
                               confidence=float(confidence), evidence=reply.evidence, latency_s=latency,
                               source=self.source, subgraph_signature=tuple(subgraph.signature),
                               label=label)
        log.info("VLM verifier: target %r in anchor %d object %s bbox %s (%.2f)", label, anchor_id,
                 object_id, reply.bbox, confidence)
        return VerifyResult(True, hyp, FOUND, reply.evidence, latency, self.source, tuple(subgraph.signature))


@VERIFIERS.register("offline")
class OfflineVerifier:
    """Answers from the memory graph alone (no VLM): a labelled fallback, source="offline".

    An object node supports the target when its label equals a target label (or has similarity
    >= ``min_similarity`` to it), its detector confidence is >= ``min_confidence`` and it was
    observed >= ``min_observations`` times. When the instruction describes one instance (relations
    whose subject is the target: "the armchair next to the floor lamp in the living room"), the
    node must also satisfy every such relation on the subgraph (``grounding.ground``: rooms
    inferred from the objects seen with it, relations on the nodes' 3D boxes), grounded only on
    nodes that pass the same confidence and observation floors as the target's own. The hypothesis
    uses the anchor in which the node's box is largest. Attributes are not checked (said in the
    evidence).
    """

    source = "offline"

    def __init__(self, config: ReasoningConfig | None = None,
                 similarity: Callable[[str, str], float] | None = None) -> None:
        self.config = config or ReasoningConfig()
        self.similarity = similarity
        path = self.config.offline.room_prior
        try:
            self._room_cues = log_ratios(load_room_prior(path)) if path else None
        except (OSError, ValueError) as exc:
            raise ValueError(f"reasoning.offline.room_prior: {exc}") from None
        path = self.config.offline.size_prior
        try:
            self._sizes = dict(load_size_prior(path).sizes) if path else default_sizes()
        except (OSError, ValueError) as exc:
            raise ValueError(f"reasoning.offline.size_prior: {exc}") from None

    def cancel(self) -> None:  # same interface as VLMVerifier; nothing in flight
        return None

    def _match(self, label: str, targets: Sequence[str]) -> tuple[float, str]:
        best, best_t = 0.0, ""
        norm = label_key(label)
        for t in targets:
            if norm == label_key(t):
                return 1.0, t
            if self.similarity is not None:
                s = float(self.similarity(norm.replace("_", " "), t.replace("_", " ")))
                if s > best:
                    best, best_t = s, t
        return best, best_t

    def _weak(self, obj: ObjectLike) -> str | None:
        """Why a node is seen too weakly to count (LOW_CONFIDENCE, FEW_OBSERVATIONS), or None."""
        cfg = self.config.offline
        if obj.confidence < cfg.min_confidence and not (cfg.confident_observations
                                                        and obj.n_obs >= cfg.confident_observations):
            return LOW_CONFIDENCE
        if obj.n_obs < cfg.min_observations:
            return FEW_OBSERVATIONS
        return None

    def verify(self, subgraph: SubgraphLike, task: TaskSpec) -> VerifyResult:
        t0 = time.perf_counter()
        try:
            return self._verify(subgraph, task, t0)
        except Exception as exc:
            log.exception("offline verifier internal error")
            return _not_found(subgraph, self.source, INTERNAL, f"{type(exc).__name__}: {exc}",
                              time.perf_counter() - t0)

    def _verify(self, subgraph: SubgraphLike, task: TaskSpec, t0: float) -> VerifyResult:
        cfg = self.config.offline
        if not subgraph.anchors:
            return _not_found(subgraph, self.source, EMPTY_SUBGRAPH, "subgraph has no anchors", 0.0)
        anchors = list(subgraph.anchors)
        best: tuple | None = None
        reasons: list[str] = []
        described = bool(target_relations(task.relations, task.targets))
        objects = list(subgraph.objects)
        context = list(getattr(subgraph, "context", ()) or ())
        # the related objects a relation is grounded on must be seen as surely as a target must
        # be: a detector's false positive or confused label ("sink" on a bathtub) seen once
        # would otherwise confirm the wrong instance beside it
        support = [o for o in objects + context if self._weak(o) is None] if described else []
        # and so must the objects that tell a room (a false "bed" makes a bedroom)
        # (the most probable room at any posterior: ``ground`` reads it against ROOM_MIN_POSTERIOR)
        rooms = infer_rooms(support, ignore=task.targets, cues=self._room_cues, min_posterior=0.0) \
            if described else None
        groundings: dict[int, Any] = {}
        for obj in subgraph.objects:
            score, target = self._match(obj.label, task.targets)
            if score < 1.0 and score < cfg.min_similarity:
                continue
            if (weak := self._weak(obj)) is not None:
                reasons.append(weak)
                continue
            view = self._best_view(obj, anchors)
            if view is None:
                reasons.append(NO_MATCH)
                continue
            if described:
                # relations on the map: the subgraph's objects and the nodes mapped near it
                verdict = ground(obj, support, task.relations, task.targets, rooms, self._sizes)
                groundings[obj.id] = verdict
                if verdict.status != "holds":
                    reasons.append(RELATION_FAILED if verdict.status == "fails" else RELATION_UNKNOWN)
                    continue
            key = (score * obj.confidence, obj.n_obs, -obj.id)
            if best is None or key > best[0]:
                best = (key, obj, score, target, view)
        latency = time.perf_counter() - t0
        verdicts = {oid: g.status for oid, g in groundings.items()}
        if best is None:
            reason = next((r for r in (RELATION_UNKNOWN, RELATION_FAILED, FEW_OBSERVATIONS, LOW_CONFIDENCE)
                           if r in reasons), NO_MATCH)
            detail = "; ".join(f"#{oid}: {' | '.join(g.evidence)}" for oid, g in groundings.items())
            return replace(_not_found(subgraph, self.source, reason,
                                      f"no object node supports {'/'.join(task.targets)} ({reason})"
                                      + (f": {detail}" if detail else ""), latency), verdicts=verdicts)
        _, obj, score, target, (anchor, bbox) = best
        attrs = [a for t in task.targets for a in task.attributes.get(t, ())]
        evidence = (f"offline: object node {obj.id} labelled {obj.label!r} (similarity {score:.2f} to "
                    f"{target!r}), detector confidence {obj.confidence:.2f}, seen {obj.n_obs} times")
        if attrs:
            evidence += f"; attributes not checked: {', '.join(attrs)}"
        if obj.id in groundings:
            evidence += "; " + "; ".join(groundings[obj.id].evidence)
        hyp = TargetHypothesis(anchor_id=int(anchor.id), object_id=int(obj.id), bbox=bbox,
                               confidence=float(score * obj.confidence), evidence=evidence,
                               latency_s=latency, source=self.source,
                               subgraph_signature=tuple(subgraph.signature), label=target)
        return VerifyResult(True, hyp, FOUND, evidence, latency, self.source, tuple(subgraph.signature),
                            verdicts)

    @staticmethod
    def _best_view(obj: ObjectLike, anchors: Sequence[AnchorLike]) -> tuple[AnchorLike, np.ndarray] | None:
        return best_view(obj, anchors)


def best_view(obj: ObjectLike, anchors: Sequence[AnchorLike]) -> tuple[AnchorLike, np.ndarray] | None:
    """The anchor of ``anchors`` where ``obj``'s image box is largest, and that box (normalised
    xyxy); None when no anchor holds a valid box of it."""
    best = None
    for anchor in anchors:
        ids = list(anchor.object_ids)
        if obj.id not in ids:
            continue
        j = ids.index(obj.id)
        boxes = np.asarray(anchor.boxes, dtype=float).reshape(-1, 4)
        if j >= len(boxes):
            continue
        box = np.clip(boxes[j], 0.0, 1.0)
        area = (box[2] - box[0]) * (box[3] - box[1])
        if not np.all(np.isfinite(box)) or box[2] <= box[0] or box[3] <= box[1]:
            continue
        if best is None or area > best[0]:
            best = (area, anchor, box)
    return None if best is None else (best[1], best[2])


def make_verifier(config: ReasoningConfig | None = None,
                  similarity: Callable[[str, str], float] | None = None) -> VLMVerifier | OfflineVerifier:
    """The verifier the config selects: the VLM when an endpoint is configured (and the backend
    is not "offline"), else the offline verifier (logged as a fallback when "vlm" was forced)."""
    config = config or ReasoningConfig()
    if config.use_vlm():
        from hiconav.reasoning.vlm_client import VLMClient

        return VLMVerifier(VLMClient(config.vlm), config)
    if config.backend == "vlm":
        log.warning("FALLBACK: backend 'vlm' but reasoning.vlm.base_url is not set; using the offline verifier")
    return OfflineVerifier(config, similarity)
