"""Subgraph verification against a real HTTP server on 127.0.0.1 replaying recorded replies.

Every case of tests/data/vlm_replies/manifest.json (good replies and >= 40 bad ones: malformed
JSON, wrong indices, boxes out of range, empty, 10 MB bodies, HTTP 500/429, slow beyond the
timeout, replies that tell the robot what to do, ...) must end as the manifest says: a
hypothesis for the right anchor and object node, or "not found" with the right reason, never an
exception and never anything that carries a command.
"""

from __future__ import annotations

import dataclasses
import json
import time

import pytest

from hiconav.reasoning import VLMClient, VLMVerifier
from hiconav.reasoning.hypothesis import TargetHypothesis

from .fake_server import load_manifest
from .helpers import fast_config, make_subgraph, make_task

MANIFEST = load_manifest()
CASES = MANIFEST["verification"]


def test_the_manifest_keeps_at_least_40_bad_replies() -> None:
    bad = [c for c in CASES if c["expect"]["reason"] not in ("ok", "not_visible")]
    assert len(bad) >= 40
    reasons = {c["expect"]["reason"] for c in bad}
    for needed in ("malformed_json", "view_out_of_range", "object_out_of_range", "bbox_invalid", "empty",
                   "oversized", "http_500", "http_429", "timeout", "instruction_injection", "tool_call",
                   "truncated"):
        assert needed in reasons


@pytest.mark.parametrize("case", CASES, ids=[c["name"] for c in CASES])
def test_recorded_reply(server, case) -> None:
    config = fast_config(server.base_url)
    spec = {k: v for k, v in case.items() if k not in ("name", "expect")}
    retried = case["expect"].get("attempts") == "max"
    server.script(*([spec] * (config.vlm.max_retries + 1 if retried else 1)))
    subgraph, task = make_subgraph(), make_task()
    with VLMClient(config.vlm) as client:
        t0 = time.monotonic()
        result = VLMVerifier(client, config).verify(subgraph, task)
        elapsed = time.monotonic() - t0
        record = client.records[-1]
    expect = case["expect"]
    assert result.reason == expect["reason"], result.detail
    assert result.source == "vlm"
    assert result.subgraph_signature == subgraph.signature
    assert elapsed < 3.0  # timeouts are 0.3 s, one retry, 10 MB never read in full
    if expect["reason"] == "ok":
        hyp = result.hypothesis
        assert isinstance(hyp, TargetHypothesis) and result.found
        assert hyp.anchor_id == expect["anchor"] and hyp.object_id == expect["object"]
        assert 0.0 <= hyp.bbox.min() and hyp.bbox.max() <= 1.0
        assert hyp.bbox[2] > hyp.bbox[0] and hyp.bbox[3] > hyp.bbox[1]
        assert hyp.source == "vlm" and hyp.latency_s > 0 and hyp.label == "mug"
        assert not hyp.bbox.flags.writeable
    else:
        assert not result.found and result.hypothesis is None
    if expect.get("attempts") == "max":
        assert record.attempts == config.vlm.max_retries + 1
        assert len(server.requests) == config.vlm.max_retries + 1
    elif expect.get("attempts") == 1:
        assert record.attempts == 1 and len(server.requests) == 1


def test_hypothesis_fields_are_exactly_the_contract(server) -> None:
    server.script("good_json_mode.json")
    config = fast_config(server.base_url)
    with VLMClient(config.vlm) as client:
        hyp = VLMVerifier(client, config).verify(make_subgraph(), make_task()).hypothesis
    names = [f.name for f in dataclasses.fields(hyp)]
    assert names[:8] == ["anchor_id", "object_id", "bbox", "confidence", "evidence", "latency_s", "source",
                         "subgraph_signature"]
    assert hyp.confidence == pytest.approx(0.9)
    assert hyp.evidence.startswith("A blue mug")
    assert json.dumps(hyp.to_json())  # serialisable for logs and reports


def test_the_request_is_one_openai_chat_call_with_images_and_json_mode(server, monkeypatch) -> None:
    monkeypatch.setenv("HICONAV_TEST_KEY", "sk-test-123")
    server.script("good_json_mode.json")
    config = fast_config(server.base_url, api_key_env="HICONAV_TEST_KEY", image_format="png")
    with VLMClient(config.vlm) as client:
        VLMVerifier(client, config).verify(make_subgraph(), make_task())
    (req,) = server.requests
    assert req["path"] == "/v1/chat/completions"
    assert req["headers"]["Authorization"] == "Bearer sk-test-123"
    body = req["json"]
    assert body["model"] == "test-model" and body["response_format"] == {"type": "json_object"}
    user = body["messages"][1]["content"]
    urls = [p["image_url"]["url"] for p in user if p["type"] == "image_url"]
    assert len(urls) == 3 and all(u.startswith("data:image/png;base64,") for u in urls)
    text = "\n".join(p["text"] for p in user if p["type"] == "text")
    assert "Step 1" in text and "Step 2" in text and "Step 3" in text
    assert "View 2: objects:\n  1. mug" in text and "2. chair" in text
    assert "blue mug" in text


def test_no_response_format_when_the_server_lacks_json_mode(server) -> None:
    server.script("good_code_fence.json")
    config = fast_config(server.base_url, json_mode=False, vision=False)
    with VLMClient(config.vlm) as client:
        result = VLMVerifier(client, config).verify(make_subgraph(), make_task())
    assert result.found
    body = server.requests[0]["json"]
    assert "response_format" not in body
    assert not any(p["type"] == "image_url" for p in body["messages"][1]["content"])


def test_at_most_k_anchors_are_sent(server) -> None:
    server.script("good_json_mode.json")
    config = fast_config(server.base_url).model_copy(update={"k": 2})
    with VLMClient(config.vlm) as client:
        VLMVerifier(client, config).verify(make_subgraph(), make_task())
    parts = server.requests[0]["json"]["messages"][1]["content"]
    assert sum(p["type"] == "image_url" for p in parts) == 2


def test_a_reply_slower_than_max_latency_is_late(server) -> None:
    server.script({"file": "good_json_mode.json", "mode": "slow", "delay_s": 0.15})
    config = fast_config(server.base_url).model_copy(update={"max_latency_s": 0.05})
    with VLMClient(config.vlm) as client:
        result = VLMVerifier(client, config).verify(make_subgraph(), make_task())
    assert not result.found and result.reason == "late"


def test_an_empty_subgraph_is_not_sent(server) -> None:
    server.script("good_json_mode.json")
    empty = dataclasses.replace(make_subgraph(), anchors=(), objects=())
    config = fast_config(server.base_url)
    with VLMClient(config.vlm) as client:
        result = VLMVerifier(client, config).verify(empty, make_task())
    assert result.reason == "empty_subgraph" and server.requests == []
