"""ReasoningActor: the slow layer - instruction decomposition and subgraph verification.

Owns the ``Reasoner`` (priority queue of subgraphs), a verifier (VLM or the labelled offline
verifier) and the instruction parser. One request at a time, as fast as the verifier answers:

- ``ParseRequest`` -> ``decompose_instruction`` -> ``TaskMsg`` to mission, exploration, memory;
- on each tick with a task and a new ``WorldSnapshot`` (latest-wins): decompose the memory graph
  into subgraphs, update the queue, verify the next subgraph, send ``HypothesisMsg`` when found.

Latency: in stepped time a reply becomes visible ``latency`` virtual seconds after the request
(the configured latency, else the measured one) and the node stays busy until then; in real time
the call itself takes that long on this actor's thread while the fast layer runs on. A rejected
target (``TargetRejected`` from the mission) retracts the confirmation so that the search goes on.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor

from hiconav.messages import (ExploredOut, HypothesisMsg, ParseRequest, ReasoningBusy, RuledOut, TargetRejected,
                              TaskMsg, WorldSnapshot)
from hiconav.reasoning.unresolved import due_marginal, track_marginal, unresolved_hypothesis, withdrawn_offers


class ReasoningActor(NodeActor):
    """pykka actor of the reasoning layer."""


class ReasoningNode(Node):
    name = "reasoning"
    actor_class = ReasoningActor

    def __init__(self, *, parse: Callable[[str], Any], make_reasoner: Callable[[Any], Any] | None,
                 verifier: Any = None, decompose: Callable[..., list] | None = None,
                 similarity: Callable[[str, str], float] | None = None, k: int = 5, rate_hz: float = 10.0,
                 stepped: bool = True, latency_s: Any = None, parse_latency_s: Any = None,
                 task_to: tuple[str, ...] = ("mission", "exploration", "memory"), sync: bool = False,
                 marginal_patience_s: float = 0.0) -> None:
        super().__init__(rate_hz)
        self.parse = parse
        self.make_reasoner = make_reasoner
        self.verifier = verifier
        self.decompose = decompose
        self.similarity = similarity
        self.k = k
        self.stepped = stepped
        self.latency_s = latency_s
        self.parse_latency_s = parse_latency_s
        self.task_to = task_to
        self.sync = sync  # tell control when a call is in flight (it holds the robot still)
        self.marginal_patience_s = float(marginal_patience_s)
        self._marginal_since: dict[int, float] = {}  # object id -> clock s since its verdict is "marginal"
        self.task = None
        self.reasoner: Any = None
        self.busy_until = 0.0
        self.requests = 0
        self.events: list[dict[str, Any]] = []
        self._parse: ParseRequest | None = None
        # decomposition of the last memory snapshot, reused while the graph's views are unchanged
        self._decomposed: tuple[Any, Any, list] | None = None
        self.decompose_reused = 0
        # object id -> the last verdict on a described instance's relations (``VerifyResult.verdicts``)
        self.verdicts: dict[int, str] = {}
        self._ruled_out: frozenset[int] = frozenset()
        # the search explored out: offer the best unresolved candidate (once per ExploredOut)
        self._explored_out = False
        self._offered: set[int] = set()
        # object id -> its verdict when offered for want of a clearer instance (marginal patience),
        # and the offers withdrawn since (``withdrawn_offers``)
        self._offer_verdicts: dict[int, str | None] = {}
        self._withdrawn: set[int] = set()
        self._memory: Any = None  # the last memory snapshot seen
        self.latest_wins(WorldSnapshot)
        self.on(ParseRequest, lambda m, now: setattr(self, "_parse", m))
        self.on(TaskMsg, self._on_task)
        self.on(TargetRejected, self._on_rejected)
        self.on(ExploredOut, lambda m, now: setattr(self, "_explored_out", True))

    def _on_task(self, msg: TaskMsg, now: float) -> None:
        self._set_task(msg.task)

    def _set_task(self, task: Any) -> None:
        self.task = task
        self.verdicts.clear()
        self._ruled_out = frozenset()  # exploration forgets its set on the new TaskMsg too
        self._explored_out = False
        self._offered = set()
        self._offer_verdicts, self._withdrawn = {}, set()
        self._marginal_since = {}
        self.reasoner = self.make_reasoner(task) if self.make_reasoner is not None else None

    def _on_rejected(self, msg: TargetRejected, now: float) -> None:
        if self.reasoner is not None:
            self.reasoner.retract(msg.reason)

    def _delay(self, configured: Any, measured: float) -> float:
        """The call's delay: ``configured`` is None (the measured time), seconds, or a latency model
        (``float(model)`` draws one call's)."""
        value = None if configured is None else float(configured)
        if not self.stepped:
            return max((value or 0.0) - measured, 0.0)  # real time: the call already took `measured`
        return value if value is not None else measured

    def _busy(self, now: float, delay: float) -> None:
        self.busy_until = now + (delay if self.stepped else 0.0)
        if self.sync and delay > 0:
            self.emit("control", ReasoningBusy(self.busy_until if self.stepped else now + delay, now))

    def _decompose(self, memory: Any) -> list:
        """``decompose`` of ``memory`` for the current task, memoised: a memory snapshot whose object
        and anchor views are the very same objects as the last one's (the graph shares unchanged
        views; only its stamp moved) decomposes to the same subgraphs, so the last result is reused."""
        last = self._decomposed
        if (last is not None and last[1] is self.task and _same_views(last[0], memory)):
            self.decompose_reused += 1
            return list(last[2])
        subgraphs = self.decompose(memory, self.task, self.similarity, k=self.k)
        self._decomposed = (memory, self.task, list(subgraphs))
        return subgraphs

    def _post_ruled_out(self, result: Any, now: float, delay: float) -> None:
        """Record the result's verdicts (and since when each marginal one has been marginal), and
        tell exploration which target-category nodes the relations rule out, when that set
        changes (a later verdict that holds or is unknown takes a node back), with the offers
        withdrawn for good (``withdrawn_offers``)."""
        self.verdicts.update(getattr(result, "verdicts", None) or {})
        self._marginal_since = track_marginal(self._marginal_since, self.verdicts, now)
        withdrawn = self._withdrawn | withdrawn_offers(self._offer_verdicts, self.verdicts)
        ruled_out = frozenset(i for i, v in self.verdicts.items() if v == "fails")
        if ruled_out != self._ruled_out or withdrawn != self._withdrawn:
            self._ruled_out, self._withdrawn = ruled_out, withdrawn
            self.emit(("exploration", "mission"), RuledOut(ruled_out, now + delay, frozenset(withdrawn)), delay)

    def tick(self, now: float) -> None:
        if now < self.busy_until - 1e-9:
            return  # the previous reply is not visible yet (stepped time)
        if self._parse is not None:
            request, self._parse = self._parse, None
            t0 = time.perf_counter()
            task = self.parse(request.instruction)
            delay = self._delay(self.parse_latency_s, time.perf_counter() - t0)
            self._set_task(task)
            self._busy(now, delay)
            self.events.append({"t": now, "kind": "parse", "instruction": request.instruction,
                                "targets": list(task.targets), "related": list(task.related), "latency_s": delay})
            self.emit(self.task_to, TaskMsg(task, now + delay), delay)
            return
        snap = self.take(WorldSnapshot)
        if snap is not None and snap.memory is not None:
            self._memory = snap.memory
        if self._explored_out:
            self._explored_out = False
            if self._offer_unresolved(now):
                return
        due = due_marginal(self._marginal_since, now, self.marginal_patience_s, exclude=self._offered)
        if due and self._offer_unresolved(now, due, f"no clearer instance in {self.marginal_patience_s:g} s"):
            return
        if (snap is None or self.reasoner is None or self.verifier is None or self.decompose is None
                or snap.memory is None or self.reasoner.done):
            return
        subgraphs = self._decompose(snap.memory)
        self.reasoner.update(subgraphs)
        subgraph = self.reasoner.next()
        if subgraph is None:
            return
        result = self.verifier.verify(subgraph, self.task)
        self.reasoner.accept(result)
        self.requests += 1
        delay = self._delay(self.latency_s, float(result.latency_s))
        self._busy(now, delay)
        self._post_ruled_out(result, now, delay)
        self.events.append({"t": now, "kind": "verify", "subgraph": getattr(subgraph, "kind", ""),
                            "found": bool(result.found), "reason": result.reason, "latency_s": delay,
                            "source": result.source, "detail": result.detail[:400]})
        if result.found and result.hypothesis is not None:
            self.emit(("mission", "memory", "recorder"), HypothesisMsg(result.hypothesis, now + delay, now, "", result.detail,
                                                           str(getattr(subgraph, "kind", ""))), delay)

    def _offer_unresolved(self, now: float, verdicts: dict[int, str] | None = None,
                          why: str = "the search explored out") -> bool:
        """Send the best unresolved candidate of a described instance (``hiconav.reasoning.unresolved``)
        among ``verdicts`` (default: all judged) as a hypothesis, one not offered before: when
        the search explored out, or a marginal one's patience ran out; a reasoning call like any
        other (it takes the modelled latency). True when one was sent."""
        if self.task is None or self._memory is None or (self.reasoner is not None and self.reasoner.done):
            return False
        hyp = unresolved_hypothesis(self._memory, self.verdicts if verdicts is None else verdicts,
                                    self.task.targets, exclude=self._offered, why=why)
        if hyp is None:
            if verdicts is None:
                self.events.append({"t": now, "kind": "unresolved", "found": False, "reason": "none left"})
            else:  # the marginal nodes are gone from memory (merged): never offered
                self._offered.update(verdicts)
            return False
        self._offered.add(int(hyp.object_id))
        if verdicts is not None:  # an explored-out offer is the last resort: never withdrawn
            self._offer_verdicts[int(hyp.object_id)] = self.verdicts.get(int(hyp.object_id))
        self.requests += 1
        delay = self._delay(self.latency_s, 0.0)
        self._busy(now, delay)
        self.events.append({"t": now, "kind": "unresolved", "found": True,
                            "reason": "explored out" if verdicts is None else "marginal",
                            "latency_s": delay, "source": hyp.source, "detail": hyp.evidence[:400]})
        self.emit(("mission", "memory", "recorder"),
                  HypothesisMsg(hyp, now + delay, now, "", hyp.evidence, "unresolved"), delay)
        return True


def _same_views(a: Any, b: Any) -> bool:
    """True when two memory snapshots hold the identical (``is``) object and anchor views in order."""
    if a is b:
        return True
    ao, bo = tuple(getattr(a, "objects", ())), tuple(getattr(b, "objects", ()))
    aa, ba = tuple(getattr(a, "anchors", ())), tuple(getattr(b, "anchors", ()))
    return (len(ao) == len(bo) and len(aa) == len(ba) and all(x is y for x, y in zip(ao, bo))
            and all(x is y for x, y in zip(aa, ba)))
