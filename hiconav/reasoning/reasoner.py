"""The reasoner: a pure state machine over the priority queue of subgraphs.

Paper, section "Deep Reasoning": a separate reasoning thread incrementally and continuously
queries the VLM with each subgraph (target and related subgraphs first, then the remaining ones
by priority S(G_k) = sum_i s(o_i, T), eq. in "Subgraph Decomposition"). This class holds that
queue and the bookkeeping; the thread (the pykka ReasoningActor) calls it:

    reasoner.update(subgraphs)         # on every new memory snapshot (memory.decompose(...))
    sg = reasoner.next()               # the next subgraph to check, or None
    result = verifier.verify(sg, task) # blocking, in the actor's worker thread
    hyp = reasoner.accept(result)      # a confirmed TargetHypothesis, or None

It skips subgraphs already checked unless their signature changed (a changed subgraph has a new
signature), retries transient failures (timeouts, 5xx) a bounded number of times, and stops
once a hypothesis is confirmed (confidence >= ``confirm_confidence``). It records statistics.
No threads, no clocks, no I/O here; it never produces commands.
"""

from __future__ import annotations

import collections
import logging
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hiconav.reasoning.config import ReasoningConfig
from hiconav.reasoning.hypothesis import TargetHypothesis
from hiconav.reasoning.verifier import FOUND, VerifyResult
from hiconav.types import TaskSpec

log = logging.getLogger(__name__)


@dataclass
class ReasonerStats:
    """Counters of one mission's reasoning (JSON-able with ``to_json``)."""

    calls: int = 0
    found: int = 0
    confirmed: int = 0
    not_found: int = 0
    rejected: collections.Counter = field(default_factory=collections.Counter)
    not_found_reasons: collections.Counter = field(default_factory=collections.Counter)
    latencies_s: list[float] = field(default_factory=list)
    skipped_unchanged: int = 0
    stale_results: int = 0
    retries: int = 0
    snapshots: int = 0

    def to_json(self) -> dict[str, Any]:
        lat = np.asarray(self.latencies_s, dtype=float)
        return {
            "calls": self.calls, "found": self.found, "confirmed": self.confirmed,
            "not_found": self.not_found, "rejected": dict(self.rejected),
            "not_found_reasons": dict(self.not_found_reasons),
            "latency_mean_s": float(lat.mean()) if lat.size else 0.0,
            "latency_p50_s": float(np.median(lat)) if lat.size else 0.0,
            "latency_max_s": float(lat.max()) if lat.size else 0.0,
            "skipped_unchanged": self.skipped_unchanged, "stale_results": self.stale_results,
            "retries": self.retries, "snapshots": self.snapshots,
        }


class Reasoner:
    """Works through the subgraph queue for one task until a hypothesis is confirmed."""

    def __init__(self, task: TaskSpec, config: ReasoningConfig | None = None) -> None:
        self.config = config or ReasoningConfig()
        self.task = task
        self.stats = ReasonerStats()
        self._queue: list[Any] = []  # subgraphs of the latest snapshot, in the given priority order
        self._checked: set[tuple] = set()  # signatures answered (found, not found or rejected)
        self._attempts: collections.Counter = collections.Counter()  # transient failures per signature
        self._in_flight: dict[tuple, Any] = {}
        self._retracted: set[tuple] = set()
        self._judged: set[Any] = set()  # focus objects of the subgraphs answered
        self.candidates: list[TargetHypothesis] = []  # found, below the confirmation threshold
        self.confirmed: TargetHypothesis | None = None

    # ------------------------------------------------------------------ queue
    def update(self, subgraphs: Sequence[Any]) -> int:
        """Replace the queue with the subgraphs of a new snapshot; returns how many are unchecked.

        ``subgraphs``: ``memory.decompose(...)`` output, already ordered by priority (target,
        related, then remaining by S(G_k)); the order is kept.
        """
        self.stats.snapshots += 1
        queue, seen = [], set()
        for sg in subgraphs:
            sig = tuple(sg.signature)
            if sig in seen:
                continue
            seen.add(sig)
            queue.append(sg)
        self._queue = queue
        return len(self.pending())

    def pending(self) -> list[Any]:
        """Subgraphs still to check, in order (not checked, not in flight)."""
        return [sg for sg in self._queue if self._eligible(tuple(sg.signature))]

    def _eligible(self, sig: tuple) -> bool:
        return sig not in self._checked and sig not in self._in_flight and \
            self._attempts[sig] < self.config.max_attempts_per_subgraph

    @property
    def done(self) -> bool:
        return self.confirmed is not None

    @property
    def in_flight(self) -> tuple[tuple, ...]:
        return tuple(self._in_flight)

    def next(self) -> Any | None:
        """The highest-priority subgraph not yet checked (marked in flight), or None.

        With ``fresh_targets_first``, a target subgraph around an object never judged comes
        before every subgraph whose focus was judged already: a target node seen for the first
        time is new evidence, where a judged node's subgraph changed by one more view mostly
        repeats its verdict, and in a house with many instances of the category the re-checks
        would keep the new one waiting for minutes.

        Returns None once a hypothesis is confirmed or when nothing new is left.
        """
        if self.done:
            return None
        if self.config.fresh_targets_first:
            for sg in self._queue:
                focus = getattr(sg, "focus_object_id", None)
                if (getattr(sg, "kind", "") == "target" and focus is not None and focus not in self._judged
                        and self._eligible(tuple(sg.signature))):
                    self._in_flight[tuple(sg.signature)] = sg
                    return sg
        skipped = 0
        for sg in self._queue:
            sig = tuple(sg.signature)
            if sig in self._checked:
                skipped += 1
                continue
            if self._eligible(sig):
                self._in_flight[sig] = sg
                self.stats.skipped_unchanged += skipped
                return sg
        self.stats.skipped_unchanged += skipped
        return None

    # ------------------------------------------------------------------ results
    def accept(self, result: VerifyResult) -> TargetHypothesis | None:
        """Record a verifier result; returns the hypothesis if it confirms the target."""
        sig = tuple(result.subgraph_signature)
        if sig not in self._in_flight:
            self.stats.stale_results += 1
            log.info("reasoner: ignoring a result for a subgraph not in flight (stale)")
            return None
        focus = getattr(self._in_flight.pop(sig), "focus_object_id", None)
        self.stats.calls += 1
        self.stats.latencies_s.append(float(result.latency_s))
        if self.done:
            self.stats.stale_results += 1
            return None
        if result.found and result.hypothesis is not None and result.reason == FOUND:
            self._checked.add(sig)
            self._judge(focus)
            self.stats.found += 1
            hyp = result.hypothesis
            if hyp.confidence >= self.config.confirm_confidence:
                self.confirmed = hyp
                self.stats.confirmed += 1
                log.info("reasoner: target confirmed in anchor %d (object %s, %.2f, %s)",
                         hyp.anchor_id, hyp.object_id, hyp.confidence, hyp.source)
                return hyp
            self.candidates.append(hyp)
            return None
        self.stats.not_found += 1
        if result.rejected:
            self.stats.rejected[result.reason] += 1
        else:
            self.stats.not_found_reasons[result.reason] += 1
        if result.transient:
            self._attempts[sig] += 1
            if self._attempts[sig] < self.config.max_attempts_per_subgraph:
                self.stats.retries += 1
                return None
        self._checked.add(sig)
        self._judge(focus)
        return None

    def _judge(self, focus: Any) -> None:
        if focus is not None:  # "remaining" subgraphs have no focus object
            self._judged.add(focus)

    def step(self, verifier: Any) -> VerifyResult | None:
        """Synchronous convenience (stepped clock, tests): next(), verify, accept()."""
        sg = self.next()
        if sg is None:
            return None
        result = verifier.verify(sg, self.task)
        self.accept(result)
        return result

    def abandon(self) -> None:
        """Forget requests in flight (the mission ended or the client was cancelled)."""
        self._in_flight.clear()

    def retract(self, reason: str = "") -> None:
        """The confirmed hypothesis was a false positive (e.g. VerifyTarget): search on.

        Its subgraph stays checked; a changed subgraph (new signature) is checked again.
        """
        if self.confirmed is not None:
            log.info("reasoner: confirmation retracted (%s)", reason or "no reason given")
            self._retracted.add(tuple(self.confirmed.subgraph_signature))
            self.confirmed = None
