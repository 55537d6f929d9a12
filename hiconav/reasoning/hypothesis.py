"""The result of subgraph verification: where the target is (anchor, object node, box).

A TargetHypothesis is a frozen message that crosses actor boundaries; it carries no command and
nothing here may produce one. ``source`` says whether a VLM or the offline reasoner made it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiconav.types import freeze


@dataclass(frozen=True)
class TargetHypothesis:
    """The target seen in one visual anchor.

    anchor_id: the AnchorView id; object_id: the ObjectView id in that anchor, or None when the
    target is visible but not (yet) an object node; bbox: (4,) float64 normalised xyxy in the
    anchor's image, 0 <= x1 < x2 <= 1, 0 <= y1 < y2 <= 1; confidence in [0, 1]; evidence: the
    reasoner's short justification; latency_s: wall time of the request that produced it;
    source: "vlm" | "offline"; subgraph_signature: the Subgraph.signature it answers; label: the
    target label it refers to.
    """

    anchor_id: int
    object_id: int | None
    bbox: np.ndarray
    confidence: float
    evidence: str
    latency_s: float
    source: str
    subgraph_signature: tuple
    label: str = ""

    def __post_init__(self) -> None:
        bbox = np.asarray(self.bbox, dtype=np.float64).reshape(4)
        object.__setattr__(self, "bbox", freeze(bbox))

    def to_json(self) -> dict:
        return {
            "anchor_id": self.anchor_id,
            "object_id": self.object_id,
            "bbox": [round(float(v), 4) for v in self.bbox],
            "confidence": round(float(self.confidence), 4),
            "evidence": self.evidence,
            "latency_s": round(float(self.latency_s), 4),
            "source": self.source,
            "label": self.label,
        }
