"""The reasoner state machine and the offline verifier (pure: no threads, no sockets)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from hiconav.reasoning import OfflineVerifier, Reasoner, ReasoningConfig, TargetHypothesis, VerifyResult
from hiconav.types import TaskSpec

from .helpers import make_subgraph, make_task


def sg(name: str, version: int = 0, **kw):
    return make_subgraph(signature=(name, version), **kw)


def hyp(signature: tuple, confidence: float = 0.9) -> TargetHypothesis:
    return TargetHypothesis(10, 2, np.array([0.1, 0.1, 0.3, 0.3]), confidence, "seen", 0.5, "vlm",
                            signature, "mug")


class ScriptedVerifier:
    """Answers by subgraph signature from a table; records the order it was asked in."""

    source = "vlm"

    def __init__(self, answers: dict[tuple, tuple[str, float]]) -> None:
        self.answers = answers
        self.asked: list[tuple] = []

    def verify(self, subgraph, task) -> VerifyResult:
        sig = tuple(subgraph.signature)
        self.asked.append(sig)
        reason, conf = self.answers.get(sig, ("not_visible", 0.0))
        if reason == "ok":
            return VerifyResult(True, hyp(sig, conf), "ok", "", 0.5, "vlm", sig)
        return VerifyResult(False, None, reason, "", 0.5, "vlm", sig)


def test_subgraphs_are_checked_in_queue_order_until_confirmed() -> None:
    queue = [sg("t"), sg("r"), sg("a"), sg("b")]
    verifier = ScriptedVerifier({("a", 0): ("ok", 0.9)})
    reasoner = Reasoner(make_task())
    reasoner.update(queue)
    while reasoner.step(verifier) is not None:
        pass
    assert verifier.asked == [("t", 0), ("r", 0), ("a", 0)]
    assert reasoner.done and reasoner.confirmed.subgraph_signature == ("a", 0)
    assert reasoner.next() is None  # stops once confirmed
    stats = reasoner.stats.to_json()
    assert stats["calls"] == 3 and stats["confirmed"] == 1
    assert stats["not_found_reasons"] == {"not_visible": 2}


def test_unchanged_subgraphs_are_skipped_and_changed_ones_checked_again() -> None:
    verifier = ScriptedVerifier({})
    reasoner = Reasoner(make_task())
    reasoner.update([sg("t"), sg("x")])
    while reasoner.step(verifier):
        pass
    assert reasoner.update([sg("t"), sg("x", version=1), sg("new")]) == 2
    while reasoner.step(verifier):
        pass
    assert verifier.asked == [("t", 0), ("x", 0), ("x", 1), ("new", 0)]
    assert reasoner.stats.skipped_unchanged >= 1


def test_a_low_confidence_hypothesis_is_kept_as_a_candidate_not_confirmed() -> None:
    verifier = ScriptedVerifier({("t", 0): ("ok", 0.2), ("r", 0): ("ok", 0.8)})
    reasoner = Reasoner(make_task(), ReasoningConfig(confirm_confidence=0.5))
    reasoner.update([sg("t"), sg("r")])
    reasoner.step(verifier)
    assert not reasoner.done and len(reasoner.candidates) == 1
    reasoner.step(verifier)
    assert reasoner.done and reasoner.confirmed.confidence == 0.8


def test_transient_failures_are_retried_a_bounded_number_of_times() -> None:
    verifier = ScriptedVerifier({("t", 0): ("timeout", 0.0)})
    reasoner = Reasoner(make_task(), ReasoningConfig(max_attempts_per_subgraph=2))
    reasoner.update([sg("t")])
    while reasoner.step(verifier):
        pass
    assert verifier.asked == [("t", 0), ("t", 0)]
    assert reasoner.stats.rejected["timeout"] == 2 and reasoner.stats.retries == 1


def test_invalid_replies_are_counted_by_reason_and_not_asked_again() -> None:
    verifier = ScriptedVerifier({("t", 0): ("bbox_invalid", 0.0), ("r", 0): ("instruction_injection", 0.0)})
    reasoner = Reasoner(make_task())
    reasoner.update([sg("t"), sg("r")])
    while reasoner.step(verifier):
        pass
    reasoner.update([sg("t"), sg("r")])
    assert reasoner.next() is None
    assert reasoner.stats.rejected == {"bbox_invalid": 1, "instruction_injection": 1}


def test_in_flight_subgraphs_are_not_handed_out_twice_and_stale_results_are_ignored() -> None:
    reasoner = Reasoner(make_task())
    reasoner.update([sg("t"), sg("r")])
    first, second = reasoner.next(), reasoner.next()
    assert first.signature == ("t", 0) and second.signature == ("r", 0) and reasoner.next() is None
    assert len(reasoner.in_flight) == 2
    reasoner.abandon()  # mission ended: forget requests in flight
    late = VerifyResult(True, hyp(("t", 0)), "ok", "", 9.0, "vlm", ("t", 0))
    assert reasoner.accept(late) is None and not reasoner.done
    assert reasoner.stats.stale_results == 1


def test_retract_resumes_the_search_after_a_false_positive() -> None:
    verifier = ScriptedVerifier({("t", 0): ("ok", 0.9), ("r", 0): ("ok", 0.9)})
    reasoner = Reasoner(make_task())
    reasoner.update([sg("t"), sg("r")])
    reasoner.step(verifier)
    assert reasoner.done
    reasoner.retract("VerifyTarget saw no mug up close")
    assert not reasoner.done
    reasoner.step(verifier)
    assert reasoner.confirmed.subgraph_signature == ("r", 0)


def test_duplicate_signatures_in_one_snapshot_are_checked_once() -> None:
    reasoner = Reasoner(make_task())
    assert reasoner.update([sg("t"), sg("t")]) == 1


# ---------------------------------------------------------------------------- offline verifier
def test_offline_verifier_finds_the_target_by_label_in_its_largest_view() -> None:
    result = OfflineVerifier().verify(make_subgraph(), make_task())
    assert result.found and result.source == "offline"
    h = result.hypothesis
    assert h.source == "offline" and h.object_id == 2 and h.label == "mug"
    assert h.anchor_id == 10  # the mug's box is larger in anchor 10 than in anchor 11
    np.testing.assert_allclose(h.bbox, [0.4, 0.3, 0.55, 0.6])
    assert "offline" in h.evidence and "attributes not checked: blue" in h.evidence
    assert h.confidence == pytest.approx(0.9)


def test_offline_verifier_needs_enough_observations_and_confidence() -> None:
    task = make_task()
    few = OfflineVerifier().verify(make_subgraph(mug_obs=1), task)
    assert not few.found and few.reason == "insufficient_observations"
    weak = OfflineVerifier().verify(make_subgraph(mug_conf=0.2, mug_obs=2), task)
    assert not weak.found and weak.reason == "low_confidence"


def test_offline_verifier_reports_no_match_for_an_absent_target() -> None:
    task = TaskSpec("find the toilet", ("toilet",))
    result = OfflineVerifier().verify(make_subgraph(), task)
    assert not result.found and result.reason == "no_matching_object" and not result.rejected


def test_offline_verifier_uses_similarity_for_near_synonyms() -> None:
    task = TaskSpec("find a cup", ("cup",))

    def similarity(a: str, b: str) -> float:
        return 0.9 if {a, b} == {"mug", "cup"} else 0.0

    assert not OfflineVerifier().verify(make_subgraph(), task).found
    result = OfflineVerifier(similarity=similarity).verify(make_subgraph(), task)
    assert result.found and result.hypothesis.object_id == 2
    assert result.hypothesis.confidence == pytest.approx(0.9 * 0.9)


def test_offline_verifier_skips_views_with_an_empty_box() -> None:
    base = make_subgraph()
    a10 = dataclasses.replace(base.anchors[0], boxes=np.array([[0, 0.5, 0.4, 1.0], [0.4, 0.3, 0.4, 0.6],
                                                               [0.5, 0.5, 0.9, 0.9]]))
    broken = dataclasses.replace(base, anchors=(a10,) + base.anchors[1:])
    result = OfflineVerifier().verify(broken, make_task())
    assert result.found and result.hypothesis.anchor_id == 11


def test_the_reasoner_runs_on_the_offline_verifier() -> None:
    reasoner = Reasoner(make_task())
    reasoner.update([make_subgraph(signature=("r", 0), mug_obs=1), make_subgraph(signature=("t", 0))])
    verifier = OfflineVerifier()
    while reasoner.step(verifier):
        pass
    assert reasoner.confirmed.source == "offline" and reasoner.confirmed.subgraph_signature == ("t", 0)


def test_the_config_selects_the_verifier(server) -> None:
    from hiconav.reasoning import VERIFIERS, VLMVerifier, make_verifier

    from .helpers import fast_config

    assert isinstance(make_verifier(ReasoningConfig()), OfflineVerifier)
    assert isinstance(make_verifier(ReasoningConfig(backend="vlm")), OfflineVerifier)  # no endpoint
    vlm = make_verifier(fast_config(server.base_url))
    assert isinstance(vlm, VLMVerifier)
    vlm.client.close()
    assert isinstance(make_verifier(fast_config(server.base_url).model_copy(update={"backend": "offline"})),
                      OfflineVerifier)
    assert VERIFIERS.names() == ["offline", "vlm"]


def test_a_target_seen_for_the_first_time_goes_before_re_checks_of_judged_ones() -> None:
    def around(focus: int, version: int):
        return _Focused(sg(f"t{focus}", version), focus)

    verifier = ScriptedVerifier({})
    reasoner = Reasoner(make_task())
    reasoner.update([around(1, 0), around(2, 0)])
    reasoner.step(verifier), reasoner.step(verifier)
    # both changed by one more view, and a third instance appears last in the queue
    reasoner.update([around(1, 1), around(2, 1), around(3, 0)])
    reasoner.step(verifier)
    assert verifier.asked[-1] == ("t3", 0)
    reasoner.step(verifier)
    assert verifier.asked[-1] == ("t1", 1)  # then the queue's own order
    plain = Reasoner(make_task(), ReasoningConfig(fresh_targets_first=False))
    plain.update([around(1, 0)])
    plain.step(verifier)
    plain.update([around(1, 1), around(3, 0)])
    assert plain.next().signature == ("t1", 1)


class _Focused:
    """A subgraph with a focus object (FakeSubgraph has none)."""

    def __init__(self, inner, focus: int) -> None:
        self.__dict__.update(vars(inner))
        self.focus_object_id = focus
