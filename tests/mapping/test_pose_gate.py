"""hiconav.mapping.PoseGate: a base pose may not jump farther than the robot can move."""

from __future__ import annotations

import numpy as np
import pytest

from hiconav.errors import FrameError
from hiconav.mapping import PoseGate, PoseGateConfig, PoseJumpError
from hiconav.settings import effective_settings
from hiconav.types import CameraIntrinsics, Frame, Pose2D, camera_pose_from_base

K = CameraIntrinsics.from_hfov(8, 6, 79.0)


def frame_at(x: float, y: float, stamp: float) -> Frame:
    pose = Pose2D(x, y, 0.0)
    return Frame(np.zeros((6, 8, 3), np.uint8), np.ones((6, 8), np.float32), K,
                 camera_pose_from_base(pose, 0.88), pose, stamp)


def test_defaults_are_a_settings_section():
    assert effective_settings()["mapping"]["pose_gate"] == {"max_speed_mps": 2.0, "margin_m": 1.0}


def test_the_first_frame_is_accepted_wherever_it_is():
    PoseGate().check(frame_at(1e6, -1e6, 0.0))


def test_a_simulator_walk_is_never_refused():
    """0.25 m forward steps every 0.5 s (the simulator's discrete actions, 0.5 m/s)."""
    gate = PoseGate()
    for i in range(200):
        f = frame_at(0.25 * i, 0.0, 0.5 * i)
        gate.check(f)
        gate.accept(f)
    assert gate.n_rejected == 0


def test_a_jump_beyond_speed_times_elapsed_plus_margin_is_refused_and_counted():
    gate = PoseGate(PoseGateConfig(max_speed_mps=2.0, margin_m=1.0))
    gate.accept(frame_at(0.0, 0.0, 10.0))
    gate.check(frame_at(2.9, 0.0, 11.0))  # 2 m/s x 1 s + 1 m = 3 m allowed
    with pytest.raises(PoseJumpError, match="max_speed_mps") as e:
        gate.check(frame_at(3.1, 0.0, 11.0))
    assert isinstance(e.value, FrameError) and e.value.field == "frame.base_pose"
    assert gate.n_rejected == 1


def test_a_huge_jump_is_refused():
    gate = PoseGate()
    gate.accept(frame_at(0.0, 0.0, 0.0))
    with pytest.raises(PoseJumpError):
        gate.check(frame_at(1e6, 0.0, 0.5))


def test_a_refused_frame_does_not_move_the_reference():
    gate = PoseGate(PoseGateConfig(max_speed_mps=1.0, margin_m=0.0))
    gate.accept(frame_at(0.0, 0.0, 0.0))
    with pytest.raises(PoseJumpError):
        gate.check(frame_at(5.0, 0.0, 1.0))
    assert gate.last == (0.0, 0.0, 0.0)


def test_a_move_refused_now_is_accepted_once_the_robot_could_have_made_it():
    gate = PoseGate(PoseGateConfig(max_speed_mps=1.0, margin_m=0.0))
    gate.accept(frame_at(0.0, 0.0, 0.0))
    with pytest.raises(PoseJumpError):
        gate.check(frame_at(5.0, 0.0, 1.0))
    gate.check(frame_at(5.0, 0.0, 6.0))


def test_a_stamp_that_goes_back_allows_the_margin_only():
    gate = PoseGate(PoseGateConfig(max_speed_mps=1.0, margin_m=0.5))
    gate.accept(frame_at(0.0, 0.0, 10.0))
    gate.check(frame_at(0.4, 0.0, 5.0))
    with pytest.raises(PoseJumpError):
        gate.check(frame_at(0.6, 0.0, 5.0))
