"""PerceptionActor: runs the detector on the newest frame (latest-wins) and sends Observations.

Owns one ``hiconav.perception`` Detector. Frames that arrive faster than the perception rate are
dropped and counted, never queued. It does not map or remember anything.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor

from hiconav.messages import FrameMsg, Observation


class PerceptionActor(NodeActor):
    """pykka actor of the perception layer."""


class PerceptionNode(Node):
    name = "perception"
    event_driven = True  # per-frame chain: see Node.event_driven
    actor_class = PerceptionActor

    def __init__(self, detector: Any, *, rate_hz: float = 10.0,
                 vocabulary: Callable[[], Sequence[str]] | None = None, to: tuple[str, ...] = ("memory", "recorder")) -> None:
        super().__init__(rate_hz)
        self.detector = detector
        self.vocabulary = vocabulary or (lambda: ())
        self.to = to
        self.detector_name = str(getattr(detector, "name", type(detector).__name__))
        self.latest_wins(FrameMsg)

    def tick(self, now: float) -> None:
        msg = self.take(FrameMsg)
        if msg is None:
            return
        detections = tuple(self.detector.detect(msg.frame, tuple(self.vocabulary())))
        self.emit(self.to, Observation(msg.frame, detections, now, self.detector_name))
