"""Optional real open-vocabulary detector: OWL-ViT / OWLv2 through Hugging Face transformers.

Weights load from a local folder named in ``perception.owlvit.weights_path``; nothing is ever
downloaded (``local_files_only`` and the offline environment variables). torch and transformers
are imported only when the detector is built. The image processor used is the PIL one, so that
torchvision is never needed (installing it would replace the CPU torch build).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from hiconav.errors import ConfigError, FrameError
from hiconav.perception.config import OwlVitConfig
from hiconav.perception.detector import DETECTORS
from hiconav.types import Detection, Frame

__all__ = ["DEFAULT_VOCABULARY", "OwlVitDetector"]

log = logging.getLogger(__name__)

DEFAULT_VOCABULARY = ("chair", "sofa", "plant", "bed", "toilet", "tv")


def _offline() -> None:
    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")


def _prompt(word: str) -> str:
    return "a photo of a " + word.replace("_", " ")


@DETECTORS.register("owlvit")
class OwlVitDetector:
    """OWL-ViT / OWLv2 zero-shot detection (source "owlvit").

    Built from ``config.weights_path`` (a transformers checkpoint folder), or directly from a
    ``model`` and ``processor`` (used by the tests with a randomly initialised model).
    """

    name = "owlvit"

    def __init__(
        self, config: OwlVitConfig | None = None, *, model: Any = None, processor: Any = None
    ) -> None:
        self.config = config or OwlVitConfig()
        if model is None or processor is None:
            model, processor = self._load(self.config)
        self.model = model.eval()
        self.processor = processor
        self.is_v2 = getattr(model.config, "model_type", "owlvit") == "owlv2"

    @staticmethod
    def _load(config: OwlVitConfig) -> tuple[Any, Any]:
        if not config.weights_path:
            raise ConfigError(
                "the owlvit detector needs local weights: set perception.owlvit.weights_path "
                "to a transformers OWL-ViT/OWLv2 checkpoint folder (nothing is downloaded), "
                "or use perception.detector: oracle",
                field="perception.owlvit.weights_path",
            )
        path = Path(config.weights_path).expanduser()
        if not (path / "config.json").is_file():
            raise ConfigError(
                f"{path} is not a transformers checkpoint folder (no config.json)",
                field="perception.owlvit.weights_path",
            )
        _offline()
        import json

        from transformers import AutoTokenizer

        model_type = json.loads((path / "config.json").read_text()).get("model_type", "owlvit")
        if model_type == "owlv2":
            from transformers import Owlv2ForObjectDetection as Model
            from transformers import Owlv2ImageProcessorPil as ImageProc
            from transformers import Owlv2Processor as Proc
        else:
            from transformers import OwlViTForObjectDetection as Model
            from transformers import OwlViTImageProcessorPil as ImageProc
            from transformers import OwlViTProcessor as Proc
        model = Model.from_pretrained(str(path), local_files_only=True).to(config.device)
        processor = Proc(
            image_processor=ImageProc.from_pretrained(str(path), local_files_only=True),
            tokenizer=AutoTokenizer.from_pretrained(str(path), local_files_only=True),
        )
        log.info("loaded %s detector from %s", model_type, path)
        return model, processor

    def detect(self, frame: Frame, vocabulary: Sequence[str] = ()) -> list[Detection]:
        """Boxes (pixels, xyxy) with labels from ``vocabulary`` (DEFAULT_VOCABULARY if empty)."""
        import torch

        rgb = np.asarray(frame.rgb)
        if rgb.ndim != 3 or rgb.shape[2] != 3:
            raise FrameError(f"rgb must be (H, W, 3), got {rgb.shape}", field="frame.rgb")
        vocab = list(vocabulary) or list(DEFAULT_VOCABULARY)
        inputs = self.processor(text=[[_prompt(v) for v in vocab]], images=[rgb], return_tensors="pt")
        device = next(self.model.parameters()).device
        inputs = {k: v.to(device) if hasattr(v, "to") else v for k, v in inputs.items()}
        with torch.no_grad():
            outputs = self.model(**inputs)
        return self.postprocess(outputs, vocab, rgb.shape[0], rgb.shape[1])

    def postprocess(self, outputs: Any, vocab: Sequence[str], height: int, width: int) -> list[Detection]:
        """Model outputs -> detections in image pixels, thresholded, clipped, best first."""
        side = max(height, width)
        # OWLv2 pads the image to a square at the bottom/right before resizing
        target = [(side, side)] if self.is_v2 else [(height, width)]
        res = self.processor.post_process_grounded_object_detection(
            outputs, threshold=self.config.score_threshold, target_sizes=target, text_labels=[list(vocab)]
        )[0]
        boxes = res["boxes"].detach().cpu().numpy().astype(np.float32).reshape(-1, 4)
        scores = res["scores"].detach().cpu().numpy().reshape(-1)
        labels = res["labels"].detach().cpu().numpy().reshape(-1)
        boxes[:, [0, 2]] = np.clip(boxes[:, [0, 2]], 0, width)
        boxes[:, [1, 3]] = np.clip(boxes[:, [1, 3]], 0, height)
        order = np.argsort(-scores)[: self.config.max_detections]
        out = []
        for i in order:
            b = boxes[i]
            if b[2] <= b[0] or b[3] <= b[1]:
                continue
            out.append(
                Detection(
                    label=vocab[int(labels[i])], score=float(scores[i]), box_xyxy=b.copy(), source="owlvit"
                )
            )
        return out
