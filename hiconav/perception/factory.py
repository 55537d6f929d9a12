"""Build the configured detector and embedder from PerceptionConfig (perception.detector / .embedder).

Only wiring: the detectors and embedders themselves live in their own modules.
"""

from __future__ import annotations

from hiconav.errors import ConfigError
from hiconav.perception.config import PerceptionConfig
from hiconav.perception.detector import DETECTORS, Detector
from hiconav.perception.embedder import Embedder, get_embedder

__all__ = ["build_detector", "build_embedder"]


def build_detector(
    config: PerceptionConfig | None = None,
    *,
    instance_categories: dict[int, str] | None = None,
    seed: int = 0,
) -> Detector:
    """The detector named by ``config.detector``.

    The oracle needs the simulator's ``instance_categories`` (House.instance_categories); a
    real detector ignores them. User detectors given as ``package.module:Class`` are called
    with no arguments.
    """
    config = config or PerceptionConfig()
    cls = DETECTORS.get(config.detector, field="perception.detector")
    if config.detector == "oracle":
        if instance_categories is None:
            raise ConfigError(
                "the oracle detector needs the simulator's instance categories; it only "
                "works in simulation (use perception.detector: owlvit on a robot)",
                field="perception.detector",
            )
        return cls(instance_categories, config.oracle, seed=seed)
    if config.detector == "owlvit":
        return cls(config.owlvit)
    return cls()


def build_embedder(config: PerceptionConfig | None = None) -> Embedder:
    """The shared embedder named by ``config.embedder`` (one per process)."""
    config = config or PerceptionConfig()
    return get_embedder(config.embedder)
