"""ExplorationPlanner: utilities -> weights -> costs -> order -> goal, hysteresis, ablations."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from _exploration_fakes import FakeGrid, make_object, similarity

sys.path.insert(0, str(Path(__file__).parents[1] / "mapping"))
from corridors import corridor_grid  # noqa: E402

from hiconav.exploration import ExplorationConfig, ExplorationPlanner
from hiconav.exploration.config import CostConfig, OrderingConfig, UtilityConfig
from hiconav.types import Frontier, Pose2D, TaskSpec

TASK = TaskSpec("find a bed", targets=("bed",), related=("nightstand",))
A = Frontier(id=7, centroid=np.array([8.5, 5.0]), viewpoint=np.array([8.0, 5.0]), size=10)
B = Frontier(id=9, centroid=np.array([1.5, 5.0]), viewpoint=np.array([2.0, 5.0]), size=10)


@dataclass
class Snapshot:
    objects: tuple = ()
    anchors: tuple = ()


def room() -> FakeGrid:
    state = np.zeros((100, 100), dtype=np.int8)
    state[0, :] = state[-1, :] = state[:, 0] = state[:, -1] = 1
    return FakeGrid(state=state, inflated=state == 1)


def planner(**ordering) -> ExplorationPlanner:
    return ExplorationPlanner(ExplorationConfig(cost=CostConfig(stride=1), ordering=OrderingConfig(**ordering)))


def plan(p: ExplorationPlanner, x: float, frontiers=(A, B), snapshot=None, grid=None):
    return p.plan(grid or room(), list(frontiers), snapshot, TASK, Pose2D(x, 5.0, 0.0), np.zeros(2), similarity,
                  now=1.0)


def test_first_plan_picks_the_nearer_of_equal_frontiers() -> None:
    p = planner()
    out = plan(p, 5.5)
    assert out.goal is not None and out.goal.id == A.id
    assert out.order == (A.id, B.id) and out.switched and out.solver == "exact"
    assert out.weights == {A.id: 1.0, B.id: 1.0}  # no memory: equal utilities -> W = 1
    g = out.goal_message()
    assert (g.x, g.y, g.kind, g.ref_id) == (8.0, 5.0, "frontier", A.id)


def test_hysteresis_keeps_the_goal_for_a_small_gain() -> None:
    p = planner(switch_margin=0.1)
    assert plan(p, 5.5).goal.id == A.id
    out = plan(p, 4.8)  # B-first is now ~6% better: within the margin
    assert out.goal.id == A.id and not out.switched and out.kept_previous
    assert out.order == (A.id, B.id)


def test_without_hysteresis_the_goal_flips() -> None:
    p = planner(switch_margin=0.0)
    assert plan(p, 5.5).goal.id == A.id
    out = plan(p, 4.8)
    assert out.goal.id == B.id and out.switched and not out.kept_previous


def test_hysteresis_switches_for_a_large_gain() -> None:
    p = planner(switch_margin=0.1)
    assert plan(p, 5.5).goal.id == A.id
    out = plan(p, 3.0)
    assert out.goal.id == B.id and out.switched


def test_switches_when_the_goal_vanishes_or_is_reached() -> None:
    p = planner(switch_margin=0.5)
    assert plan(p, 5.5).goal.id == A.id
    out = plan(p, 5.5, frontiers=(B,))
    assert out.goal.id == B.id and out.switched
    p = planner(switch_margin=10.0, reached_distance=0.5)
    assert plan(p, 5.5).goal.id == A.id
    assert plan(p, 7.8).goal.id == A.id  # near A's viewpoint, but A is still first anyway
    C = Frontier(id=11, centroid=np.array([8.0, 8.5]), viewpoint=np.array([8.0, 8.0]), size=10)
    out = plan(p, 7.8, frontiers=(A, B, C))  # reached A (0.2 m): hysteresis releases it
    assert out.kept_previous is False


def test_utility_steers_the_order() -> None:
    cfg = ExplorationConfig(cost=CostConfig(stride=1), utility=UtilityConfig(beta=5.0))
    p = ExplorationPlanner(cfg)
    snap = Snapshot(objects=(make_object("nightstand", (1.0, 5.0), (0.5, 0.5, 0.6)),))
    out = plan(p, 5.5, snapshot=snap)
    assert out.goal.id == B.id  # farther, but next to a related object
    assert out.weights[B.id] == 1.0 and out.weights[A.id] == pytest.approx(np.exp(-5.0))
    assert out.s_struct[B.id] > out.s_struct[A.id]
    # ablation: without S_struct the utilities are equal and the nearer frontier wins
    cfg2 = cfg.model_copy(update={"utility": UtilityConfig(beta=5.0, use_struct=False)})
    assert plan(ExplorationPlanner(cfg2), 5.5, snapshot=snap).goal.id == A.id


def test_ordering_ablations() -> None:
    snap = Snapshot(objects=(make_object("nightstand", (1.0, 5.0), (0.5, 0.5, 0.6)),))
    near = plan(planner(ordering="nearest"), 5.5, snapshot=snap)
    assert near.goal.id == A.id and near.solver == "nearest"
    util = plan(planner(ordering="greedy_utility"), 5.5, snapshot=snap)
    assert util.goal.id == B.id and util.solver == "greedy_utility"


def test_no_frontier_or_none_reachable() -> None:
    p = planner()
    out = plan(p, 5.5, frontiers=())
    assert out.goal is None and out.order == () and out.solver == "none"
    g = room()
    g.state[:, 40] = 1  # split the room: B's side is cut off
    g.inflated = g.state == 1
    out = plan(p, 5.5, grid=g)
    assert out.goal.id == A.id and out.dropped == (B.id,)
    assert B.id in out.weights  # weights cover every frontier of the call


def test_wtrp_order_beats_greedy_on_the_objective() -> None:
    """Many frontiers with random utilities: the WTRP order's objective is never worse than the
    greedy-utility order's (both evaluated with eq. 15 on the same matrix)."""
    rng = np.random.default_rng(0)
    fr = [Frontier(id=i, centroid=np.array(c) + 0.3, viewpoint=np.array(c), size=5)
          for i, c in enumerate(rng.uniform(1.5, 8.5, size=(9, 2)))]
    objs = tuple(make_object(lbl, tuple(rng.uniform(1, 9, 2)), (0.5, 0.5, 0.5))
                 for lbl in ("nightstand", "sofa", "lamp", "toilet"))
    costs = {}
    for mode in ("wtrp", "greedy_utility", "nearest"):
        out = plan(planner(ordering=mode), 5.0, frontiers=fr, snapshot=Snapshot(objects=objs))
        costs[mode] = out.cost
        assert sorted(out.order) == list(range(9))
    assert costs["wtrp"] <= costs["greedy_utility"] + 1e-9
    assert costs["wtrp"] <= costs["nearest"] + 1e-9
    assert costs["wtrp"] < max(costs["greedy_utility"], costs["nearest"])


def test_without_an_embedder_only_exact_target_labels_count() -> None:
    snap = Snapshot(objects=(make_object("bed", (1.0, 5.0), (2.0, 1.6, 0.6)),
                             make_object("nightstand", (8.8, 5.0), (0.5, 0.5, 0.6))))
    out = ExplorationPlanner(ExplorationConfig(cost=CostConfig(stride=1))).plan(
        room(), [A, B], snap, TASK, Pose2D(5.5, 5.0, 0.0), np.zeros(2), None)
    assert out.s_struct[B.id] > 0.5 and out.goal.id == B.id
    assert out.s_struct[A.id] < 1e-3  # the nightstand scores 0 without an embedder


def test_a_deterministic_planner_runs_the_ils_without_a_wall_time_limit(monkeypatch) -> None:
    """The stepped clock's planner runs a fixed ILS schedule (no wall-time limit, a fixed number
    of starts), so the order cannot depend on how fast or busy the machine is; the real-time
    planner keeps its time limit."""
    import hiconav.exploration.wtrp.ils as ils

    calls = []
    real = ils.solve_ils

    def spy(M, W, **kw):
        calls.append(kw)
        return real(M, W, **kw)

    monkeypatch.setattr(ils, "solve_ils", spy)
    rng = np.random.default_rng(3)
    xy = rng.uniform(1.0, 9.0, size=(40, 2))
    frontiers = [Frontier(id=i, centroid=p, viewpoint=p, size=10) for i, p in enumerate(xy)]
    cfg = ExplorationConfig(cost=CostConfig(stride=1))
    orders = [plan(ExplorationPlanner(cfg, deterministic=True), 5.5, frontiers) for _ in range(2)]
    assert orders[0].solver == "ils" and orders[0].order == orders[1].order
    assert calls[0]["time_limit"] is None and calls[0]["max_restarts"] == cfg.ordering.stepped_restarts
    plan(ExplorationPlanner(cfg), 5.5, frontiers)
    assert calls[-1]["time_limit"] == cfg.ordering.time_limit


def test_ruled_out_instances_are_no_target_evidence() -> None:
    """A bed the reasoning ruled out (not the described one) no longer draws the robot back."""
    from types import SimpleNamespace

    o = make_object("bed", (1.0, 5.0), (1.0, 1.0, 0.6))
    bed = SimpleNamespace(id=3, label=o.label, center=o.center, box_min=o.box_min, box_max=o.box_max)
    cfg = ExplorationConfig(cost=CostConfig(stride=1), utility=UtilityConfig(beta=5.0))
    snap = Snapshot(objects=(bed,))
    drawn = plan(ExplorationPlanner(cfg), 5.5, snapshot=snap)
    assert drawn.goal.id == B.id and drawn.s_struct[B.id] > 0.3
    free = ExplorationPlanner(cfg).plan(room(), [A, B], snap, TASK, Pose2D(5.5, 5.0, 0.0), np.zeros(2),
                                        similarity, now=1.0, ruled_out=frozenset({3}))
    assert free.goal.id == A.id and free.s_struct[B.id] == 0.0


def test_frontiers_reachable_only_one_cell_thinner_are_costed_so_when_nothing_else_is_reachable() -> None:
    """The tracker keeps such frontiers as a last resort (``FrontierTracker.squeezed``); costed on
    the lethal layer they were all dropped and the search ended with floor unseen."""
    far = Frontier(id=3, centroid=np.array([5.0, 1.5]), viewpoint=np.array([4.6, 1.5]), size=40)
    out = planner().plan(corridor_grid(6), [far], None, TASK, Pose2D(1.0, 1.5, 0.0), np.zeros(2), similarity, now=1.0)
    assert out.goal is not None and out.goal.id == far.id and out.order == (far.id,)
    out = planner().plan(corridor_grid(4), [far], None, TASK, Pose2D(1.0, 1.5, 0.0), np.zeros(2), similarity, now=1.0)
    assert out.goal is None and out.dropped == (far.id,)


def test_a_target_out_of_reach_draws_the_frontier_on_the_way_to_it_and_a_rejected_one_can_be_left_out() -> None:
    """A bed glimpsed 3.5 m beyond frontier B (a sliver of box, sigma_min) gives B nothing and the
    nearer frontier A goes first; once verification set it aside as out of reach (``drawn``) B is
    the goal. With ``exclude_rejected`` a node rejected for good is no evidence at all."""
    from types import SimpleNamespace

    o = make_object("bed", (-2.0, 5.0), (0.05, 0.3, 0.2))
    bed = SimpleNamespace(id=3, label=o.label, center=o.center, box_min=o.box_min, box_max=o.box_max)
    snap = Snapshot(objects=(bed,))
    cfg = ExplorationConfig(cost=CostConfig(stride=1), utility=UtilityConfig(reach_sigma=2.0))

    def go(config, **sets):
        return ExplorationPlanner(config).plan(room(), [A, B], snap, TASK, Pose2D(6.0, 5.0, 0.0), np.zeros(2),
                                               similarity, now=1.0, **sets)

    assert go(cfg).goal.id == A.id and go(cfg).s_struct[B.id] < 1e-6
    drawn = go(cfg, drawn={3})
    assert drawn.goal.id == B.id and drawn.s_struct[B.id] > 0.1
    assert go(cfg, drawn={3}, rejected={3}).goal.id == B.id  # rejections count only when asked
    excluding = cfg.model_copy(update={"utility": UtilityConfig(reach_sigma=2.0, exclude_rejected=True)})
    assert go(excluding, drawn={3}, rejected={3}).goal.id == A.id
