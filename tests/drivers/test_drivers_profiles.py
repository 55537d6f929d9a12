"""Robot profiles: shipped ones load; bad ones fail with file, line and field."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hiconav.drivers.profiles import RobotProfile, available_profiles, load_profile, profile_from_dict

from hiconav.errors import ConfigError
from hiconav.types import Pose2D


def test_shipped_profiles_load():
    names = available_profiles()
    assert {"sim_habitat", "sim_vehicle", "ardupilot_rover", "px4_rover"} <= set(names)
    for name in names:
        p = load_profile(name)
        assert p.name == name
        assert p.rates.setpoint_hz >= 10
        k = p.camera.intrinsics()
        assert k.width > 0 and k.fx > 0


def test_guided_mode_follows_autopilot():
    assert load_profile("px4_rover").mavlink.guided_mode == "OFFBOARD"
    assert load_profile("ardupilot_rover").mavlink.guided_mode == "GUIDED"


def test_sim_profile_matches_habitat_camera():
    k = load_profile("sim_habitat").camera.intrinsics()
    assert math.degrees(k.hfov) == pytest.approx(79.0)
    assert (k.width, k.height) == (640, 480)


def test_error_names_file_line_and_field(tmp_path):
    path = tmp_path / "robot.yaml"
    path.write_text("name: r\ndriver: mavlink\nlimits:\n  max_linear: -1.0\n  max_angular: 1.0\n")
    with pytest.raises(ConfigError) as err:
        load_profile(path)
    e = err.value
    assert e.file == str(path) and e.line == 4 and e.field == "limits.max_linear"
    assert "greater than 0" in str(e) and f"{path}:4" in str(e)


def test_unknown_key_is_rejected_with_its_line(tmp_path):
    path = tmp_path / "robot.yaml"
    path.write_text("name: r\ncamera:\n  width: 640\n  hfvo_deg: 70\n")
    with pytest.raises(ConfigError) as err:
        load_profile(path)
    assert err.value.field == "camera.hfvo_deg" and err.value.line == 4
    assert "Extra inputs are not permitted" in str(err.value)


def test_setpoint_rate_below_10hz_is_rejected():
    with pytest.raises(ConfigError, match="rates.setpoint_hz"):
        profile_from_dict({"name": "r", "rates": {"setpoint_hz": 5}})


@pytest.mark.parametrize("fence", [
    {"kind": "box", "xy_min": [0, 0]},
    {"kind": "box", "xy_min": [1, 0], "xy_max": [0, 1]},
    {"kind": "polygon", "polygon": [[0, 0], [1, 0]]},
])
def test_bad_geofence_is_rejected(fence):
    with pytest.raises(ConfigError, match="geofence"):
        profile_from_dict({"name": "r", "geofence": fence})


def test_partial_intrinsics_rejected():
    with pytest.raises(ConfigError, match="fx, fy, cx, cy"):
        profile_from_dict({"name": "r", "camera": {"fx": 500.0}})


def test_several_errors_are_all_listed(tmp_path):
    path = tmp_path / "robot.yaml"
    path.write_text("name: r\nfootprint: {radius: 0}\nmavlink: {autopilot: inav}\n")
    with pytest.raises(ConfigError) as err:
        load_profile(path)
    text = str(err.value)
    assert "2 errors" in text and "footprint.radius" in text and "mavlink.autopilot" in text
    assert f"{path}:2" in text and f"{path}:3" in text


def test_invalid_yaml_and_unknown_name(tmp_path):
    path = tmp_path / "robot.yaml"
    path.write_text("name: r\nlimits: [1, 2\n")
    with pytest.raises(ConfigError, match="not valid YAML") as err:
        load_profile(path)
    assert err.value.line is not None
    with pytest.raises(ConfigError, match="ardupilot_rover"):
        load_profile("no_such_robot")


def test_camera_extrinsics_offset_and_tilt():
    p = profile_from_dict({"name": "r", "camera": {"extrinsics": {"height": 0.5, "forward": 0.2, "left": 0.1,
                                                                  "tilt_deg": 10}}})
    T = p.camera.T_world_cam(Pose2D(1.0, 2.0, math.pi / 2))
    # facing +y: forward offset goes to +y, left offset to -x
    assert T[:3, 3] == pytest.approx([0.9, 2.2, 0.5])
    z_cam = T[:3, 2]
    assert z_cam[1] > 0.9 and z_cam[2] == pytest.approx(math.sin(math.radians(10)))
    assert np.allclose(T[:3, :3].T @ T[:3, :3], np.eye(3))


def test_with_updates_revalidates():
    p = RobotProfile(name="r")
    q = p.with_updates(mavlink={"url": "udpin:127.0.0.1:14551"})
    assert q.mavlink.url.endswith("14551") and p.mavlink.url.endswith("14550")
    with pytest.raises(ConfigError):
        p.with_updates(limits={"max_linear": 0})
