"""The Detector protocol and the detector registry.

A detector turns one RGB(-D) frame and a vocabulary of category names into 2D detections. This
module defines the interface only; it must not import any model code.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol, runtime_checkable

from hiconav.registry import Registry
from hiconav.types import Detection, Frame, label_key

__all__ = ["DETECTORS", "Detector", "normalise_label"]


@runtime_checkable
class Detector(Protocol):
    """Anything with ``detect(frame, vocabulary) -> list[Detection]``.

    ``vocabulary`` lists the category names of interest (lowercase; spaces or underscores);
    an empty vocabulary means "every category the detector knows". Each Detection names its
    ``source`` (the detector), so that oracle results are never mistaken for real ones.
    """

    name: str

    def detect(self, frame: Frame, vocabulary: Sequence[str]) -> list[Detection]: ...


DETECTORS: Registry = Registry("detector")

# Common synonyms of the simulator's category names (lowercase snake case).
_ALIASES = {
    "couch": "sofa",
    "television": "tv",
    "tv_monitor": "tv",
    "tvmonitor": "tv",
    "potted_plant": "plant",
    "houseplant": "plant",
    "house_plant": "plant",
    "arm_chair": "armchair",
    "dining_table": "dining_table",
    "diningtable": "dining_table",
    "refrigerator": "fridge",
}


def normalise_label(label: str) -> str:
    """Lowercase snake case with the usual synonyms folded ("Couch" -> "sofa", "TV" -> "tv")."""
    key = label_key(label)
    return _ALIASES.get(key, key)
