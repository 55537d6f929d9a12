"""Modelled reasoning latency on the stepped clock, and the blocking (sync_reasoning) ablation."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from hiconav.actors.control import ControlNode
from hiconav.actors.reasoning import ReasoningNode
from hiconav.messages import GoalMsg, ReasoningBusy, WorldSnapshot
from hiconav.mission import LatencyModel
from hiconav.types import DiscreteAction, Goal, Pose2D


def test_the_latency_model_is_seeded_and_stays_within_its_jitter():
    a, b = LatencyModel(2.0, 0.5, seed=3), LatencyModel(2.0, 0.5, seed=3)
    draws = [float(a) for _ in range(200)]
    assert draws == [float(b) for _ in range(200)]
    assert min(draws) >= 1.5 and max(draws) <= 2.5 and np.std(draws) > 0.1
    assert float(LatencyModel(2.0, 0.0, seed=3)) == 2.0
    assert float(LatencyModel(0.0, 0.5, seed=3)) == 0.0  # no negative latency


def test_a_parse_takes_the_modelled_latency_and_tells_control_when_sync():
    node = ReasoningNode(parse=lambda text: SimpleNamespace(targets=("bed",), related=()), make_reasoner=None,
                         stepped=True, parse_latency_s=LatencyModel(2.0, 0.0, 0), sync=True)
    from hiconav.messages import ParseRequest

    node.receive(ParseRequest("find the bed", 0.0), 0.0)
    node.run_tick(0.0)
    out = node.drain()
    task = [o for o in out if o.msg.__class__.__name__ == "TaskMsg"]
    busy = [o for o in out if isinstance(o.msg, ReasoningBusy)]
    assert task and all(o.delay == 2.0 for o in task)
    assert busy and busy[0].dest == "control" and busy[0].msg.until == 2.0
    assert node.busy_until == 2.0


class _Nav:
    reached = False

    def __init__(self) -> None:
        self.steps = 0

    def set_goal(self, goal) -> None:
        pass

    def step(self, grid, pose):
        self.steps += 1
        return DiscreteAction.MOVE_FORWARD


def _control(hold: bool) -> tuple[ControlNode, _Nav]:
    nav = _Nav()
    node = ControlNode(nav, hold_while_reasoning=hold)
    node.receive(GoalMsg(1, Goal(3.0, 0.0), 0.0), 0.0)
    node.receive(WorldSnapshot(0, 0.0, Pose2D(0.0, 0.0, 0.0), None, None), 0.0)
    node.receive(ReasoningBusy(2.0, 0.0), 0.0)
    return node, nav


def test_sync_control_holds_the_robot_until_the_reply_then_moves():
    node, nav = _control(hold=True)
    node.run_tick(1.0)
    assert nav.steps == 0 and node.held_ticks == 1
    node.run_tick(2.0)
    assert nav.steps == 1


def test_asynchronous_control_moves_while_reasoning_thinks():
    node, nav = _control(hold=False)
    node.run_tick(1.0)
    assert nav.steps == 1


def test_the_latency_model_is_in_robot_time_on_the_stepped_clock():
    """A discrete action takes a robot ACTION_SECONDS (0.5 s); the stepped clock gives it one
    driver tick (0.1 s at 10 Hz), so 2 s of reasoning lasts 0.4 clock seconds: four actions, as
    on a real robot, not twenty."""
    from types import SimpleNamespace

    from hiconav.mission import stepped_time_scale
    from hiconav.sim.simulator import ACTION_SECONDS

    rates = SimpleNamespace(driver=10.0, control=10.0)
    assert stepped_time_scale(rates, "discrete") == 0.1 / ACTION_SECONDS == 0.2
    assert stepped_time_scale(rates, "velocity") == 1.0  # a 0.1 s tick moves the robot for 0.1 s
    assert stepped_time_scale(SimpleNamespace(driver=2.0, control=10.0), "discrete") == 1.0
    assert float(LatencyModel(2.0, 0.0, seed=3, scale=0.2)) == 2.0 * 0.2
    a, b = LatencyModel(2.0, 0.5, seed=3), LatencyModel(2.0, 0.5, seed=3, scale=0.2)
    assert all(abs(float(a) * 0.2 - float(b)) < 1e-12 for _ in range(5))  # same draws, scaled
