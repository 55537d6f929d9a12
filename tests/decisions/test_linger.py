"""decisions.linger: which undecided instance of the target's category to turn beside."""

from __future__ import annotations

import numpy as np
import pytest

from hiconav.decisions import linger

from .fakes import Node


def node(oid: int, label: str, x: float, y: float, half: float = 0.3) -> Node:
    return Node(oid, label, np.array([x - half, y - half, 0.0]), np.array([x + half, y + half, 0.9]))


ROBOT = np.array([0.0, 0.0])


def test_the_nearest_instance_of_the_category_within_reach_is_lingered_by():
    nodes = [node(1, "chair", 2.0, 0.0), node(2, "Chair", 1.0, 0.0), node(3, "fridge", 0.5, 0.0)]
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 1.5, (), ()) == 2
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 0.5, (), ()) is None  # 0.7 m: too far
    assert linger.undecided_near(nodes, ["sofa"], ROBOT, 1.5, (), ()) is None


def test_an_instance_ruled_out_lingered_by_or_excluded_is_passed_over():
    nodes = [node(1, "chair", 1.0, 0.0), node(2, "chair", 1.5, 0.0)]
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 1.5, {1}, ()) == 2
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 1.5, (), {1}) == 2
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 1.5, (), (), excluded=lambda i: i == 1) == 2
    assert linger.undecided_near(nodes, ["chair"], ROBOT, 1.5, {1}, {2}) is None


def test_an_instance_told_by_what_hangs_above_it_is_looked_up_at_first_facing_it():
    import math

    from hiconav.types import Pose2D

    assert linger.told_by_what_is_above([("bed", "below", "painting")], ["bed"])
    assert linger.told_by_what_is_above([("Bed", "under", "painting")], ["bed"])
    assert not linger.told_by_what_is_above([("bed", "next to", "painting")], ["bed"])
    assert not linger.told_by_what_is_above([("painting", "above", "bed")], ["bed"])  # not the target's
    goal = linger.look_up_goal(Pose2D(0.0, 0.0, 0.0), node(1, "bed", 0.0, 1.0), math.radians(30))
    assert goal.kind == "look" and goal.yaw == pytest.approx(math.pi / 2) and goal.tilt == pytest.approx(math.radians(30))
    assert (goal.x, goal.y) == (0.0, 0.0)
