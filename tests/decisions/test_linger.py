"""decisions.linger: which undecided instance of the target's category to turn beside."""

from __future__ import annotations

import numpy as np

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
