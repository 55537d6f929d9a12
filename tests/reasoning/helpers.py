"""Test helpers of the reasoning tests: a subgraph shaped like the memory graph's, fast settings.

The subgraph mirrors the memory engineer's contract (AnchorView / ObjectView / Subgraph fields)
with small local dataclasses, so these tests do not depend on the memory graph's code:
view 1 = anchor 10 [sink(1), mug(2), counter_top(3)], view 2 = anchor 11 [mug(2), chair(4)],
view 3 = anchor 12 [sofa(5)] (the numbering tests/data/vlm_replies/generate.py assumes).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hiconav.reasoning.config import ReasoningConfig, VLMConfig
from hiconav.types import TaskSpec


@dataclass(frozen=True)
class FakeObject:
    id: int
    label: str
    confidence: float = 0.9
    n_obs: int = 3
    anchor_ids: tuple[int, ...] = ()
    center: np.ndarray = field(default_factory=lambda: np.zeros(3))
    # every object of the fixture stands in one 0.2 m box: the task's "mug next to the sink" holds
    box_min: np.ndarray = field(default_factory=lambda: np.full(3, -0.1))
    box_max: np.ndarray = field(default_factory=lambda: np.full(3, 0.1))


@dataclass(frozen=True)
class FakeAnchor:
    id: int
    object_ids: tuple[int, ...]
    boxes: np.ndarray
    image: np.ndarray
    labels_seen: tuple[str, ...] = ()


@dataclass(frozen=True)
class FakeSubgraph:
    kind: str
    anchors: tuple[FakeAnchor, ...]
    objects: tuple[FakeObject, ...]
    priority: float
    signature: tuple


def image(seed: int, h: int = 48, w: int = 64) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 255, (h, w, 3), dtype=np.uint8)


def make_subgraph(signature: tuple = ("target", (10, 11, 12), 1), *, mug_conf: float = 0.9,
                  mug_obs: int = 3, kind: str = "target", priority: float = 3.0) -> FakeSubgraph:
    objects = (
        FakeObject(1, "sink", 0.95, 5, (10,)),
        FakeObject(2, "mug", mug_conf, mug_obs, (10, 11)),
        FakeObject(3, "counter_top", 0.8, 4, (10,)),
        FakeObject(4, "chair", 0.9, 2, (11,)),
        FakeObject(5, "sofa", 0.9, 6, (12,)),
    )
    anchors = (
        FakeAnchor(10, (1, 2, 3),
                   np.array([[0.0, 0.5, 0.4, 1.0], [0.4, 0.3, 0.55, 0.6], [0.5, 0.5, 0.9, 0.9]]),
                   image(10), ("sink", "mug", "counter_top", "window")),
        FakeAnchor(11, (2, 4), np.array([[0.1, 0.2, 0.2, 0.3], [0.2, 0.2, 0.4, 0.45]]), image(11)),
        FakeAnchor(12, (5,), np.array([[0.1, 0.1, 0.9, 0.9]]), image(12)),
    )
    return FakeSubgraph(kind, anchors, objects, priority, signature)


def make_task() -> TaskSpec:
    return TaskSpec("find the blue mug beside the sink", ("mug",), ("sink", "counter_top"),
                    {"mug": ("blue",)}, (("mug", "next to", "sink"),), "offline")


def fast_vlm(base_url: str, **over) -> VLMConfig:
    """Short timeouts and back-off so failure cases finish in well under a second."""
    values = {"base_url": base_url, "model": "test-model", "timeout_s": 0.3, "connect_timeout_s": 0.3,
              "max_retries": 1, "backoff_s": 0.01, "backoff_max_s": 0.05, "max_in_flight": 1}
    values.update(over)
    return VLMConfig(**values)


def fast_config(base_url: str, **over) -> ReasoningConfig:
    return ReasoningConfig(vlm=fast_vlm(base_url, **over))


def houses_elsewhere(source, tmp_path, n: int, name: str):
    """The first ``n`` houses of the ProcTHOR file ``source``, written to ``tmp_path/elsewhere/name``
    (a .jsonl.gz outside the data root); its path."""
    import gzip

    with gzip.open(source, "rt", encoding="utf-8") as fh:
        lines = [next(fh) for _ in range(n)]
    houses = tmp_path / "elsewhere" / name
    houses.parent.mkdir(exist_ok=True)
    with gzip.open(houses, "wt", encoding="utf-8") as fh:
        fh.writelines(lines)
    return houses
