"""The mission asks the memory for keyframes while it verifies (``KeyframeRequest``)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

from hiconav.actors.memory import MemoryNode
from hiconav.actors.mission import _ROUTES
from hiconav.mapping import OccupancyGrid
from hiconav.memory import CognitiveMemoryGraph, MemoryConfig
from hiconav.messages import KeyframeRequest, Observation
from hiconav.perception import HashingEmbedder
from hiconav.types import Pose2D

sys.path.insert(0, str(Path(__file__).parents[1] / "memory"))
from synth import chair, detect, render  # noqa: E402


def test_the_memory_makes_requested_frames_anchors_spaced_and_only_until_the_request_ends():
    node = MemoryNode(OccupancyGrid(), CognitiveMemoryGraph(MemoryConfig(), embedder=HashingEmbedder()))
    boxes = [chair(3.0, 0.0)]
    pose = Pose2D(0.0, 0.0, math.radians(10))  # glancing from one spot: no reason of eq. 2 after the first
    made = []
    for k in range(12):
        now = 0.25 * k
        if k == 1:
            node.receive(KeyframeRequest(until=2.0, every_s=0.5, stamp=now), now)
        frame = render(pose, boxes, stamp=now, seq=k)
        node.receive(Observation(frame, tuple(detect(frame, boxes)), now, "test"), now)
        node.run_tick(now)
        node.drain()
        made.append(len(node.cmg.snapshot().anchors))
    # the first frame (eq. 2's "first"), then one every 0.5 s from the request to its end (2.0 s)
    assert made == [1, 2, 2, 3, 3, 4, 4, 5, 5, 5, 5, 5]


def test_keyframe_requests_go_to_the_memory():
    assert _ROUTES[KeyframeRequest] == "memory"
