"""PerceptionActor: runs the detector on the newest frame (latest-wins) and sends Observations.

Owns one ``hiconav.perception`` Detector. Frames that arrive faster than the perception rate are
dropped and counted, never queued. It does not map or remember anything.

A frame the detector refuses (``FrameError``, e.g. the oracle without an instance channel) is
dropped and counted (``stats.dropped["bad_frame"]``, in the mission result's ``dropped``; the
last reason in ``last_drop``): it goes no further and the mission goes on with the next frame.
Frames are checked where they are made (``hiconav.types.Frame``), so a wrong-shaped image or a
non-finite pose never gets this far.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from typing import Any

from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor
from hiconav.errors import FrameError
from hiconav.messages import FrameMsg, Observation

log = logging.getLogger(__name__)


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
        self.last_drop: str | None = None  # why the newest dropped frame was refused
        self.latest_wins(FrameMsg)

    def tick(self, now: float) -> None:
        msg = self.take(FrameMsg)
        if msg is None:
            return
        try:
            detections = tuple(self.detector.detect(msg.frame, tuple(self.vocabulary())))
        except FrameError as exc:
            n = self.stats.dropped.get("bad_frame", 0) + 1
            self.stats.dropped["bad_frame"] = n
            self.last_drop = str(exc)
            if n == 1 or n % 100 == 0:  # a sensor that stays broken must not flood the log
                log.warning("perception: frame %s dropped (bad_frame #%d): %s", getattr(msg.frame, "seq", "?"), n, exc)
            return
        self.emit(self.to, Observation(msg.frame, detections, now, self.detector_name))
