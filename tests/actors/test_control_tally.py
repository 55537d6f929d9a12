"""The control layer tallies its discrete actions by the behaviour whose goal they served."""

from __future__ import annotations

from hiconav.actors.control import ControlNode
from hiconav.messages import GoalMsg, WorldSnapshot
from hiconav.types import DiscreteAction, Goal, Pose2D


class _ScriptedNav:
    """A navigator that answers each step with the next scripted action."""

    reached = False

    def __init__(self, actions: list[DiscreteAction]) -> None:
        self.actions = list(actions)

    def set_goal(self, goal) -> None:
        pass

    def step(self, grid, pose):
        return self.actions.pop(0)


def _act(node: ControlNode, seq: int, t: float) -> None:
    node.receive(WorldSnapshot(seq, t, Pose2D(0.0, 0.0, 0.0), None, None), t)
    node.run_tick(t)


def test_actions_are_tallied_under_the_source_of_the_goal_they_served():
    L, R, F = DiscreteAction.TURN_LEFT, DiscreteAction.TURN_RIGHT, DiscreteAction.MOVE_FORWARD
    node = ControlNode(_ScriptedNav([L, F, F, R, R, DiscreteAction.LOOK_UP, F]))
    node.receive(GoalMsg(1, Goal(3.0, 0.0), 0.0, "Explore"), 0.0)
    for i in range(3):
        _act(node, i, 0.1 * i)
    node.receive(GoalMsg(2, Goal(1.0, 1.0, kind="look"), 0.3, "VerifyTarget"), 0.3)
    for i in range(3, 6):
        _act(node, i, 0.1 * i)
    node.receive(GoalMsg(3, Goal(2.0, 2.0), 0.6), 0.6)  # a sender that does not say who it is
    _act(node, 6, 0.6)
    assert node.actions == {"Explore": {"turns": 1, "forward": 2, "other": 0},
                            "VerifyTarget": {"turns": 2, "forward": 0, "other": 1},
                            "unnamed": {"turns": 0, "forward": 1, "other": 0}}


def test_a_stop_for_want_of_a_path_is_no_action():
    node = ControlNode(_ScriptedNav([DiscreteAction.STOP]))
    node.receive(GoalMsg(1, Goal(3.0, 0.0), 0.0, "Explore"), 0.0)
    _act(node, 0, 0.0)
    assert node.actions == {} and node.state == "failed"
