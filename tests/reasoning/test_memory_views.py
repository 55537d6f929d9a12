"""The verifiers on the memory graph's real view types (hiconav.memory AnchorView / ObjectView).

The other reasoning tests use local look-alikes so that they do not depend on the memory code;
this one checks that the real frozen views (read-only arrays, float32 boxes) work as well.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from hiconav.reasoning import OfflineVerifier, VLMClient, VLMVerifier
from hiconav.types import CameraIntrinsics, Pose2D

from .helpers import fast_config, image, make_task

snapshot = pytest.importorskip("hiconav.memory.snapshot")


@dataclass(frozen=True)
class Subgraph:  # the contract's fields; hiconav.memory.Subgraph where it exists
    kind: str
    anchors: tuple
    objects: tuple
    priority: float
    signature: tuple


def real_subgraph():
    try:
        from hiconav.memory import Subgraph as Real  # type: ignore[attr-defined]
    except ImportError:
        Real = Subgraph
    K = CameraIntrinsics.from_hfov(64, 48, 79)

    def obj(i, label, anchors):
        return snapshot.ObjectView(i, label, 0.9, np.zeros(3), -np.ones(3), np.ones(3), 3,
                                   np.zeros(4, np.float32), anchors)

    def anchor(i, ids, boxes):
        return snapshot.AnchorView(i, Pose2D(0, 0, 0), np.eye(4), K, 0.0, image(i), ids,
                                   np.asarray(boxes, np.float32), ("sink", "mug"))

    objects = (obj(1, "sink", (10,)), obj(2, "mug", (10, 11)), obj(3, "counter_top", (10,)),
               obj(4, "chair", (11,)), obj(5, "sofa", (12,)))
    anchors = (anchor(10, (1, 2, 3), [[0, 0.5, 0.4, 1], [0.4, 0.3, 0.55, 0.6], [0.5, 0.5, 0.9, 0.9]]),
               anchor(11, (2, 4), [[0.1, 0.2, 0.2, 0.3], [0.2, 0.2, 0.4, 0.45]]),
               anchor(12, (5,), [[0.1, 0.1, 0.9, 0.9]]))
    try:
        return Real(kind="target", anchors=anchors, objects=objects, priority=3.0, signature=("t", 1))
    except TypeError:
        return Subgraph("target", anchors, objects, 3.0, ("t", 1))


def test_offline_verifier_on_real_views() -> None:
    result = OfflineVerifier().verify(real_subgraph(), make_task())
    assert result.found and result.hypothesis.anchor_id == 10 and result.hypothesis.object_id == 2


def test_vlm_verifier_on_real_views(server) -> None:
    server.script("good_code_fence.json")
    config = fast_config(server.base_url)
    with VLMClient(config.vlm) as client:
        result = VLMVerifier(client, config).verify(real_subgraph(), make_task())
    assert result.found and result.hypothesis.anchor_id == 11 and result.hypothesis.object_id == 2
