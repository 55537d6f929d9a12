"""A real HTTP server on 127.0.0.1 that replays recorded OpenAI-format replies (for tests).

It listens on an ephemeral port in a background thread (``http.server.ThreadingHTTPServer``) and
answers ``POST .../chat/completions`` with the next scripted reply: a file from
tests/data/vlm_replies/ served with a status and a mode:

- ``normal``: the body with ``Content-Length``;
- ``slow``: wait ``delay_s`` before sending anything (beyond the client's timeout);
- ``drip``: headers at once, then the body one byte every ``delay_s``;
- ``huge`` / ``huge_chunked``: ``size`` bytes (10 MB) with ``Content-Length`` / chunked;
- ``truncated``: a ``Content-Length`` larger than the bytes sent, then the connection closes;
- ``close``: close the connection without a reply.

Every request is recorded (path, headers, JSON body) so tests can check what the client sent.
Waits use an event that ``stop()`` sets, so no handler outlives the test for long.
"""

from __future__ import annotations

import json
import socket
import threading
import time
from collections import deque
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any, Self

REPLIES = Path(__file__).resolve().parents[1] / "data" / "vlm_replies"


def load_manifest() -> dict:
    return json.loads((REPLIES / "manifest.json").read_text(encoding="utf-8"))


class FakeVLMServer:
    """Scripted OpenAI-compatible server; use as a context manager."""

    def __init__(self, replies_dir: Path = REPLIES) -> None:
        self.replies_dir = replies_dir
        self._script: deque[dict] = deque()
        self.default: dict = {"status": 404, "body": b'{"error": {"message": "no scripted reply"}}'}
        self.requests: list[dict[str, Any]] = []
        self.request_arrived = threading.Event()
        self.active = 0  # handlers running now, and the most at once (checks max_in_flight)
        self.max_active = 0
        self._stop = threading.Event()
        self._lock = threading.Lock()
        server = self

        class Handler(BaseHTTPRequestHandler):
            protocol_version = "HTTP/1.1"
            disable_nagle_algorithm = True  # no 40 ms Nagle + delayed-ACK stall per reply

            def log_message(self, *args: Any) -> None:  # keep test output clean
                return None

            def do_POST(self) -> None:
                length = int(self.headers.get("Content-Length") or 0)
                raw = self.rfile.read(length) if length else b""
                try:
                    body = json.loads(raw) if raw else None
                except ValueError:
                    body = None
                with server._lock:
                    server.requests.append({"path": self.path, "headers": dict(self.headers), "json": body,
                                            "stamp": time.monotonic()})
                    spec = server._script.popleft() if server._script else server.default
                    server.active += 1
                    server.max_active = max(server.max_active, server.active)
                server.request_arrived.set()
                if not self.path.endswith("/chat/completions"):
                    spec = {"status": 404, "body": b'{"error": {"message": "unknown path"}}'}
                try:
                    server._serve(self, spec)
                except (TimeoutError, BrokenPipeError, ConnectionResetError, OSError):
                    self.close_connection = True
                finally:
                    with server._lock:
                        server.active -= 1

        self._httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self._httpd.daemon_threads = True
        self._thread = threading.Thread(target=self._httpd.serve_forever, kwargs={"poll_interval": 0.05},
                                        daemon=True)

    # ------------------------------------------------------------------ control
    @property
    def port(self) -> int:
        return self._httpd.server_address[1]

    @property
    def base_url(self) -> str:
        return f"http://127.0.0.1:{self.port}/v1"

    def start(self) -> FakeVLMServer:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._httpd.shutdown()
        self._httpd.server_close()

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def script(self, *specs: dict | str) -> None:
        """Queue replies: manifest-style dicts ({"file", "status", "mode", ...}) or file names."""
        with self._lock:
            self._script.clear()
            self.requests.clear()
            self.request_arrived.clear()
            self.max_active = 0
            for spec in specs:
                self._script.append({"file": spec} if isinstance(spec, str) else dict(spec))

    # ------------------------------------------------------------------ replies
    def _body(self, spec: dict) -> bytes:
        if "body" in spec:
            body = spec["body"]
            return body if isinstance(body, bytes) else json.dumps(body).encode()
        if "file" in spec:
            return (self.replies_dir / spec["file"]).read_bytes()
        return b""

    def _serve(self, h: BaseHTTPRequestHandler, spec: dict) -> None:
        mode = spec.get("mode", "normal")
        status = int(spec.get("status", 200))
        headers = {"Content-Type": "application/json", **spec.get("headers", {})}
        if mode == "close":
            h.close_connection = True
            h.connection.shutdown(socket.SHUT_RDWR)
            return
        if mode == "slow" and self._stop.wait(float(spec.get("delay_s", 2.0))):
            return
        if mode in ("huge", "huge_chunked"):
            size = int(spec.get("size", 10_000_000))
            h.send_response(status)
            for k, v in headers.items():
                h.send_header(k, v)
            if mode == "huge":
                h.send_header("Content-Length", str(size))
            else:
                h.send_header("Transfer-Encoding", "chunked")
            h.end_headers()
            chunk = b'{"pad": "' + b"x" * (64 * 1024) + b'"}'
            sent = 0
            while sent < size and not self._stop.is_set():
                part = chunk[: min(len(chunk), size - sent)]
                if mode == "huge":
                    h.wfile.write(part)
                else:
                    h.wfile.write(f"{len(part):x}\r\n".encode() + part + b"\r\n")
                sent += len(part)
            if mode == "huge_chunked":
                h.wfile.write(b"0\r\n\r\n")
            return
        body = self._body(spec)
        h.send_response(status)
        for k, v in headers.items():
            h.send_header(k, v)
        if mode == "truncated":
            h.send_header("Content-Length", str(len(body) + 500))
            h.end_headers()
            h.wfile.write(body[: len(body) // 2])
            h.wfile.flush()
            h.close_connection = True
            return
        h.send_header("Content-Length", str(len(body)))
        h.end_headers()
        if mode == "drip":
            delay = float(spec.get("delay_s", 0.1))
            for i in range(len(body)):
                h.wfile.write(body[i:i + 1])
                h.wfile.flush()
                if self._stop.wait(delay):
                    return
            return
        h.wfile.write(body)
