"""The last resort of an explored-out search (hiconav.decisions.last_resort) and its rings."""

from __future__ import annotations

from typing import NamedTuple

import pytest

from hiconav.decisions import approach as plan
from hiconav.decisions import last_resort
from hiconav.decisions.config import ApproachSettings



class Node(NamedTuple):
    id: int
    confidence: float
    n_obs: int


def obj(oid: int, label: str, x: float, y: float, n_obs: int, conf: float) -> Node:
    return Node(oid, conf, n_obs)


def test_the_last_resort_is_a_node_set_aside_as_out_of_reach_the_reasonings_first_then_the_best_seen():
    nodes = [obj(1, "bed", 0, 0, n_obs=2, conf=0.9), obj(2, "bed", 3, 0, n_obs=9, conf=0.5),
             obj(3, "bed", 6, 0, n_obs=30, conf=0.9)]
    reach = {1: "no reachable view point", 2: "approach: no reachable approach cell"}
    assert last_resort.pick(nodes, reach, set()).id == 2  # 0.5 x 9 beats 0.9 x 2; 3 was judged, not stranded
    assert last_resort.pick(nodes, reach, {1}).id == 1  # the reasoning layer's candidate first
    assert last_resort.pick(nodes, {}, {1}) is None
    assert last_resort.pick(nodes[:1], {7: "no reachable view point"}, set()) is None  # gone from memory


def test_a_last_resorts_rings_go_on_past_the_usual_ones_out_to_last_resort_m():
    s = ApproachSettings(distance=0.85, last_resort_m=3.0)
    assert plan.rings(s) == pytest.approx([0.85, 1.0, 1.25, 1.5])
    assert plan.rings(s, wide=True) == pytest.approx([0.85, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0])
    wide = plan.ring_order(s, wide=True)
    assert [t.ring for t in wide if t.strict][-1] == pytest.approx(3.0)
    assert all(t.box_weight == s.settle_box_weight for t in wide if t.ring > 1.5)  # nearest the object
    assert plan.rings(ApproachSettings(last_resort_m=0.0), wide=True) == plan.rings(ApproachSettings())
