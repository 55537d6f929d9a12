"""Subgraph decomposition of the CMG for the reasoner (paper "Subgraph Decomposition", eqs. 8-11).

Given a snapshot and the task's target set O_t and related set O_r:
1. for each target object o_t: the anchors observing it (V_a^t), and all objects those anchors
   observe (V_o^t = union of O(a_i), eqs. 9-10); kind "target";
2. the same for each related object; kind "related";
3. the remaining anchors (in none of the above) each with their objects, grouped into subgraphs
   of at most k anchors (anchors ranked by their own score, so the most promising are grouped
   first); kind "remaining".
Every subgraph holds at most k anchors: when an object has more observers, the k with the
largest view of it (2D box area) form its subgraph and the rest fall to "remaining".
Target subgraphs come first, then related, then remaining ordered by
S(G_k) = sum_{o_i in V_o^k} s(o_i, T) (eq. 11), plus ``far_evidence_weight`` times the
similarity of labels seen only beyond the mapping depth (0 gives the paper's score exactly).
s(o, T) = max(0, max over the task's targets and the instruction of similarity(label, q)).

A subgraph's ``signature`` is built from its content only (kind, anchor ids, each anchor's object
ids, each object's label): it changes iff what the VLM would be shown changed.

Pure function of a snapshot: must not modify the graph or call a VLM.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from hiconav.geometry import footprint_gap
from hiconav.memory.snapshot import AnchorView, MemorySnapshot, ObjectView
from hiconav.types import TaskSpec, label_key

__all__ = ["Subgraph", "decompose", "task_similarity"]

_KIND_ORDER = {"target": 0, "related": 1, "remaining": 2}


@dataclass(frozen=True, eq=False)
class Subgraph:
    """One unit of VLM reasoning: <= k anchors (images) and the objects they observe.

    kind: "target" | "related" | "remaining"; focus_object_id: the target/related object the
    subgraph was built around (None for remaining); priority: S(G_k) of eq. (11).
    """

    kind: str
    anchors: tuple[AnchorView, ...]
    objects: tuple[ObjectView, ...]
    priority: float
    signature: tuple
    focus_object_id: int | None = None
    # memory objects near the instances of the target it shows that its anchors do not show (a
    # described instance: "the laptop near the tv stand" holds on the map even when no one image
    # holds both)
    context: tuple[ObjectView, ...] = ()

    @property
    def anchor_ids(self) -> tuple[int, ...]:
        return tuple(a.id for a in self.anchors)

    @property
    def object_ids(self) -> tuple[int, ...]:
        return tuple(o.id for o in self.objects)


def task_similarity(label: str, task: TaskSpec, similarity: Callable[[str, str], float],
                    cache: dict[str, float] | None = None) -> float:
    """s(o, T): max(0, similarity of the label to each target and to the instruction)."""
    if cache is not None and label in cache:
        return cache[label]
    text = label.replace("_", " ")
    queries = [t.replace("_", " ") for t in task.targets]
    if task.instruction:
        queries.append(task.instruction)
    s = max([0.0] + [float(similarity(text, q)) for q in queries])
    if cache is not None:
        cache[label] = s
    return s


def _matches(label: str, words: tuple[str, ...], similarity: Callable[[str, str], float],
             threshold: float) -> bool:
    key = label_key(label)
    for w in words:
        if key == label_key(w):
            return True
        if threshold < 1.0 and float(similarity(label.replace("_", " "), w.replace("_", " "))) >= threshold:
            return True
    return False


def _signature(kind: str, anchors: tuple[AnchorView, ...], objects: tuple[ObjectView, ...]) -> tuple:
    return (kind, tuple((a.id, a.object_ids) for a in anchors), tuple((o.id, o.label) for o in objects))


def _context(snapshot: MemorySnapshot, focus: ObjectView, shown: tuple[ObjectView, ...],
             radius: float) -> tuple[ObjectView, ...]:
    """The snapshot's objects within ``radius`` of ``focus``'s box that ``shown`` lacks, by id."""
    have = {o.id for o in shown}
    return tuple(o for o in snapshot.objects if o.id not in have and footprint_gap(focus.box_min, focus.box_max, o.box_min, o.box_max) <= radius)


def _around_targets(snapshot: MemorySnapshot, shown: tuple[ObjectView, ...], is_target: Callable[[str], bool],
                    radius: float, first: ObjectView | None = None) -> tuple[ObjectView, ...]:
    """``_context`` of each object of ``shown`` whose label ``is_target`` (``first``, the focus,
    before the others), each node once, in that order."""
    out: list[ObjectView] = []
    have = {o.id for o in shown}
    rest = [o for o in shown if (first is None or o.id != first.id) and is_target(o.label)]
    for t in ([first] if first is not None else []) + rest:
        for o in _context(snapshot, t, shown, radius):
            if o.id not in have:
                have.add(o.id)
                out.append(o)
    return tuple(out)


def _described(task: TaskSpec) -> bool:
    """The task singles out one instance by relations whose subject is one of its targets."""
    targets = {label_key(t) for t in task.targets}
    return any(len(r) >= 3 and label_key(str(r[0])) in targets for r in task.relations)


def _objects_of(snapshot: MemorySnapshot, anchors: tuple[AnchorView, ...]) -> tuple[ObjectView, ...]:
    ids = sorted({oid for a in anchors for oid in a.object_ids if snapshot.has_object(oid)})
    return tuple(snapshot.object(i) for i in ids)  # eq. (9): V_o^k = union of O(a_i)


def decompose(snapshot: MemorySnapshot, task: TaskSpec, similarity: Callable[[str, str], float],
              k: int = 5, *, label_match_threshold: float = 0.8,
              far_evidence_weight: float = 0.5, context_m: float = 2.5) -> list[Subgraph]:
    """Subgraphs of ``snapshot`` for ``task``, in the order the reasoner should query them.

    For a described instance (relations on the target), each subgraph also carries the memory
    objects within ``context_m`` of the box of each instance of the target it shows (a target
    subgraph's focus first) that its anchors do not show (``Subgraph.context``, part of its
    signature: a related object mapped from elsewhere makes the subgraph due again). Every
    instance a subgraph shows is judged on it, and one seen at the edge of a related or remaining
    subgraph (a painting in the view that centres the bed) was judged on what those images hold
    alone: its room read from the bed next door, not the sink beside it. 0: none.

    similarity(a, b) -> float in [-1, 1] (e.g. ``Embedder.similarity``). An object matches a
    target/related word when the normalised labels are equal or their similarity is at least
    ``label_match_threshold`` (1.0 = exact only).
    """
    if k < 1:
        raise ValueError(f"k must be >= 1, got {k}")
    cache: dict[str, float] = {}

    def s_obj(o: ObjectView) -> float:
        return task_similarity(o.label, task, similarity, cache)

    def score(anchors: tuple[AnchorView, ...], objects: tuple[ObjectView, ...]) -> float:
        total = sum(s_obj(o) for o in objects)  # eq. (11)
        if far_evidence_weight > 0:
            mapped = {label_key(o.label) for o in objects}
            far = {label_key(lab) for a in anchors for lab in a.labels_seen} - mapped
            total += far_evidence_weight * sum(task_similarity(lab, task, similarity, cache)
                                               for lab in sorted(far))
        return float(total)

    def box_area(a: AnchorView, oid: int) -> float:
        b = a.box_of(oid)
        return 0.0 if b is None else float(max(b[2] - b[0], 0.0) * max(b[3] - b[1], 0.0))

    out: list[Subgraph] = []
    used: set[int] = set()
    described = context_m > 0 and _described(task)
    targets = tuple(task.targets)

    def is_target(label: str) -> bool:
        return _matches(label, targets, similarity, label_match_threshold)

    for kind, words in (("target", targets), ("related", tuple(task.related))):
        if not words:
            continue
        focus = [o for o in snapshot.objects if _matches(o.label, words, similarity, label_match_threshold)]
        # most reliable first: confidence x observations, then id for determinism
        focus.sort(key=lambda o: (-o.confidence * o.n_obs, o.id))
        built: list[Subgraph] = []
        for o in focus:
            observers = [snapshot.anchor(a) for a in o.anchor_ids if snapshot.has_anchor(a)]
            if not observers:
                continue
            observers.sort(key=lambda a: (-box_area(a, o.id), a.id))
            chosen = tuple(sorted(observers[:k], key=lambda a: a.id))  # eq. (10): V_a^t
            if {a.id for a in chosen} <= used:
                continue  # the VLM would see exactly the same images again
            used.update(a.id for a in chosen)
            objs = _objects_of(snapshot, chosen)
            near = (_around_targets(snapshot, objs, is_target, context_m, o if kind == "target" else None)
                    if described else ())
            sig = _signature(kind, chosen, objs) + ((tuple((c.id, c.label) for c in near),) if near else ())
            built.append(Subgraph(kind, chosen, objs, score(chosen, objs), sig, o.id, near))
        if kind == "related":
            built.sort(key=lambda g: -g.priority)
        out.extend(built)

    # Remaining anchors: rank each by its own score, group in chunks of <= k, order by S(G_k).
    rest = [a for a in snapshot.anchors if a.id not in used]
    ranked = sorted(rest, key=lambda a: (-score((a,), _objects_of(snapshot, (a,))), a.id))
    groups: list[Subgraph] = []
    for i in range(0, len(ranked), k):
        chunk = tuple(sorted(ranked[i:i + k], key=lambda a: a.id))
        objs = _objects_of(snapshot, chunk)
        near = _around_targets(snapshot, objs, is_target, context_m) if described else ()
        sig = _signature("remaining", chunk, objs) + ((tuple((c.id, c.label) for c in near),) if near else ())
        groups.append(Subgraph("remaining", chunk, objs, score(chunk, objs), sig, None, near))
    groups.sort(key=lambda g: (-g.priority, g.anchors[0].id))
    out.extend(groups)
    return out


def priorities(subgraphs: list[Subgraph]) -> np.ndarray:
    """(K,) priorities of a decomposition, in order (for diagnostics and plots)."""
    return np.array([g.priority for g in subgraphs], dtype=np.float64)
