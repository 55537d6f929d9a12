"""Failsafe logic (pure): geofence, link/heartbeat/pose/mode checks, latching, motion gate, Ctrl-C hook."""

from __future__ import annotations

import math
import signal

import pytest
from hiconav.drivers.base import FailsafeState
from hiconav.drivers.failsafe import FailsafeMonitor, Geofence, install_stop_handlers
from hiconav.drivers.profiles import FailsafeProfile

from hiconav.types import Pose2D

P0 = Pose2D(0.0, 0.0, 0.0)


def healthy(now: float, **kw):
    args = {"last_message": now - 0.1, "last_heartbeat": now - 0.5, "pose_stamp": now - 0.05, "pose": P0,
            "engaged": True}
    args.update(kw)
    return args


def test_box_and_polygon_geofence():
    box = Geofence.box((-1, -1), (1, 1))
    assert box.contains(0, 0) and box.contains(0.99, -0.99)
    assert not box.contains(1.01, 0) and not box.contains(float("nan"), 0)
    l_shape = Geofence([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]])
    assert l_shape.contains(0.5, 1.5) and l_shape.contains(1.5, 0.5)
    assert not l_shape.contains(1.5, 1.5)


def test_geofence_margin_shrinks_region():
    fence = Geofence.box((-1, -1), (1, 1), margin=0.3)
    assert fence.contains(0.6, 0.0)
    assert not fence.contains(0.8, 0.0)
    assert fence.distance_to_boundary(0.8, 0.0) == pytest.approx(0.2)


def test_healthy_is_ok():
    m = FailsafeMonitor(FailsafeProfile())
    s = m.evaluate(10.0, **healthy(10.0))
    assert s.ok and s.state == FailsafeState.OK and s.link_ok


def test_link_loss_latches_and_pauses_until_resume():
    m = FailsafeMonitor(FailsafeProfile(link_timeout_s=0.5))
    s = m.evaluate(10.0, **healthy(10.0, last_message=9.4))
    assert s.state == FailsafeState.LINK_LOST and s.paused and not s.link_ok
    # messages flow again: still paused (latched)
    s = m.evaluate(11.0, **healthy(11.0))
    assert s.paused and s.state == FailsafeState.LINK_LOST and s.link_ok
    ok, _ = m.resume(11.0, **healthy(11.0))
    assert ok and m.evaluate(11.0, **healthy(11.0)).ok


def test_link_loss_may_auto_recover_when_configured():
    m = FailsafeMonitor(FailsafeProfile(resume_on_link_recovery=True))
    assert not m.evaluate(10.0, **healthy(10.0, last_message=9.0)).ok
    assert m.evaluate(11.0, **healthy(11.0)).ok


def test_never_connected_is_not_latched():
    m = FailsafeMonitor(FailsafeProfile())
    s = m.evaluate(1.0, last_message=None, last_heartbeat=None, pose_stamp=None, pose=None, engaged=None)
    assert not s.ok and not s.paused
    assert m.evaluate(2.0, **healthy(2.0)).ok


def test_pose_before_the_first_heartbeat_is_not_a_heartbeat_loss():
    # a vehicle named in the profile is heard (poses) before its first HEARTBEAT arrives
    m = FailsafeMonitor(FailsafeProfile())
    s = m.evaluate(1.0, **healthy(1.0, last_heartbeat=None, engaged=None))
    assert s.state == FailsafeState.HEARTBEAT_LOST and not s.paused
    assert m.evaluate(2.0, **healthy(2.0)).ok


def test_a_rejected_pose_jump_latches_until_jumps_stop():
    m = FailsafeMonitor(FailsafeProfile(pose_timeout_s=0.5))
    jump = (10.0, "a reported position 1414.21 m from the last one was rejected")
    s = m.evaluate(10.0, **healthy(10.0, pose_jump=jump))
    assert s.state == FailsafeState.POSE_JUMP and s.paused and "1414" in s.reason
    assert m.gate(s, P0, 0.3, 0.0)[:2] == (0.0, 0.0)
    ok, why = m.resume(10.2, **healthy(10.2, pose_jump=jump))
    assert not ok and "rejected" in why
    assert m.resume(10.6, **healthy(10.6, pose_jump=jump))[0]
    assert m.evaluate(10.6, **healthy(10.6, pose_jump=jump)).ok


def test_next_deadline_is_the_earliest_timeout_still_ahead():
    m = FailsafeMonitor(FailsafeProfile(link_timeout_s=0.4, heartbeat_timeout_s=3.0, pose_timeout_s=0.5))
    assert m.next_deadline(10.0, last_message=9.9, last_heartbeat=9.5, pose_stamp=9.95) == pytest.approx(10.3)
    assert m.next_deadline(10.5, last_message=9.9, last_heartbeat=9.5, pose_stamp=9.95) == pytest.approx(12.5)
    assert m.next_deadline(1.0, last_message=None, last_heartbeat=None, pose_stamp=None) is None


def test_heartbeat_loss_latches():
    m = FailsafeMonitor(FailsafeProfile(heartbeat_timeout_s=3.0))
    s = m.evaluate(10.0, **healthy(10.0, last_heartbeat=6.0))
    assert s.state == FailsafeState.HEARTBEAT_LOST and s.paused


def test_stale_pose_stops_but_does_not_latch():
    m = FailsafeMonitor(FailsafeProfile(pose_timeout_s=0.5))
    s = m.evaluate(10.0, **healthy(10.0, pose_stamp=9.0))
    assert s.state == FailsafeState.POSE_STALE and not s.paused and not s.ok
    assert m.gate(s, P0, 0.5, 0.3)[:2] == (0.0, 0.0)
    assert m.evaluate(10.1, **healthy(10.1)).ok


def test_mode_loss_latches():
    m = FailsafeMonitor(FailsafeProfile())
    s = m.evaluate(10.0, **healthy(10.0, engaged=False))
    assert s.state == FailsafeState.MODE_LOST and s.paused
    ok, why = m.resume(10.0, **healthy(10.0, engaged=False))
    assert not ok and "guided" in why


def test_geofence_breach_latches_and_resume_needs_inside():
    m = FailsafeMonitor(FailsafeProfile(), Geofence.box((-1, -1), (1, 1)))
    out = Pose2D(1.5, 0.0, 0.0)
    s = m.evaluate(10.0, **healthy(10.0, pose=out))
    assert s.state == FailsafeState.GEOFENCE and s.paused
    assert m.gate(s, out, 0.5, 0.0)[:2] == (0.0, 0.0)
    ok, why = m.resume(10.0, **healthy(10.0, pose=out))
    assert not ok and "geofence" in why
    assert m.resume(10.0, **healthy(10.0))[0]


def test_gate_cuts_motion_toward_the_fence_but_allows_turning():
    m = FailsafeMonitor(FailsafeProfile(geofence_lookahead_s=1.0), Geofence.box((-1, -1), (1, 1)))
    near = Pose2D(0.7, 0.0, 0.0)
    s = m.evaluate(10.0, **healthy(10.0, pose=near))
    v, w, why = m.gate(s, near, 0.5, 0.4)
    assert (v, w) == (0.0, 0.4) and "geofence" in why
    away = Pose2D(0.7, 0.0, math.pi)
    assert m.gate(s, away, 0.5, 0.0)[:2] == (0.5, 0.0)


def test_sigint_hook_stops_then_raises_keyboard_interrupt():
    calls = []
    uninstall = install_stop_handlers(lambda: calls.append("stop"))
    try:
        with pytest.raises(KeyboardInterrupt):
            # raise_signal delivers to this (the main) thread and runs the Python handler before
            # it returns; os.kill(getpid()) may run it later, on a loaded machine outside this block
            signal.raise_signal(signal.SIGINT)
        assert calls == ["stop"]
    finally:
        uninstall()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
