"""Perception and memory drop a frame the core refuses, count it, and the mission goes on."""

from __future__ import annotations

import numpy as np

from hiconav.actors.memory import MemoryNode
from hiconav.actors.node import Node
from hiconav.actors.perception import PerceptionNode
from hiconav.actors.runtime import SteppedRuntime
from hiconav.errors import FrameError
from hiconav.mapping import OccupancyGrid, PoseGate, PoseGateConfig
from hiconav.messages import EpisodeEnded, FrameMsg, Observation, WorldSnapshot
from hiconav.types import CameraIntrinsics, Frame, Pose2D, camera_pose_from_base

K = CameraIntrinsics.from_hfov(16, 12, 79.0)


def frame_at(x: float, stamp: float, seq: int, *, depth_shape: tuple[int, int] = (12, 16)) -> Frame:
    pose = Pose2D(x, 0.0, 0.0)
    return Frame(np.zeros(depth_shape + (3,), np.uint8), np.full(depth_shape, np.nan, np.float32), K,
                 camera_pose_from_base(pose, 0.88), pose, stamp, seq=seq)


def observe(node: MemoryNode, frame: Frame, now: float) -> list[WorldSnapshot]:
    node.receive(Observation(frame, (), now, "test"), now)
    node.run_tick(now)
    return [o.msg for o in node.drain()]


class Refuses:
    """A detector that refuses odd frames (like the oracle without an instance channel)."""

    name = "refuses"

    def detect(self, frame, vocabulary):
        if frame.seq % 2:
            raise FrameError("no instance channel", field="frame.instances")
        return []


def test_memory_drops_and_counts_a_pose_jump_and_integrates_the_next_frame():
    node = MemoryNode(OccupancyGrid(), pose_gate=PoseGate(PoseGateConfig(max_speed_mps=2.0, margin_m=1.0)))
    assert len(observe(node, frame_at(0.0, 0.0, 1), 0.0)) == 5  # one snapshot per destination
    assert observe(node, frame_at(1e6, 0.5, 2), 0.5) == []
    assert node.stats.dropped == {"pose_jump": 1} and "max_speed_mps" in node.last_drop
    out = observe(node, frame_at(0.25, 1.0, 3), 1.0)
    assert out and out[0].frame_seq == 3 and node.grid.version == 2


def test_memory_drops_and_counts_a_frame_the_grid_refuses():
    node = MemoryNode(OccupancyGrid())
    observe(node, frame_at(0.0, 0.0, 1), 0.0)
    assert observe(node, frame_at(0.0, 0.5, 2, depth_shape=(6, 8)), 0.5) == []  # depth does not fit K
    assert node.stats.dropped == {"bad_frame": 1} and "depth" in node.last_drop
    assert node.grid.version == 1


def test_memory_drops_a_pose_past_the_grid_extent_even_when_the_gate_allows_it():
    node = MemoryNode(OccupancyGrid(), pose_gate=PoseGate(PoseGateConfig(max_speed_mps=100.0, margin_m=100.0)))
    observe(node, frame_at(0.0, 0.0, 1), 0.0)
    assert observe(node, frame_at(1000.0, 10.0, 2), 10.0) == []
    assert node.stats.dropped == {"bad_frame": 1} and "max_extent_m" in node.last_drop


def test_perception_drops_and_counts_a_frame_the_detector_refuses():
    node = PerceptionNode(Refuses())
    sent = []
    for seq in (1, 2):
        node.receive(FrameMsg(frame_at(0.0, 0.1 * seq, seq)), 0.1 * seq)
        node.run_tick(0.1 * seq)
        sent += [o.msg.frame.seq for o in node.drain()]
    assert sent == [2, 2]  # memory and recorder get frame 2 only
    assert node.stats.dropped == {"bad_frame": 1} and "instance" in node.last_drop


class ScriptedDriver(Node):
    """Sends one scripted frame per tick to perception, then ends the episode."""

    name = "driver"

    def __init__(self, frames: list[Frame]) -> None:
        super().__init__(10.0)
        self.frames = list(frames)

    def tick(self, now):
        if self.frames:
            self.emit("perception", FrameMsg(self.frames.pop(0)))
        else:
            self.emit("runtime", EpisodeEnded("stop", 0, now))


def test_bad_frames_never_end_the_mission():
    frames = [frame_at(0.0, 0.0, 2), frame_at(0.1, 0.1, 1),  # refused by the detector
              frame_at(1e6, 0.2, 4),  # a localisation jump: refused by memory
              frame_at(0.2, 0.3, 6)]
    memory = MemoryNode(OccupancyGrid())
    report = SteppedRuntime([ScriptedDriver(frames), PerceptionNode(Refuses()), memory]).run(max_time=5.0)
    assert report.reason == "episode_ended" and report.failure is None
    assert report.stats["perception"].dropped == {"bad_frame": 1}
    assert report.stats["memory"].dropped == {"pose_jump": 1}
    assert memory.grid.version == 2
