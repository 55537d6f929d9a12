"""The VLM client over real HTTP on 127.0.0.1: retries, back-off, limits, cancellation, latency."""

from __future__ import annotations

import threading
import time

import cv2
import numpy as np
import pytest

from hiconav.reasoning import VLMClient, VLMConfig, image_data_url

from .fake_server import FakeVLMServer
from .helpers import fast_vlm

MESSAGES = [{"role": "user", "content": "hello"}]


def test_a_good_reply_returns_its_content_and_records_latency(server) -> None:
    server.script("good_json_mode.json")
    with VLMClient(fast_vlm(server.base_url)) as client:
        result = client.chat(MESSAGES)
        stats = client.latency_stats()
    assert result.ok and result.status == 200 and result.attempts == 1
    assert '"visible": 1' in result.content and result.finish_reason == "stop"
    assert result.latency_s > 0 and stats["n"] == 1 and stats["errors"] == 0
    assert stats["max_s"] == pytest.approx(result.latency_s)


def test_500_then_success_is_retried(server) -> None:
    server.script({"file": "http_500.json", "status": 500}, "good_json_mode.json")
    with VLMClient(fast_vlm(server.base_url)) as client:
        result = client.chat(MESSAGES)
    assert result.ok and result.attempts == 2 and len(server.requests) == 2


def test_429_twice_then_success_within_two_retries(server) -> None:
    rate = {"file": "http_429.json", "status": 429, "headers": {"Retry-After": "0"}}
    server.script(rate, rate, "good_json_mode.json")
    with VLMClient(fast_vlm(server.base_url, max_retries=2)) as client:
        result = client.chat(MESSAGES)
    assert result.ok and result.attempts == 3


def test_retries_are_bounded(server) -> None:
    server.script(*[{"file": "http_500.json", "status": 500}] * 5)
    with VLMClient(fast_vlm(server.base_url, max_retries=2)) as client:
        result = client.chat(MESSAGES)
    assert result.error == "http_500" and result.attempts == 3 and len(server.requests) == 3


def test_backoff_is_exponential(server) -> None:
    server.script(*[{"file": "http_500.json", "status": 500}] * 3)
    with VLMClient(fast_vlm(server.base_url, max_retries=2, backoff_s=0.1, backoff_max_s=5.0)) as client:
        client.chat(MESSAGES)
    stamps = [r["stamp"] for r in server.requests]
    gaps = np.diff(stamps)
    assert gaps[0] >= 0.1 and gaps[1] >= 0.2  # 0.1 s, then 0.2 s


def test_retry_after_is_honoured(server) -> None:
    server.script({"file": "http_429.json", "status": 429, "headers": {"Retry-After": "0.25"}},
                  "good_json_mode.json")
    with VLMClient(fast_vlm(server.base_url, backoff_s=0.01, backoff_max_s=1.0)) as client:
        result = client.chat(MESSAGES)
    assert result.ok
    assert server.requests[1]["stamp"] - server.requests[0]["stamp"] >= 0.25


def test_4xx_other_than_429_is_not_retried(server) -> None:
    server.script(*[{"file": "http_400.json", "status": 400}] * 3)
    with VLMClient(fast_vlm(server.base_url, max_retries=2)) as client:
        result = client.chat(MESSAGES)
    assert result.error == "http_400" and result.attempts == 1


def test_a_timeout_is_retried_then_reported(server) -> None:
    slow = {"file": "good_json_mode.json", "mode": "slow", "delay_s": 1.0}
    server.script(slow, slow)
    with VLMClient(fast_vlm(server.base_url, timeout_s=0.2)) as client:
        t0 = time.monotonic()
        result = client.chat(MESSAGES)
    assert result.error == "timeout" and result.attempts == 2
    assert time.monotonic() - t0 < 1.0


def test_a_body_over_the_limit_is_not_read_in_full(server) -> None:
    server.script({"mode": "huge_chunked", "size": 10_000_000})
    with VLMClient(fast_vlm(server.base_url, timeout_s=2.0)) as client:
        t0 = time.monotonic()
        result = client.chat(MESSAGES)
    assert result.error == "oversized" and result.attempts == 1  # not retried
    assert time.monotonic() - t0 < 2.0


def test_content_length_over_the_limit_is_rejected_before_reading(server) -> None:
    server.script({"mode": "huge", "size": 10_000_000})
    with VLMClient(fast_vlm(server.base_url)) as client:
        result = client.chat(MESSAGES)
    assert result.error == "oversized" and "Content-Length" in result.detail


def test_cancel_aborts_a_request_in_flight() -> None:
    with FakeVLMServer() as srv:
        srv.script({"file": "good_json_mode.json", "mode": "slow", "delay_s": 5.0})
        client = VLMClient(fast_vlm(srv.base_url, timeout_s=10.0, max_retries=3))
        out: dict = {}
        worker = threading.Thread(target=lambda: out.setdefault("r", client.chat(MESSAGES)))
        t0 = time.monotonic()
        worker.start()
        assert srv.request_arrived.wait(5.0)
        client.cancel()
        worker.join(3.0)
        assert not worker.is_alive()
        assert out["r"].error == "cancelled" and time.monotonic() - t0 < 3.0
        # refused while cancelled, served again after reset()
        assert client.chat(MESSAGES).error == "cancelled" and len(srv.requests) == 1
        srv.script("good_json_mode.json")
        client.reset()
        assert client.chat(MESSAGES).ok
        client.close()


def test_cancel_interrupts_the_backoff_wait() -> None:
    with FakeVLMServer() as srv:
        busy = {"file": "http_503_overloaded.json", "status": 503, "headers": {"Retry-After": "30"}}
        srv.script(busy, busy, busy)
        client = VLMClient(fast_vlm(srv.base_url, max_retries=2, backoff_max_s=60.0))
        out: dict = {}
        worker = threading.Thread(target=lambda: out.setdefault("r", client.chat(MESSAGES)))
        worker.start()
        assert srv.request_arrived.wait(5.0)
        client.cancel()
        worker.join(3.0)
        assert not worker.is_alive() and out["r"].error == "cancelled"
        client.close()


@pytest.mark.parametrize("max_in_flight", [1, 2])
def test_at_most_max_in_flight_requests(max_in_flight: int) -> None:
    with FakeVLMServer() as srv:
        srv.script(*[{"file": "good_json_mode.json", "mode": "slow", "delay_s": 0.2}] * 4)
        client = VLMClient(fast_vlm(srv.base_url, timeout_s=5.0, max_in_flight=max_in_flight))
        results = []
        threads = [threading.Thread(target=lambda: results.append(client.chat(MESSAGES))) for _ in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(10.0)
        client.close()
    assert len(results) == 4 and all(r.ok for r in results)
    assert srv.max_active == max_in_flight


def test_an_unreachable_server_is_a_transport_error() -> None:
    with FakeVLMServer() as srv:
        url = srv.base_url
    with VLMClient(fast_vlm(url, max_retries=1)) as client:  # the port is closed now
        result = client.chat(MESSAGES)
    assert result.error == "transport" and result.attempts == 2


def test_a_client_needs_an_endpoint() -> None:
    with pytest.raises(ValueError, match="base_url"):
        VLMClient(VLMConfig())


def test_config_rejects_bad_urls_and_in_flight_limits() -> None:
    with pytest.raises(ValueError, match="http"):
        VLMConfig(base_url="127.0.0.1:8080/v1")
    with pytest.raises(ValueError):
        VLMConfig(base_url="http://x/v1", max_in_flight=3)
    assert VLMConfig(base_url="http://127.0.0.1:8080/v1/").base_url == "http://127.0.0.1:8080/v1"


@pytest.mark.parametrize("fmt,mime", [("jpeg", "image/jpeg"), ("png", "image/png")])
def test_images_are_base64_data_urls(fmt: str, mime: str) -> None:
    import base64

    rgb = np.zeros((300, 1000, 3), np.uint8)
    rgb[:, :, 0] = 255  # pure red in RGB
    url = image_data_url(rgb, fmt, max_side=200)
    head, data = url.split(",", 1)
    assert head == f"data:{mime};base64"
    bgr = cv2.imdecode(np.frombuffer(base64.b64decode(data), np.uint8), cv2.IMREAD_COLOR)
    assert bgr.shape == (60, 200, 3)  # longer side 200, aspect kept
    assert bgr[30, 100, 2] > 200 and bgr[30, 100, 0] < 50  # still red once decoded (BGR order)


def test_image_encoding_rejects_wrong_types() -> None:
    with pytest.raises(ValueError, match="uint8"):
        image_data_url(np.zeros((4, 4, 3), np.float32))
