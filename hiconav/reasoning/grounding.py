"""Grounding a described instance on the memory graph: rooms inferred from what the robot saw,
and the spatial relations of an instruction checked on object nodes' 3D boxes.

"The armchair next to the floor lamp in the living room" decomposes (``decompose``) into the
target ``armchair`` and the relations (armchair, next to, floor_lamp), (armchair, in,
living_room), (floor_lamp, in, living_room). A label match proposes an armchair; only this
module's verdict says which armchair the words single out. It is the offline reasoner's rule
for a subgraph (the VLM path answers the same question from the subgraph's images).

* **Rooms** are never read from a house's ground truth: each object node's room type is inferred
  from the objects the robot saw with it, as a naive-Bayes posterior whose likelihoods were
  counted in the ProcTHOR *training* houses (``room_prior``: a bed says bedroom, a sink bathroom,
  an armchair bedroom or living room), each cue weighted by ``exp(-d / ROOM_DECAY_M)`` of its
  planar distance and counted only for nodes observed from a common anchor (co-visible objects
  share a room far more often than objects behind a wall).
* **Relations** are predicates on axis-aligned boxes (world metres): ``next to`` a planar gap of
  at most ``NEXT_TO_M``, ``near`` at most ``NEAR_M``, ``on`` resting on the other's top, ``under``
  and ``above`` overlapping in plan one below the other, ``facing`` / ``opposite`` at most
  ``ACROSS_M`` (across a room), ``in`` a room (or inside a box),
  ``between`` near both. View-dependent words (left of, behind, in front of, ...) have no fixed
  meaning without the speaker's viewpoint and are read as ``near`` (a labelled approximation).

Verdicts are "holds", "marginal" (every relation holds, some only within the memory boxes'
noise margin: ``relation_grade``), "fails" or "unknown" (the related object is not in the
subgraph, or its box is narrower than an object of its kind is across and the whole object may
stand within reach: ``could_hold``, ``size_prior``; or no room can be inferred), so a described
instance is confirmed only when every relation holds; a marginal one is offered after a wait
(``unresolved.due_marginal``). Pure functions; no clocks, and no I/O but the first read of
the shipped room and size priors (package data).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from hiconav.geometry import centre_in_footprint, footprint_gap
from hiconav.reasoning.decompose import CONTAINMENT
from hiconav.reasoning.decompose import ROOMS as PARSER_ROOMS
from hiconav.reasoning.room_prior import ROOMS, default_log_ratios
from hiconav.reasoning.size_prior import default_sizes
from hiconav.relations import NEAR, NEXT_TO
from hiconav.types import label_key

# the gaps of the ground-truth predicates that generate described-instance episodes
# (``hiconav.relations``), so that a description and its grounding mean one thing, plus the
# noise of a memory box: built from the depth points the robot saw, a box can stop short of its
# object's hidden side and read a gap a few centimetres to a decimetre wider than the true one
# (0.1 m chosen on 78 ProcTHOR train textnav episodes, seeds 0 and 1). Memory boxes are
# axis-aligned, so their gap is computed here directly
BOX_NOISE_M = 0.1
NEXT_TO_M = NEXT_TO + BOX_NOISE_M  # m: planar gap between two boxes that reads "next to" / "beside"
NEAR_M = NEAR + BOX_NOISE_M  # m: planar gap that reads "near"
# m: planar gap that reads "facing" / "opposite" / "across from": the two stand on either side of
# a room's open floor (a sofa facing the TV across a living room), farther apart than "near"
ACROSS_M = 3.5
ACROSS_WORDS = frozenset(["facing", "opposite", "across from"])
# m: a box whose bottom lies this close to another's top rests on it (wider than the ground truth's
# 0.10 m: a memory box grows by a few far-off points of its object)
ON_GAP_M = 0.30
# m: footprints this far apart still count as one above the other: a painting or TV hung above a
# bed or sofa that stands against the same wall has its memory box on the wall's face, the
# furniture's stops short of the wall, so their boxes from depth points rarely overlap in plan
STACK_PAD_M = 0.30
# a thing hung on a wall (a painting, a wall TV, a mirror) has a box this thin in plan, or thinner
HUNG_THIN_M = 0.2
# m: how far short of the wall a piece of furniture's memory box may stop and still stand under a
# thing hung on that wall: built from the depth points of its front and top, the box of a bed,
# dresser or chair pushed against the wall rarely reaches the wall behind it
HUNG_REACH_M = 0.8
# m: a memory box narrower than its category's short side (``size_prior``) by more than this along
# an axis is seen in part: a relation that fails on it may hold on the whole object
SHORT_OF_SIZE_M = 0.2
ROOM_DECAY_M = 2.5  # m: a room cue's weight falls by e over this planar distance
ROOM_REACH_M = 6.0  # m: cues farther than this say nothing of an object's room
# below this posterior the room is unknown (chosen on ProcTHOR train textnav, seeds 0 and 1)
ROOM_MIN_POSTERIOR = 0.7
# a described room that is the most probable one at this posterior or more, below
# ROOM_MIN_POSTERIOR, is "marginal": likelier than every other room together, not sure
ROOM_LEAN_POSTERIOR = 0.5
# Aliases people use for the four room types (the parser maps them to these labels or keeps them).
ROOM_ALIASES: dict[str, str] = {
    "bedroom": "bedroom", "bed_room": "bedroom", "master_bedroom": "bedroom", "guest_room": "bedroom",
    "bathroom": "bathroom", "bath_room": "bathroom", "restroom": "bathroom", "washroom": "bathroom",
    "toilet_room": "bathroom", "lavatory": "bathroom",
    "kitchen": "kitchen", "kitchenette": "kitchen",
    "living_room": "living_room", "livingroom": "living_room", "lounge": "living_room",
    "sitting_room": "living_room", "family_room": "living_room", "den": "living_room",
}
# room types the instruction parser knows that no room cue infers (dining room, hallway, office,
# laundry room, garage): the ProcTHOR houses have none of them, and the objects that furnish them
# (a dining table, a desk, a washing machine) stand in the four rooms above as often
UNINFERRED_ROOMS = frozenset(PARSER_ROOMS.values()) - frozenset(ROOMS)
NEAR_WORDS = frozenset(["near", "left of", "right of", "in front of", "behind", "facing", "opposite", "at",
                        "with", "against", "by"])


class BoxLike(Protocol):
    id: int
    label: str
    box_min: Any  # (3,) world metres
    box_max: Any
    anchor_ids: Any


def room_of(label: str) -> str | None:
    """The room type a relation's object names ("living room" -> "living_room"), or None."""
    key = label_key(label)
    return ROOM_ALIASES.get(key)


# ------------------------------------------------------------------------------------ geometry
def planar_gap(a: BoxLike, b: BoxLike) -> float:
    """Planar distance (m) between the footprints of two boxes; 0 when they overlap in plan."""
    return footprint_gap(np.asarray(a.box_min, float), np.asarray(a.box_max, float),
                         np.asarray(b.box_min, float), np.asarray(b.box_max, float))


def _plan_overlap(a: BoxLike, b: BoxLike, pad: float = 0.05) -> bool:
    a0, a1 = np.asarray(a.box_min, float), np.asarray(a.box_max, float)
    b0, b1 = np.asarray(b.box_min, float), np.asarray(b.box_max, float)
    return bool(a0[0] <= b1[0] + pad and b0[0] <= a1[0] + pad and a0[1] <= b1[1] + pad and b0[1] <= a1[1] + pad)


def hung_over(top: BoxLike, low: BoxLike) -> bool:
    """Whether ``top``, a thing hung on a wall (its footprint at most ``HUNG_THIN_M`` thick along
    x or y), hangs over ``low``: their footprints overlap along the wall (within the boxes'
    noise) and ``low``'s box stops at most ``HUNG_REACH_M`` short of it across the wall. The
    ground truth's "under" wants the footprints to overlap; a memory box of furniture against
    the wall stops short of it."""
    t0, t1 = np.asarray(top.box_min, float), np.asarray(top.box_max, float)
    l0, l1 = np.asarray(low.box_min, float), np.asarray(low.box_max, float)
    ext = t1[:2] - t0[:2]
    for k in (0, 1):  # k: the axis across the wall
        j = 1 - k
        if ext[k] > HUNG_THIN_M or ext[k] > ext[j]:
            continue
        along = t0[j] <= l1[j] + BOX_NOISE_M and l0[j] <= t1[j] + BOX_NOISE_M
        across = max(l0[k] - t1[k], t0[k] - l1[k], 0.0)
        if along and across <= HUNG_REACH_M:
            return True
    return False


@dataclass(frozen=True)
class _Box:
    id: int
    label: str
    box_min: np.ndarray
    box_max: np.ndarray


def grown_toward(box: BoxLike, toward: BoxLike, size: tuple[float, float] | None) -> _Box | None:
    """The box ``box`` may still grow to, toward ``toward``: where its footprint is narrower than
    its category's short side (``size``: long, short side, metres) by more than
    ``SHORT_OF_SIZE_M`` along an axis (narrower than any common object of its kind is across:
    seen edge-on or in part, for sure), that axis extended to the short side on the side facing
    ``toward``'s centre. None when the box is not short of its size or the category has none."""
    if size is None:
        return None
    b0, b1 = np.asarray(box.box_min, float), np.asarray(box.box_max, float)
    short = float(size[1]) - (b1[:2] - b0[:2])
    grow = np.where(short > SHORT_OF_SIZE_M, short, 0.0)
    if not np.any(grow > 0.0):
        return None
    here = (b0[:2] + b1[:2]) / 2.0
    there = (np.asarray(toward.box_min, float)[:2] + np.asarray(toward.box_max, float)[:2]) / 2.0
    lo, hi = b0.copy(), b1.copy()
    for k in (0, 1):
        if there[k] >= here[k]:
            hi[k] += grow[k]
        else:
            lo[k] -= grow[k]
    return _Box(int(box.id), str(box.label), lo, hi)


def could_hold(relation: str, a: BoxLike, b: BoxLike, sizes: Mapping[str, tuple[float, float]]) -> bool:
    """Whether ``relation`` of ``a`` to the related object ``b``, failing on their boxes, would
    hold (or hold within the noise margin) once ``b``'s box, seen in part, grew toward ``a`` to
    its category's short side (``grown_toward``; ``sizes``: category -> (long, short) m). Only the
    related object grows: a candidate's own box seen in part is what the verification views are
    for, and growing it too kept wrong instances of the category open on train. Rooms ("in")
    never grow."""
    rel = relation.strip().lower()
    if rel == "in":
        return False
    grown = grown_toward(b, a, sizes.get(label_key(str(b.label))))
    return grown is not None and relation_grade(rel, a, grown) != "fails"


def _centre_in_plan(a: BoxLike, b: BoxLike, pad: float = 0.10) -> bool:
    return centre_in_footprint(a.box_min, a.box_max, b.box_min, b.box_max, pad)


def relation_holds(relation: str, a: BoxLike, b: BoxLike) -> bool:
    """Whether ``a`` stands in ``relation`` to ``b`` (both object boxes; see the module's list),
    read with the box-noise margins: "holds" or "marginal" by ``relation_grade``."""
    return relation_grade(relation, a, b) != "fails"


def relation_grade(relation: str, a: BoxLike, b: BoxLike) -> str:
    """"holds" when ``a`` stands in ``relation`` to ``b`` as the ground truth's predicate reads
    it (planar gap within ``NEXT_TO`` / ``NEAR``, stacked boxes overlapping in plan within
    ``BOX_NOISE_M``, "on" with the upper box's centre over the lower one); "marginal" when it does
    so only within the memory boxes' noise margin (``NEXT_TO_M``, ``NEAR_M``, ``STACK_PAD_M``; for
    "on", at the right height with the footprints within ``STACK_PAD_M``); else "fails". A
    marginal relation may be a true one read through a box that stops short of its object, or a
    false one: the instance beside the described one, a few centimetres past the words' reach."""
    rel = relation.strip().lower()
    if rel == "on":
        if abs(float(a.box_min[2]) - float(b.box_max[2])) > ON_GAP_M:
            return "fails"
        if _centre_in_plan(a, b):
            return "holds"
        # a table top's box stops short where what stands on it hides the top from the camera, or
        # where the camera saw it at a grazing angle: at the right height and within the stack pad
        # in plan it may be the support, read through a box that has not grown to its object yet
        return "marginal" if _plan_overlap(a, b, STACK_PAD_M) else "fails"
    if rel in ("under", "below", "above"):
        top, low = (b, a) if rel != "above" else (a, b)
        if float(top.box_min[2]) < float(low.box_max[2]) - ON_GAP_M:
            return "fails"
        if _plan_overlap(a, b, BOX_NOISE_M) or hung_over(top, low):
            return "holds"
        return "marginal" if _plan_overlap(a, b, STACK_PAD_M) else "fails"
    if rel == "in":
        ok = _centre_in_plan(a, b, pad=0.0) and float(b.box_min[2]) - 0.1 <= float(a.box_min[2]) <= float(b.box_max[2])
        return "holds" if ok else "fails"
    gap = planar_gap(a, b)
    if rel in ACROSS_WORDS:
        return "holds" if gap <= ACROSS_M else "fails"
    reach = NEXT_TO if rel == "next to" else NEAR  # near and the view-dependent words
    if gap <= reach:
        return "holds"
    return "marginal" if gap <= reach + BOX_NOISE_M else "fails"


# ---------------------------------------------------------------------------------------- rooms
def infer_rooms(objects: Sequence[BoxLike], ignore: Iterable[str] = (),
                cues: Mapping[str, Mapping[str, float]] | None = None,
                min_posterior: float = ROOM_MIN_POSTERIOR) -> dict[int, tuple[str | None, float]]:
    """Object id -> (inferred room type or None, its posterior) for every object.

    A naive-Bayes posterior over ``ROOMS`` from a uniform prior: every object co-visible with it
    (a common anchor) within ``ROOM_REACH_M``, and itself, adds its category's log-likelihood
    ratios (``cues``; default: learnt from the ProcTHOR training houses, ``room_prior``) weighted
    by exp(-gap / ROOM_DECAY_M). The most probable room is inferred when its posterior reaches
    ``min_posterior`` (default ``ROOM_MIN_POSTERIOR``), else None; None with 0.0 when no object
    with a cue was seen with it.
    Objects whose label is in ``ignore`` give no cue: for "the tv in the bedroom" the tvs are
    what the description tells apart, so a tv's own lean to the living room must not decide
    which room it is in."""
    table = default_log_ratios() if cues is None else cues
    out: dict[int, tuple[str | None, float]] = {}
    # co-visibility: a common anchor, pruned ones included where the node keeps them (observed_by)
    anchors = {o.id: set(getattr(o, "observed_by", ()) or getattr(o, "anchor_ids", ()) or ()) for o in objects}
    skip = {label_key(str(t)) for t in ignore}
    # the objects that give a cue, with their ratios per room (looked up once, not per pair)
    cue_objects = [(other, [float(ratios.get(room, 0.0)) for room in ROOMS]) for other in objects
                   if (key := label_key(str(other.label))) not in skip and (ratios := table.get(key))]
    for o in objects:
        logit = dict.fromkeys(ROOMS, 0.0)
        seen = False
        for other, ratios in cue_objects:
            if other.id != o.id and not (anchors[o.id] & anchors[other.id]):
                continue
            gap = 0.0 if other.id == o.id else planar_gap(o, other)
            if gap > ROOM_REACH_M:
                continue
            w = math.exp(-gap / ROOM_DECAY_M)
            seen = True
            for room, r in zip(ROOMS, ratios):
                logit[room] += w * r
        if not seen:
            out[o.id] = (None, 0.0)
            continue
        top = max(logit.values())
        z = sum(math.exp(v - top) for v in logit.values())
        room, v = max(logit.items(), key=lambda kv: (kv[1], kv[0]))
        p = math.exp(v - top) / z
        out[o.id] = (room if p >= min_posterior else None, p)
    return out


# -------------------------------------------------------------------------------------- verdict
@dataclass(frozen=True)
class Grounding:
    """The verdict on one candidate object: ``status`` "holds" | "fails" | "unknown", with one
    line of evidence per relation."""

    object_id: int
    status: str
    evidence: tuple[str, ...]


def labels_match(label: str, name: str) -> bool:
    """True when two labels name one thing (case, spaces and underscores aside)."""
    return label_key(label) == label_key(name)


def target_relations(relations: Iterable[Sequence[str]], targets: Iterable[str]) -> list[tuple[str, str, str]]:
    """The relations whose subject is one of ``targets``: what singles out the described instance."""
    names = {label_key(t) for t in targets}
    return [(s, r, o) for s, r, o in (tuple(x) for x in relations) if label_key(s) in names]


def ground(candidate: BoxLike, objects: Sequence[BoxLike], relations: Sequence[Sequence[str]],
           targets: Sequence[str], rooms: dict[int, tuple[str | None, float]] | None = None,
           sizes: Mapping[str, tuple[float, float]] | None = None) -> Grounding:
    """Check every relation of ``relations`` whose subject is a target on ``candidate``.

    ``objects``: the nodes to ground on (the subgraph's; ``candidate`` among them); relations of a
    related object ("the floor lamp in the living room") are checked one level down, on the node
    that satisfied the target's relation. Holds only when every relation holds. ``sizes``:
    category -> (long, short) footprint sides in metres (default: the shipped ``size_prior``); a
    relation that fails only because a related object's box is narrower than its kind is across
    is "unknown" (``could_hold``).
    """
    rooms = rooms if rooms is not None else infer_rooms(objects, ignore=targets, min_posterior=0.0)
    sizes = default_sizes() if sizes is None else sizes
    rels = target_relations(relations, targets)
    if not rels:
        return Grounding(candidate.id, "holds", ("no relation to check",))
    evidence: list[str] = []
    statuses: list[str] = []
    for subject, rel, obj in rels:
        status, line = _one(candidate, rel, obj, objects, relations, rooms, depth=0, sizes=sizes)
        statuses.append(status)
        evidence.append(f"{subject} {rel} {obj}: {status} ({line})")
    status = next(s for s in ("fails", "unknown", "marginal", "holds") if s in statuses)
    return Grounding(candidate.id, status, tuple(evidence))


def _one(node: BoxLike, rel: str, obj: str, objects: Sequence[BoxLike], relations: Sequence[Sequence[str]],
         rooms: dict[int, tuple[str | None, float]], depth: int, *,
         sizes: Mapping[str, tuple[float, float]]) -> tuple[str, str]:
    room = room_of(obj)
    if room is None and label_key(obj) in UNINFERRED_ROOMS:
        # "the table in the dining room": a room type the room prior does not tell apart; waiting
        # for its evidence would hold the search forever, so the words are not checked
        return "holds", f"a {obj.replace('_', ' ')} is no room type the map infers (not checked)"
    if room is not None and rel.strip().lower() in CONTAINMENT:
        seen, score = rooms.get(node.id, (None, 0.0))
        if seen is not None and score < ROOM_MIN_POSTERIOR:
            # ``rooms`` from infer_rooms(min_posterior=0): the most probable room, not sure of it.
            # The described room leaning ahead of every other together is "marginal": an instance
            # in a room that shows cues of two (a dining table in a bedroom) would otherwise stay
            # "unknown" for good, and the robot drove on past it until the step limit
            if seen == room and score >= ROOM_LEAN_POSTERIOR:
                return "marginal", f"leans to {seen} (p {score:.2f} < {ROOM_MIN_POSTERIOR:g})"
            seen = None
        if seen is None:
            return "unknown", ("no room cue seen with it" if score <= 0.0 else
                               f"no room clear enough (p {score:.2f} < {ROOM_MIN_POSTERIOR:g})")
        return ("holds" if seen == room else "fails"), f"inferred {seen} (p {score:.2f})"
    others = [o for o in objects if o.id != node.id and labels_match(o.label, obj)]
    if not others:
        return "unknown", f"no {obj} in view"
    # the related object's own relations ("the floor lamp in the living room"), checked one level down
    nested = [(r, o2) for s2, r, o2 in (tuple(x) for x in relations)
              if labels_match(s2, obj) and not labels_match(o2, node.label)] if depth == 0 else []
    best = "fails"
    line = ""
    partial: BoxLike | None = None  # the nearest related object the relation would hold on, grown
    for other in sorted(others, key=lambda o: planar_gap(node, o)):
        grade = relation_grade(rel, node, other)
        if grade == "fails":
            if partial is None and could_hold(rel, node, other, sizes):
                partial = other
            continue
        if nested:
            sub = [_one(other, r, o2, objects, relations, rooms, depth=1, sizes=sizes)[0] for r, o2 in nested]
            if "fails" in sub:
                line = f"#{other.id} is {rel} it, but not {', '.join(f'{r} {o2}' for r, o2 in nested)}"
                continue
            if "unknown" in sub:
                if best == "fails":
                    best, line = "unknown", f"#{other.id} is {rel} it; {', '.join(f'{r} {o2}' for r, o2 in nested)} unknown"
                continue
            if "marginal" in sub:
                grade = "marginal"
        if grade == "holds":
            return "holds", f"#{other.id} at {planar_gap(node, other):.2f} m"
        if best != "marginal":
            best, line = "marginal", f"#{other.id} at {planar_gap(node, other):.2f} m, within the boxes' noise margin only"
    if best == "fails" and partial is not None and not line:
        # a related object seen in part (a counter seen edge-on, the near end of a table): the
        # relation fails on its box but would hold on the whole object; what the robot has seen
        # does not rule the candidate out
        return "unknown", (f"#{partial.id} at {planar_gap(node, partial):.2f} m, its box narrower "
                           f"than a {obj.replace('_', ' ')} is across: seen in part")
    if not line:
        line = f"nearest {obj} #{min(others, key=lambda o: planar_gap(node, o)).id} at " \
               f"{min(planar_gap(node, o) for o in others):.2f} m"
    return best, line
