"""hiconav.perception.OwlVitDetector: the real pre/post-processing on a randomly initialised tiny
OWL-ViT built from a config (no weights, no download), and the error without weights."""

from __future__ import annotations

import json
import string
from types import SimpleNamespace

import numpy as np
import pytest

from hiconav.errors import ConfigError
from hiconav.perception import DETECTORS, OwlVitConfig, OwlVitDetector
from hiconav.types import CameraIntrinsics, Frame, Pose2D

torch = pytest.importorskip("torch")
transformers = pytest.importorskip("transformers")


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """A 2-layer OWL-ViT with random weights and a character-level CLIP tokenizer."""
    d = tmp_path_factory.mktemp("owl")
    vocab = {"!": 0, "<|startoftext|>": 1, "<|endoftext|>": 2}  # OWL-ViT treats id 0 at BOS as padding
    for ch in string.ascii_lowercase:
        vocab[ch] = len(vocab)
        vocab[ch + "</w>"] = len(vocab)
    (d / "vocab.json").write_text(json.dumps(vocab))
    (d / "merges.txt").write_text("#version: 0.2\n")
    tok = transformers.CLIPTokenizer(
        str(d / "vocab.json"), str(d / "merges.txt"), pad_token="<|endoftext|>", model_max_length=16
    )
    ip = transformers.OwlViTImageProcessorPil(
        size={"height": 32, "width": 32}, crop_size={"height": 32, "width": 32}
    )
    proc = transformers.OwlViTProcessor(image_processor=ip, tokenizer=tok)
    cfg = transformers.OwlViTConfig(
        text_config=dict(
            vocab_size=len(vocab),
            hidden_size=32,
            intermediate_size=37,
            num_hidden_layers=2,
            num_attention_heads=4,
            max_position_embeddings=16,
            bos_token_id=1,
            eos_token_id=2,
            pad_token_id=2,
        ),
        vision_config=dict(
            hidden_size=32,
            intermediate_size=37,
            num_hidden_layers=2,
            num_attention_heads=4,
            image_size=32,
            patch_size=8,
        ),
        projection_dim=32,
    )
    torch.manual_seed(0)
    model = transformers.OwlViTForObjectDetection(cfg)
    return model, proc


def frame(h: int = 48, w: int = 64) -> Frame:
    rgb = np.random.default_rng(0).integers(0, 255, (h, w, 3), dtype=np.uint8)
    return Frame(
        rgb=rgb,
        depth=np.ones((h, w), np.float32),
        intrinsics=CameraIntrinsics.from_hfov(w, h, 79),
        T_world_cam=np.eye(4),
        base_pose=Pose2D(0, 0, 0),
        stamp=0.0,
    )


def test_without_weights_the_error_names_the_setting():
    with pytest.raises(ConfigError, match=r"perception\.owlvit\.weights_path"):
        OwlVitDetector(OwlVitConfig())
    with pytest.raises(ConfigError, match="config.json"):
        OwlVitDetector(OwlVitConfig(weights_path="/nonexistent/owlvit"))
    assert DETECTORS.get("owlvit") is OwlVitDetector


def test_detect_runs_the_real_model_path(tiny):
    model, proc = tiny
    det = OwlVitDetector(OwlVitConfig(score_threshold=0.0, max_detections=10), model=model, processor=proc)
    out = det.detect(frame(), ["sofa", "tv"])
    assert len(out) <= 10
    scores = [d.score for d in out]
    assert scores == sorted(scores, reverse=True)
    for d in out:
        assert d.source == "owlvit" and d.label in ("sofa", "tv")
        x0, y0, x1, y1 = d.box_xyxy
        assert 0 <= x0 < x1 <= 64 and 0 <= y0 < y1 <= 48


def test_postprocess_converts_normalised_boxes_to_pixels(tiny):
    model, proc = tiny
    det = OwlVitDetector(OwlVitConfig(score_threshold=0.5), model=model, processor=proc)
    logits = torch.tensor([[[4.0, -4.0], [-4.0, 3.0], [-5.0, -5.0], [6.0, 0.0]]])  # 4 queries, 2 labels
    boxes = torch.tensor(
        [
            [
                [0.5, 0.5, 0.2, 0.4],  # cx, cy, w, h (normalised)
                [0.25, 0.75, 0.1, 0.1],
                [0.5, 0.5, 1.0, 1.0],
                [0.95, 0.5, 0.3, 0.2],
            ]
        ]
    )  # crosses the right edge: clipped
    out = det.postprocess(SimpleNamespace(logits=logits, pred_boxes=boxes), ["sofa", "tv"], 100, 200)
    assert [d.label for d in out] == ["sofa", "sofa", "tv"]  # sorted by score; query 2 below threshold
    np.testing.assert_allclose(out[1].box_xyxy, [80, 30, 120, 70], atol=1e-3)
    np.testing.assert_allclose(out[2].box_xyxy, [40, 70, 60, 80], atol=1e-3)
    np.testing.assert_allclose(out[0].box_xyxy, [160, 40, 200, 60], atol=1e-3)
    assert out[0].score == pytest.approx(1 / (1 + np.exp(-6.0)), abs=1e-6)
