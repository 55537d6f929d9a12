"""Recording and replaying frames: folder format, step and realtime playback, errors."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hiconav.drivers import open_driver
from hiconav.drivers.base import Driver
from hiconav.drivers.replay_driver import FrameRecorder, ReplayDriver, ReplayFrameSource, read_index

from hiconav.errors import DataError
from hiconav.types import (
    CameraIntrinsics,
    DiscreteAction,
    Frame,
    Pose2D,
    VelocityCommand,
    camera_pose_from_base,
)

K = CameraIntrinsics.from_hfov(32, 24, 79.0)


def make_frame(i: int, stamp: float) -> Frame:
    pose = Pose2D(0.25 * i, 0.0, 0.1 * i)
    rgb = np.full((24, 32, 3), i, dtype=np.uint8)
    depth = np.full((24, 32), 1.0 + i, dtype=np.float32)
    inst = np.full((24, 32), i, dtype=np.int32)
    return Frame(rgb, depth, K, camera_pose_from_base(pose, 0.88), pose, stamp, inst, seq=i)


@pytest.fixture
def recording(tmp_path):
    folder = tmp_path / "run"
    with FrameRecorder(folder) as rec:
        for i in range(5):
            rec.write(make_frame(i, 100.0 + 0.5 * i))
    return folder


def test_round_trip_keeps_arrays_pose_and_intrinsics(recording):
    entries = read_index(recording)
    assert len(entries) == 5 and entries[2]["file"] == "frame_000002.npz"
    drv = ReplayDriver(recording)
    assert isinstance(drv, Driver)
    f = drv.latest_frame()
    ref = make_frame(0, 100.0)
    assert np.array_equal(f.rgb, ref.rgb) and np.array_equal(f.depth, ref.depth)
    assert np.array_equal(f.instances, ref.instances) and np.allclose(f.T_world_cam, ref.T_world_cam)
    assert f.intrinsics == K and f.base_pose == ref.base_pose and f.stamp == 100.0
    assert not f.rgb.flags.writeable


def test_step_mode_advances_per_command_and_pauses_at_end(recording):
    drv = ReplayDriver(recording)
    seen = [drv.latest_frame().seq]
    for cmd in [DiscreteAction.MOVE_FORWARD, VelocityCommand(0.1, 0.0), DiscreteAction.TURN_LEFT,
                DiscreteAction.MOVE_FORWARD]:
        drv.send(cmd)
        seen.append(drv.latest_frame().seq)
    assert seen == [0, 1, 2, 3, 4]
    assert drv.health().ok
    drv.send(DiscreteAction.STOP)
    h = drv.health()
    assert h.paused and h.reason == "end of recording"
    assert len(drv.commands) == 5


def test_realtime_mode_follows_recorded_stamps(recording):
    now = [0.0]
    drv = ReplayDriver(recording, mode="realtime", clock=lambda: now[0])
    assert drv.latest_frame().seq == 0
    now[0] = 1.1  # 0.5 s per frame
    assert drv.latest_frame().seq == 2
    now[0] = 10.0
    assert drv.latest_frame().seq == 4 and drv.health().paused


def test_frame_source_serves_nearest_recorded_pose(recording):
    src = ReplayFrameSource(recording)
    f = src.frame_at(Pose2D(0.74, 0.0, 0.3), stamp=7.0)
    assert f.seq == 3 and f.stamp == 7.0


def test_registry_builds_replay_driver(recording):
    drv = open_driver("replay", folder=str(recording))
    assert isinstance(drv, ReplayDriver) and len(drv) == 5


def test_bad_recordings_are_reported(tmp_path, recording):
    with pytest.raises(DataError, match="no index.json"):
        read_index(tmp_path)
    index = recording / "index.json"
    data = json.loads(index.read_text())
    del data["frames"][1]["pose"]
    index.write_text(json.dumps(data))
    with pytest.raises(DataError) as err:
        read_index(recording)
    assert err.value.field == "frames[1].pose"
    index.write_text("{not json")
    with pytest.raises(DataError, match="not valid JSON"):
        read_index(recording)
