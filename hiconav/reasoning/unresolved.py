"""The best unresolved candidate of a described instance, once the search has nothing left.

A described instance ("the TV in the bedroom") is confirmed only when every relation holds on the
memory graph. When the robot has explored every frontier and no instance was confirmed, the
instances it did see are all that is left: one whose relation is *unknown* (the lamp it stands
by, or the room's cues, were never in view with it), or whose relations held but whose detection
stayed below the verifier's gates, or even one the relations ruled out (a room inferred wrongly
from a few cues). Ending the mission with none of them is a certain failure; going to the most
plausible one is not. This module ranks them; the reasoning node offers the first as a
hypothesis when the mission reports the search explored out (``ExploredOut``), and the mission
verifies it (re-detection) like any other before it stops.

A relation that holds only within the memory boxes' noise margin ("marginal") does not confirm an
instance either: the search goes on for ``reasoning.marginal_patience_s`` (robot time, on the
mission's clock), and the
best marginal instance is offered then if no clearer one was confirmed (``due_marginal``).

Order: verdict "holds" (gated out by confidence or observations) before "marginal" before
"unknown" before "fails";
then the detection evidence, confidence x observations; then the lower id (older node). Pure: no
clocks, no I/O.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from typing import Any

from hiconav.reasoning.grounding import labels_match
from hiconav.reasoning.hypothesis import TargetHypothesis
from hiconav.reasoning.verifier import best_view

__all__ = ["VERDICT_RANK", "best_unresolved", "due_marginal", "track_marginal", "unresolved_hypothesis",
           "withdrawn_offers"]

# a verdict's place in the order (lower first); verdicts not listed are never offered
VERDICT_RANK: dict[str, int] = {"holds": 0, "marginal": 1, "unknown": 2, "fails": 3}


def best_unresolved(objects: Sequence[Any], verdicts: Mapping[int, str], targets: Sequence[str],
                    exclude: Collection[int] = ()) -> Any | None:
    """The object node to offer, or None: among ``objects`` (memory ObjectViews: ``id``, ``label``,
    ``confidence``, ``n_obs``) labelled as one of ``targets`` and judged (``verdicts``: object id
    -> "holds" / "unknown" / "fails"), not in ``exclude`` (offered or rejected already), the first
    by verdict, then confidence x observations, then id."""
    pool = [o for o in objects
            if any(labels_match(str(o.label), t) for t in targets) and verdicts.get(int(o.id)) in VERDICT_RANK
            and int(o.id) not in exclude]
    if not pool:
        return None
    return min(pool, key=lambda o: (VERDICT_RANK[verdicts[int(o.id)]],
                                    -float(o.confidence) * int(o.n_obs), int(o.id)))


def track_marginal(since: Mapping[int, float], verdicts: Mapping[int, str], now: float) -> dict[int, float]:
    """Object id -> the clock time (s) since which its verdict has been "marginal" without a
    break: ids newly marginal start at ``now``, ids whose verdict changed are dropped."""
    return {oid: float(since.get(oid, now)) for oid, v in verdicts.items() if v == "marginal"}


def due_marginal(since: Mapping[int, float], now: float, patience_s: float,
                 exclude: Collection[int] = ()) -> dict[int, str]:
    """The marginal candidates whose patience ran out, as verdicts for ``unresolved_hypothesis``.

    A relation that holds only within the memory boxes' noise margin (``grounding.relation_grade``)
    may be the described one read through a box that stops short of its object, or the instance
    beside it: the search goes on for ``patience_s`` clock seconds in case a clearly matching
    instance shows up, and then the marginal one is offered rather than waiting for the whole
    house to be explored (0: never offered before the search explores out)."""
    if patience_s <= 0.0:
        return {}
    return {oid: "marginal" for oid, t0 in since.items() if now - t0 >= patience_s and oid not in exclude}


def withdrawn_offers(offered: Mapping[int, str | None], verdicts: Mapping[int, str]) -> set[int]:
    """The offered nodes (``offered``: object id -> its verdict when it was offered) whose verdict
    has turned to "fails" since: the offer is withdrawn for good.

    An undecided instance offered after the marginal patience is judged on while the robot
    drives to it. Its room posterior sways with the nodes each subgraph holds: one call reads
    "fails" (another room, surely) and the next "marginal" again from fewer cues, and the robot
    stopped at an instance the description rules out. The caller records only such offers: an
    explored-out offer is the mission's last resort, kept whatever the verdicts say, and a node
    offered as it failed is never withdrawn."""
    return {oid for oid, then in offered.items() if then != "fails" and verdicts.get(oid) == "fails"}


def unresolved_hypothesis(memory: Any, verdicts: Mapping[int, str], targets: Sequence[str],
                          exclude: Collection[int] = (), why: str = "the search explored out") -> TargetHypothesis | None:
    """``best_unresolved`` on a memory snapshot (``objects``, ``anchors``) as a hypothesis: the
    anchor where the node's box is largest, confidence the node's detector confidence, source
    "offline" and evidence saying it is a fallback. None when no node qualifies or no anchor
    holds the chosen node's box."""
    objects = list(getattr(memory, "objects", ()) or ())
    node = best_unresolved(objects, verdicts, targets, exclude)
    if node is None:
        return None
    view = best_view(node, list(getattr(memory, "anchors", ()) or ()))
    if view is None:
        return None
    anchor, bbox = view
    verdict = verdicts[int(node.id)]
    label = next((t for t in targets if labels_match(str(node.label), t)), str(node.label))
    evidence = (f"offline fallback, {why}: object node {node.id} labelled "
                f"{node.label!r} is the best unresolved candidate (relations {verdict}, detector "
                f"confidence {float(node.confidence):.2f}, seen {int(node.n_obs)} times)")
    return TargetHypothesis(anchor_id=int(anchor.id), object_id=int(node.id), bbox=bbox,
                            confidence=float(node.confidence), evidence=evidence, latency_s=0.0,
                            source="offline", subgraph_signature=("unresolved", int(node.id)),
                            label=label)
