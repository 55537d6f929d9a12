"""Perception: the Detector protocol and its backends (oracle, OWL-ViT), and text embedders.

Importing this package is cheap: model code (torch, transformers) loads only when a model-backed
detector or embedder is first used.
"""

from hiconav.perception.config import OracleConfig, OwlVitConfig, PerceptionConfig
from hiconav.perception.detector import DETECTORS, Detector, normalise_label
from hiconav.perception.embedder import EMBEDDERS, Embedder, HashingEmbedder, MiniLMEmbedder, get_embedder
from hiconav.perception.factory import build_detector, build_embedder
from hiconav.perception.oracle import OracleDetector
from hiconav.perception.owlvit import OwlVitDetector

__all__ = [
    "DETECTORS",
    "EMBEDDERS",
    "Detector",
    "Embedder",
    "HashingEmbedder",
    "MiniLMEmbedder",
    "OracleConfig",
    "OracleDetector",
    "OwlVitConfig",
    "OwlVitDetector",
    "PerceptionConfig",
    "build_detector",
    "build_embedder",
    "get_embedder",
    "normalise_label",
]
