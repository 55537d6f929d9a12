"""A robot's invalid frame is dropped and counted by the driver actor, never ending the mission."""

from __future__ import annotations

from types import SimpleNamespace

from hiconav.actors.driver import DriverNode
from hiconav.errors import FrameError
from hiconav.messages import CommandMsg, FrameMsg
from hiconav.types import DiscreteAction, Pose2D


class _Robot:
    """Its first ``bad`` frames are invalid (a NaN pose from the autopilot, say)."""

    def __init__(self, bad: int) -> None:
        self.bad = bad
        self.steps = 0
        self.pose = Pose2D(0.0, 0.0, 0.0)

    def _frame(self):
        if self.bad > 0:
            self.bad -= 1
            raise FrameError("base pose is not finite", field="frame.base_pose")
        return SimpleNamespace(stamp=float(self.steps))

    def reset(self, start):
        return self._frame()

    def observe(self):
        return self._frame()

    def step(self, action):
        self.steps += 1
        return self._frame()


def _frames(node: DriverNode) -> list:
    return [o for o in node.drain() if isinstance(o.msg, FrameMsg)]


def test_bad_frames_are_dropped_counted_and_observed_again_in_lockstep():
    node = DriverNode(_Robot(bad=2), Pose2D(0, 0, 0), lockstep=True)
    node.start(0.0)  # the reset's frame is bad
    assert node.stats.dropped["bad_frame"] == 1
    node.run_tick(0.1)  # observed again: bad again
    assert _frames(node) == [] and node.stats.dropped["bad_frame"] == 2
    node.run_tick(0.2)  # observed again: a good frame goes out
    assert len(_frames(node)) == 1 and node.stats.dropped["bad_frame"] == 2
    assert node.ended is None and "not finite" in node.last_bad_frame


def test_a_bad_frame_after_a_step_is_dropped_and_the_next_tick_observes():
    robot = _Robot(bad=0)
    node = DriverNode(robot, Pose2D(0, 0, 0), lockstep=True)
    node.start(0.0)
    node.run_tick(0.1)
    assert len(_frames(node)) == 1
    robot.bad = 1
    node.receive(CommandMsg(1, 0.2, action=DiscreteAction.MOVE_FORWARD), 0.2)
    node.run_tick(0.2)
    assert _frames(node) == [] and node.stats.dropped["bad_frame"] == 1 and robot.steps == 1
    node.run_tick(0.3)
    assert len(_frames(node)) == 1 and node.ended is None
