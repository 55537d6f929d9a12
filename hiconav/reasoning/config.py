"""Settings of the reasoning layer (instruction decomposition, VLM client, subgraph verification).

Pydantic models with defaults; ``hiconav/settings.py`` assembles them from YAML. This module only
declares and validates settings: it must not open sockets, read files or import heavy packages.
"""

from __future__ import annotations

import os
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator

from hiconav.limits import MAX_DURATION_S


class VLMConfig(BaseModel):
    """One OpenAI-compatible chat endpoint (llama.cpp server, vLLM, Ollama, a hosted API).

    ``base_url`` ends with the API version, e.g. ``http://127.0.0.1:8080/v1``; the client POSTs to
    ``{base_url}/chat/completions``. The API key is never stored here: ``api_key_env`` names the
    environment variable that holds it (unset or empty = no Authorization header).
    """

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    base_url: str | None = None
    model: str = "qwen3-omni"
    api_key_env: str = "HICONAV_VLM_API_KEY"
    json_mode: bool = True  # send response_format {"type": "json_object"} (server supports it)
    vision: bool = True  # send anchor images; False for text-only models (object lists only)
    connect_timeout_s: float = Field(5.0, gt=0, le=MAX_DURATION_S)
    timeout_s: float = Field(30.0, gt=0, le=MAX_DURATION_S)  # per read, and the total deadline of one attempt
    max_retries: int = Field(2, ge=0, le=10)  # extra attempts after 429 / 5xx / timeouts
    backoff_s: float = Field(0.5, ge=0, le=MAX_DURATION_S)  # first back-off; doubles each retry (exponential)
    backoff_max_s: float = Field(8.0, ge=0, le=MAX_DURATION_S)
    max_in_flight: int = Field(1, ge=1, le=2)
    max_response_bytes: int = Field(1_000_000, ge=1024)
    temperature: float = Field(0.0, ge=0, le=2)
    max_tokens: int = Field(512, ge=16)
    image_format: Literal["jpeg", "png"] = "jpeg"
    image_max_side: int = Field(512, ge=32)
    jpeg_quality: int = Field(85, ge=10, le=100)

    @field_validator("base_url")
    @classmethod
    def _check_url(cls, value: str | None) -> str | None:
        if value is None or value.strip() == "":
            return None
        value = value.strip().rstrip("/")
        if not value.startswith(("http://", "https://")):
            raise ValueError(f"base_url must start with http:// or https://, got {value!r}")
        return value

    def api_key(self) -> str | None:
        """The key from the environment variable named by ``api_key_env`` (None if unset)."""
        key = os.environ.get(self.api_key_env, "").strip()
        return key or None


class OfflineVerifierConfig(BaseModel):
    """The memory-graph verifier used without a VLM (labelled source="offline")."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    # detector confidence of the object node (0.35 chosen on 78 ProcTHOR train textnav episodes:
    # 0.5 left small targets, a statue, a vase, a plant, below it for whole episodes)
    min_confidence: float = Field(0.35, ge=0, le=1)
    min_observations: int = Field(2, ge=1)  # n_obs of the object node
    # a node observed this often passes min_confidence: detectors score small and far objects low
    # in every frame, and many observations are evidence the score is not (0: never). 3 chosen on
    # ProcTHOR train textnav seeds 0-2 (10 -> 3: SPL +0.6, +0.1, +0.5 points, SR unchanged):
    # a described instance seen three times held its verdict back while the robot drove past it
    confident_observations: int = Field(3, ge=0)
    min_similarity: float = Field(0.85, ge=0, le=1)  # label-target similarity when not equal
    # the counts of categories per room type the rooms are inferred from (a file written by
    # ``hiconav room-prior --houses FILE``); None: the shipped counts, from
    # the ProcTHOR train houses
    room_prior: str | None = None
    # the median footprint sides per category that tell a related object's box seen in part (a
    # file written by ``hiconav size-prior --houses FILE``); None: the shipped sizes, from the
    # ProcTHOR train houses
    size_prior: str | None = None


class ReasoningConfig(BaseModel):
    """Settings of the slow layer."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    backend: Literal["auto", "vlm", "offline"] = "auto"  # auto = vlm iff vlm.base_url is set
    vlm: VLMConfig = Field(default_factory=VLMConfig)
    offline: OfflineVerifierConfig = Field(default_factory=OfflineVerifierConfig)
    k: int = Field(5, ge=1, le=16)  # anchors (images) per subgraph request
    max_objects_per_anchor: int = Field(40, ge=1)
    confirm_confidence: float = Field(0.5, ge=0, le=1)  # a hypothesis at or above confirms
    # seconds of robot time (0.5 s per discrete action; the simulator's clock takes them at a fifth,
    # as ``decisions.*`` durations) a described instance whose relations hold only within the
    # boxes' noise margin waits for a clearer one before it is offered (``unresolved.due_marginal``;
    # 0: until explored out)
    marginal_patience_s: float = Field(50.0, ge=0, le=18000)
    default_vlm_confidence: float = Field(0.7, ge=0, le=1)  # when the reply gives none
    max_latency_s: float | None = Field(None, gt=0, le=MAX_DURATION_S)  # replies slower than this are "late"
    max_attempts_per_subgraph: int = Field(2, ge=1)  # transient failures (timeouts, 5xx) retried
    # a target subgraph around an object never judged goes before re-checks of judged ones
    fresh_targets_first: bool = True
    fallback_to_offline: bool = True  # decomposition falls back (labelled) when the VLM fails
    max_related: int = Field(6, ge=0)
    label_similarity_threshold: float = Field(0.62, ge=0, le=1)  # noun -> vocabulary by embedding
    vocabulary: tuple[str, ...] | None = None  # None = hiconav.reasoning.decompose.DEFAULT_VOCABULARY
    # The stepped clock's model of a reasoning call (decomposition or subgraph verification,
    # offline or VLM): its reply becomes visible latency_s +- latency_jitter_s (uniform, seeded)
    # after the request, as from a fast hosted VLM; 0 makes every call instantaneous
    latency_s: float = Field(2.0, ge=0, le=MAX_DURATION_S)
    latency_jitter_s: float = Field(0.5, ge=0, le=MAX_DURATION_S)

    def use_vlm(self) -> bool:
        """Whether the VLM backend is selected (an endpoint is configured and not forced off)."""
        if self.backend == "offline":
            return False
        return self.vlm.base_url is not None
