"""Client for OpenAI-compatible chat endpoints (llama.cpp server, vLLM, Ollama, hosted APIs).

This is the ONLY module in ``hiconav/`` that opens sockets. Its API is synchronous and meant to
be called from a worker thread (the reasoning actor); ``cancel()`` may be called from any other
thread and aborts requests in flight (their sockets are shut down) and waits in back-off.

What it guarantees:
- POST ``{base_url}/chat/completions`` with ``model``, ``messages``, ``temperature``,
  ``max_tokens`` and, when the server supports it (config ``json_mode``), ``response_format
  {"type": "json_object"}``; images go in as base64 data URLs (``image_data_url``).
- At most ``max_in_flight`` (1-2) requests at once (a semaphore).
- Bounded retries with exponential back-off (honouring ``Retry-After``) on 429, 5xx, timeouts
  and broken transfers; other 4xx are not retried.
- Bodies larger than ``max_response_bytes`` are rejected without being read in full (streamed;
  a ``Content-Length`` above the limit is rejected before reading anything).
- It never raises for network or server trouble: ``chat`` returns a ``ChatResult`` whose
  ``error`` names the reason ("timeout", "http_500", "oversized", ...). Latency is recorded per
  request in ``records``.

It must not interpret the reply (``replies.py`` does) and never produces robot commands.
"""

from __future__ import annotations

import base64
import collections
import json
import logging
import socket
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Self

import httpcore
import httpx
import numpy as np

from hiconav.reasoning.config import VLMConfig

log = logging.getLogger(__name__)

RETRY_STATUS = frozenset({408, 409, 425, 429, 500, 502, 503, 504})


@dataclass(frozen=True)
class ChatResult:
    """Outcome of one ``chat`` call (all attempts).

    content: the assistant message text (None on failure); message: the assistant message dict
    (to inspect ``tool_calls``); finish_reason: as reported by the server; error: None on success,
    else a short reason code; detail: human-readable detail; status: last HTTP status (None if no
    response); latency_s: wall time from the call to its return, back-off included; attempts:
    number of HTTP attempts; n_bytes: size of the last body read.
    """

    content: str | None
    message: dict | None
    finish_reason: str | None
    error: str | None
    detail: str
    status: int | None
    latency_s: float
    attempts: int
    n_bytes: int

    @property
    def ok(self) -> bool:
        return self.error is None


@dataclass(frozen=True)
class RequestRecord:
    """One entry of the client's latency log."""

    stamp: float
    latency_s: float
    attempts: int
    status: int | None
    error: str | None
    n_bytes: int


def image_data_url(image: np.ndarray, fmt: str = "jpeg", max_side: int = 512,
                   jpeg_quality: int = 85) -> str:
    """Encode an RGB image as a ``data:image/...;base64,`` URL.

    image: (H, W, 3) uint8 RGB (or (H, W) grey); downscaled so that its longer side is at most
    ``max_side`` pixels (aspect kept). fmt: "jpeg" or "png".
    """
    import cv2  # heavy import kept local: the client is usable without images

    img = np.asarray(image)
    if img.dtype != np.uint8:
        raise ValueError(f"image must be uint8, got {img.dtype}")
    if img.ndim == 3 and img.shape[2] == 3:
        img = cv2.cvtColor(img, cv2.COLOR_RGB2BGR)
    elif img.ndim != 2:
        raise ValueError(f"image must be (H, W, 3) RGB or (H, W) grey, got shape {img.shape}")
    h, w = img.shape[:2]
    scale = max_side / max(h, w)
    if scale < 1.0:
        img = cv2.resize(img, (max(1, round(w * scale)), max(1, round(h * scale))),
                         interpolation=cv2.INTER_AREA)
    if fmt == "png":
        ok, buf = cv2.imencode(".png", img)
        mime = "image/png"
    elif fmt in ("jpeg", "jpg"):
        ok, buf = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, int(jpeg_quality)])
        mime = "image/jpeg"
    else:
        raise ValueError(f"image format must be 'jpeg' or 'png', got {fmt!r}")
    if not ok:
        raise ValueError("cv2.imencode failed")
    return f"data:{mime};base64," + base64.b64encode(buf.tobytes()).decode("ascii")


class _TrackingBackend(httpcore.NetworkBackend):
    """httpcore's sync backend that remembers open sockets so ``cancel`` can shut them down.

    Closing a socket from another thread does not wake a blocked ``recv`` on Linux; ``shutdown``
    does, so in-flight requests fail at once with a transport error.
    """

    def __init__(self) -> None:
        self._backend = httpcore.SyncBackend()
        self._lock = threading.Lock()
        self._sockets: set[socket.socket] = set()

    def connect_tcp(self, host: str, port: int, timeout: float | None = None,
                    local_address: str | None = None, socket_options: Any = None) -> Any:
        stream = self._backend.connect_tcp(host, port, timeout=timeout, local_address=local_address,
                                           socket_options=socket_options)
        sock = stream.get_extra_info("socket")
        if sock is not None:
            with self._lock:
                self._sockets = {s for s in self._sockets if s.fileno() != -1}
                self._sockets.add(sock)
        return stream

    def connect_unix_socket(self, path: str, timeout: float | None = None,
                            socket_options: Any = None) -> Any:  # pragma: no cover - not used
        return self._backend.connect_unix_socket(path, timeout=timeout, socket_options=socket_options)

    def sleep(self, seconds: float) -> None:  # pragma: no cover - httpcore retries are off
        self._backend.sleep(seconds)

    def shutdown_all(self) -> int:
        with self._lock:
            sockets, self._sockets = list(self._sockets), set()
        n = 0
        for sock in sockets:
            try:
                sock.shutdown(socket.SHUT_RDWR)
                n += 1
            except OSError:
                pass
        return n


class _Abort(Exception):
    """Internal: stop reading a body for ``reason``."""

    def __init__(self, reason: str, detail: str) -> None:
        super().__init__(detail)
        self.reason = reason
        self.detail = detail


class VLMClient:
    """Synchronous OpenAI-compatible chat client with retries, limits and cancellation."""

    def __init__(self, config: VLMConfig, *, transport: httpx.BaseTransport | None = None,
                 max_records: int = 1000) -> None:
        if config.base_url is None:
            raise ValueError("VLMConfig.base_url is not set: no endpoint to talk to")
        self.config = config
        self.url = f"{config.base_url}/chat/completions"
        self._backend = _TrackingBackend()
        if transport is None:
            transport = httpx.HTTPTransport(retries=0)
            # Same pool httpx would build, with the socket-tracking backend (for cancel()).
            transport._pool = httpcore.ConnectionPool(
                max_connections=max(2, config.max_in_flight), http1=True, http2=False,
                network_backend=self._backend)
        headers = {"Accept": "application/json", "Accept-Encoding": "identity"}
        key = config.api_key()
        if key:
            headers["Authorization"] = f"Bearer {key}"
        self._client = httpx.Client(
            transport=transport, headers=headers, follow_redirects=False,
            timeout=httpx.Timeout(config.timeout_s, connect=config.connect_timeout_s))
        self._slots = threading.BoundedSemaphore(config.max_in_flight)
        self._cancelled = threading.Event()
        self._lock = threading.Lock()
        self.records: collections.deque[RequestRecord] = collections.deque(maxlen=max_records)

    # ------------------------------------------------------------------ control
    def cancel(self) -> None:
        """Abort requests in flight and refuse new ones until ``reset()`` (thread-safe)."""
        self._cancelled.set()
        n = self._backend.shutdown_all()
        log.info("VLM client cancelled; %d connection(s) shut down", n)

    def reset(self) -> None:
        """Accept requests again after ``cancel()`` (a new mission)."""
        self._cancelled.clear()

    @property
    def cancelled(self) -> bool:
        return self._cancelled.is_set()

    def close(self) -> None:
        self.cancel()
        self._client.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def latency_stats(self) -> dict[str, float]:
        """Count, mean, p50, max latency (s) and error count over the recorded requests."""
        with self._lock:
            recs = list(self.records)
        if not recs:
            return {"n": 0, "mean_s": 0.0, "p50_s": 0.0, "max_s": 0.0, "errors": 0}
        lat = np.array([r.latency_s for r in recs])
        return {"n": len(recs), "mean_s": float(lat.mean()), "p50_s": float(np.median(lat)),
                "max_s": float(lat.max()), "errors": sum(r.error is not None for r in recs)}

    # ------------------------------------------------------------------ requests
    def build_payload(self, messages: Sequence[dict], *, json_mode: bool | None = None,
                      max_tokens: int | None = None) -> dict:
        payload: dict[str, Any] = {
            "model": self.config.model,
            "messages": list(messages),
            "temperature": self.config.temperature,
            "max_tokens": max_tokens or self.config.max_tokens,
            "stream": False,
        }
        if self.config.json_mode if json_mode is None else json_mode:
            payload["response_format"] = {"type": "json_object"}
        return payload

    def chat(self, messages: Sequence[dict], *, json_mode: bool | None = None,
             max_tokens: int | None = None) -> ChatResult:
        """Send one chat completion request (with retries); never raises for I/O trouble."""
        t0 = time.monotonic()
        payload = self.build_payload(messages, json_mode=json_mode, max_tokens=max_tokens)
        if self._cancelled.is_set():
            return self._finish(t0, None, None, None, "cancelled", "client cancelled", None, 0, 0)
        # Wait for a slot, but give up when cancelled (polls the event, no busy loop).
        while not self._slots.acquire(timeout=0.05):
            if self._cancelled.is_set():
                return self._finish(t0, None, None, None, "cancelled", "client cancelled", None, 0, 0)
        try:
            return self._attempts(t0, payload)
        finally:
            self._slots.release()

    def _attempts(self, t0: float, payload: dict) -> ChatResult:
        cfg = self.config
        attempt = 0
        error, detail, status, n_bytes = "unknown", "", None, 0
        while attempt <= cfg.max_retries:
            attempt += 1
            if self._cancelled.is_set():
                error, detail = "cancelled", "client cancelled"
                break
            retry_after: float | None = None
            try:
                status, body, retry_after = self._post(payload)
                n_bytes = len(body)
                if 200 <= status < 300:
                    return self._parse_envelope(t0, body, status, attempt)
                error, detail = f"http_{status}", body[:200].decode("utf-8", "replace")
                if status not in RETRY_STATUS:
                    break
            except _Abort as exc:
                error, detail = exc.reason, exc.detail
                if exc.reason in ("oversized", "cancelled"):
                    break
            except httpx.TimeoutException as exc:
                error, detail = "timeout", f"{type(exc).__name__}: {exc}"
            except (httpx.RemoteProtocolError, httpx.ReadError) as exc:
                if self._cancelled.is_set():
                    error, detail = "cancelled", "client cancelled"
                    break
                error, detail = "truncated", f"{type(exc).__name__}: {exc}"
            except httpx.HTTPError as exc:
                if self._cancelled.is_set():
                    error, detail = "cancelled", "client cancelled"
                    break
                error, detail = "transport", f"{type(exc).__name__}: {exc}"
            if attempt > cfg.max_retries:
                break
            delay = min(cfg.backoff_max_s, cfg.backoff_s * (2 ** (attempt - 1)))
            if retry_after is not None:
                delay = min(cfg.backoff_max_s, max(delay, retry_after))
            log.info("VLM attempt %d failed (%s); retrying in %.2f s", attempt, error, delay)
            if self._cancelled.wait(delay):
                error, detail = "cancelled", "client cancelled during back-off"
                break
        return self._finish(t0, None, None, None, error, detail, status, attempt, n_bytes)

    def _post(self, payload: dict) -> tuple[int, bytes, float | None]:
        """One HTTP attempt: returns (status, body, Retry-After seconds) or raises _Abort / httpx errors."""
        cfg = self.config
        limit = cfg.max_response_bytes
        deadline = time.monotonic() + cfg.timeout_s
        retry_after = None
        with self._client.stream("POST", self.url, json=payload) as response:
            ra = response.headers.get("retry-after")
            if ra:
                try:
                    retry_after = max(0.0, float(ra))
                except ValueError:
                    retry_after = None
            length = response.headers.get("content-length")
            if length is not None and length.isdigit() and int(length) > limit:
                raise _Abort("oversized", f"Content-Length {length} > limit {limit} bytes")
            chunks: list[bytes] = []
            total = 0
            for chunk in response.iter_bytes():  # as received (decoded); limit on decoded size
                if self._cancelled.is_set():
                    raise _Abort("cancelled", "client cancelled while reading")
                total += len(chunk)
                if total > limit:
                    raise _Abort("oversized", f"body exceeds limit {limit} bytes (stopped reading)")
                if time.monotonic() > deadline:
                    raise httpx.ReadTimeout(f"body not complete within {cfg.timeout_s} s")
                chunks.append(chunk)
            body = b"".join(chunks)
            return response.status_code, body, retry_after

    def _parse_envelope(self, t0: float, body: bytes, status: int, attempts: int) -> ChatResult:
        try:
            data = json.loads(body)
            choice = data["choices"][0]
            message = choice.get("message") or {}
            if not isinstance(message, dict):
                raise TypeError("message is not an object")
            content = message.get("content")
            if isinstance(content, list):  # some servers return content parts
                content = "".join(p.get("text", "") for p in content if isinstance(p, dict))
            if content is not None and not isinstance(content, str):
                raise TypeError(f"content is {type(content).__name__}, not a string")
            finish = choice.get("finish_reason")
        except (ValueError, KeyError, IndexError, TypeError, AttributeError) as exc:
            return self._finish(t0, None, None, None, "bad_envelope",
                                f"not an OpenAI chat completion: {type(exc).__name__}: {exc}",
                                status, attempts, len(body))
        return self._finish(t0, content, message, finish, None, "", status, attempts, len(body))

    def _finish(self, t0: float, content: str | None, message: dict | None, finish: str | None,
                error: str | None, detail: str, status: int | None, attempts: int,
                n_bytes: int) -> ChatResult:
        latency = time.monotonic() - t0
        with self._lock:
            self.records.append(RequestRecord(time.time(), latency, attempts, status, error, n_bytes))
        if error is not None:
            log.warning("VLM request failed: %s (%s) after %d attempt(s), %.3f s",
                        error, detail[:200], attempts, latency)
        return ChatResult(content, message, finish, error, detail, status, latency, attempts, n_bytes)
