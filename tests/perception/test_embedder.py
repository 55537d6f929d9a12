"""hiconav.perception embedders: the offline MiniLM default and the hashing fallback."""

from __future__ import annotations

import numpy as np
import pytest

from hiconav.errors import ConfigError
from hiconav.perception import Embedder, HashingEmbedder, MiniLMEmbedder, get_embedder


@pytest.fixture(scope="module")
def minilm() -> MiniLMEmbedder:
    return get_embedder("minilm")  # type: ignore[return-value]


def test_minilm_embeds_unit_vectors(minilm):
    assert isinstance(minilm, Embedder)
    e = minilm.embed(["sofa", "a potted plant", "toilet"])
    assert e.shape == (3, 384) and e.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(e, axis=1), 1.0, atol=1e-5)


def test_minilm_similarity_is_semantic(minilm):
    assert minilm.similarity("sofa", "couch") > minilm.similarity("sofa", "toilet")
    assert minilm.similarity("tv", "television") > minilm.similarity("tv", "bed")
    assert minilm.similarity("find the bed", "bed") > minilm.similarity("find the bed", "sink")
    assert minilm.similarity("chair", "chair") == pytest.approx(1.0, abs=1e-5)


def test_minilm_caches_per_text(minilm):
    a = minilm.embed(["dining_table"])
    assert "dining table" in minilm._cache
    b = minilm.embed(["dining table"])  # underscores and spaces are the same label
    np.testing.assert_array_equal(a, b)
    assert get_embedder("minilm") is minilm


def test_hashing_fallback_is_fast_and_deterministic():
    h = HashingEmbedder()
    e = h.embed(["chair", "armchair", "toilet"])
    np.testing.assert_allclose(np.linalg.norm(e, axis=1), 1.0, atol=1e-6)
    assert h.similarity("chair", "armchair") > h.similarity("chair", "toilet")
    np.testing.assert_array_equal(HashingEmbedder().embed(["chair"]), h.embed(["chair"]))


def test_unknown_embedder_names_the_setting():
    with pytest.raises(ConfigError, match="perception.embedder"):
        get_embedder("nope")
