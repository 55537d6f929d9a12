"""hiconav.types Frame / CameraIntrinsics: sensor input is checked where it enters, with a
FrameError naming the field; a valid frame is taken as it is."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hiconav.errors import FrameError
from hiconav.types import CameraIntrinsics, Frame, Pose2D, camera_pose_from_base

K = CameraIntrinsics.from_hfov(8, 6, 79.0)
POSE = Pose2D(1.0, -2.0, 0.5)


def frame(**kw) -> Frame:
    args = dict(rgb=np.zeros((6, 8, 3), np.uint8), depth=np.ones((6, 8), np.float32), intrinsics=K,
                T_world_cam=camera_pose_from_base(POSE, 0.88), base_pose=POSE, stamp=0.0)
    args.update(kw)
    return Frame(**args)


def field_of(excinfo: pytest.ExceptionInfo) -> str:
    return excinfo.value.field


def test_a_valid_frame_is_kept_as_given_and_read_only():
    rgb = np.full((6, 8, 3), 7, np.uint8)
    f = frame(rgb=rgb)
    assert f.rgb is rgb and not f.rgb.flags.writeable and not f.depth.flags.writeable


def test_nan_inf_zero_and_negative_depth_are_accepted_as_no_return():
    depth = np.array([[np.nan, np.inf, 0.0, -1.0] * 2] * 6, np.float32)
    assert frame(depth=depth).depth is depth


def test_float_rgb_in_zero_one_is_accepted():
    frame(rgb=np.full((6, 8, 3), 0.5, np.float32))


@pytest.mark.parametrize("shape", [(6, 8, 4), (6, 8), (6, 8, 1)])
def test_rgb_that_is_not_three_channels_is_refused(shape):
    with pytest.raises(FrameError, match=r"\(H, W, 3\)") as e:
        frame(rgb=np.zeros(shape, np.uint8))
    assert field_of(e) == "frame.rgb"


def test_rgb_of_another_size_than_the_depth_is_refused():
    with pytest.raises(FrameError, match="must match") as e:
        frame(rgb=np.zeros((12, 16, 3), np.uint8))
    assert field_of(e) == "frame.rgb"


@pytest.mark.parametrize("bad", [np.nan, np.inf, 255.0, -0.1])
def test_float_rgb_that_is_not_finite_in_zero_one_is_refused(bad):
    rgb = np.full((6, 8, 3), 0.5, np.float32)
    rgb[2, 3, 1] = bad
    with pytest.raises(FrameError, match=r"\[0, 1\]") as e:
        frame(rgb=rgb)
    assert field_of(e) == "frame.rgb"


def test_rgb_of_another_integer_type_is_refused():
    with pytest.raises(FrameError, match="uint8") as e:
        frame(rgb=np.zeros((6, 8, 3), np.uint16))
    assert field_of(e) == "frame.rgb"


@pytest.mark.parametrize("name,value", [("fx", 0.0), ("fx", -3.0), ("fy", math.nan), ("fx", math.inf),
                                        ("cx", math.nan), ("cy", math.inf), ("width", 0), ("height", 2.5)])
def test_bad_intrinsics_are_refused_naming_the_field(name, value):
    args = dict(width=8, height=6, fx=5.0, fy=5.0, cx=4.0, cy=3.0)
    args[name] = value
    with pytest.raises(FrameError) as e:
        CameraIntrinsics(**args)
    assert field_of(e) == f"intrinsics.{name}"


def test_a_frame_checks_intrinsics_it_did_not_build():
    class Loose:  # duck-typed intrinsics, e.g. a robot driver's own type
        width, height, fx, fy, cx, cy = 8, 6, 0.0, 5.0, 4.0, 3.0

    with pytest.raises(FrameError) as e:
        frame(intrinsics=Loose())
    assert field_of(e) == "frame.intrinsics.fx"


def test_non_finite_camera_pose_is_refused():
    T = camera_pose_from_base(POSE, 0.88)
    T[0, 3] = np.nan
    with pytest.raises(FrameError) as e:
        frame(T_world_cam=T)
    assert field_of(e) == "frame.T_world_cam"


def test_camera_pose_of_the_wrong_shape_is_refused():
    with pytest.raises(FrameError) as e:
        frame(T_world_cam=np.eye(3))
    assert field_of(e) == "frame.T_world_cam"


@pytest.mark.parametrize("name", ["x", "y", "yaw"])
def test_non_finite_base_pose_is_refused_naming_the_coordinate(name):
    values = dict(x=1.0, y=2.0, yaw=0.0)
    values[name] = math.nan
    with pytest.raises(FrameError) as e:
        frame(base_pose=Pose2D(**values))
    assert field_of(e) == f"frame.base_pose.{name}"


def test_non_finite_stamp_is_refused():
    with pytest.raises(FrameError) as e:
        frame(stamp=math.inf)
    assert field_of(e) == "frame.stamp"


def test_missing_parts_are_left_to_the_consumer_that_needs_them():
    f = frame(rgb=None, T_world_cam=None, base_pose=None)
    assert f.rgb is None and f.T_world_cam is None and f.base_pose is None
