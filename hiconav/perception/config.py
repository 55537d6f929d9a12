"""Settings of the perception area (detectors, embedders), validated by pydantic.

Only data lives here: no model loading, no imports heavier than pydantic.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class OracleConfig(BaseModel):
    """Noise model of the oracle detector (reads the simulator's instance channel).

    The defaults are deliberately imperfect so that target verification matters: about one
    object in ten is missed, one frame in ten carries a spurious box, and one detection in ten
    takes the label of a similar category (sofa <-> armchair, tv <-> laptop, ...).
    """

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    miss_rate: float = Field(0.1, ge=0.0, le=1.0, description="probability to drop a visible object")
    false_positive_rate: float = Field(
        0.1, ge=0.0, le=1.0, description="probability per frame of one spurious box"
    )
    confusion_rate: float = Field(
        0.1, ge=0.0, le=1.0, description="probability to report a similar category instead"
    )
    min_pixel_area: int = Field(150, ge=1, description="objects smaller than this many pixels are not seen")
    score_min: float = Field(0.45, ge=0.0, le=1.0)
    score_max: float = Field(0.95, ge=0.0, le=1.0)
    masks: bool = Field(True, description="attach (H, W) bool masks to detections")
    extra_confusions: dict[str, list[str]] = Field(
        default_factory=dict, description="more similar-category pairs"
    )


class OwlVitConfig(BaseModel):
    """The optional open-vocabulary detector (OWL-ViT / OWLv2 through transformers)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    weights_path: str | None = Field(
        None,
        description="local folder of a transformers OWL-ViT/OWLv2 "
        "checkpoint (config.json, weights, tokenizer); never downloaded",
    )
    score_threshold: float = Field(0.15, ge=0.0, le=1.0)
    device: str = "cpu"
    max_detections: int = Field(50, ge=1)


class PerceptionConfig(BaseModel):
    """perception.* settings."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    detector: str = Field("oracle", description="registered detector name: oracle | owlvit")
    embedder: str = Field("minilm", description="registered embedder name: minilm | hashing (fallback)")
    oracle: OracleConfig = Field(default_factory=OracleConfig)
    owlvit: OwlVitConfig = Field(default_factory=OwlVitConfig)
