"""The memory graph on a real ProcTHOR house in the built-in simulator with the oracle detector:
object nodes track ground-truth instances (few duplicates, no wrong merges) and pruning stays
exact and valid on the live graph."""

from __future__ import annotations

import numpy as np
import pytest

from hiconav.memory import CognitiveMemoryGraph, MemoryConfig
from hiconav.memory.setcover import is_feasible_cover, multicover_requirements
from hiconav.perception import HashingEmbedder, OracleConfig, OracleDetector
from hiconav.types import DiscreteAction

sim_mod = pytest.importorskip("hiconav.sim")


@pytest.fixture(scope="module")
def replay(shared_data):
    house = sim_mod.load_house("procthor:val/3", data_dir=shared_data)
    sim = sim_mod.Simulator(house, seed=0)
    # a clean oracle: no label confusion or spurious boxes, so node purity is measurable
    det = OracleDetector(house.instance_categories,
                         OracleConfig(confusion_rate=0.0, false_positive_rate=0.0), seed=0)
    graph = CognitiveMemoryGraph(MemoryConfig(), embedder=HashingEmbedder())
    episode = sim_mod.generate_episodes(house, 1, seed=0)[0]
    frame = sim.reset(episode.start)
    rng = np.random.default_rng(0)
    turns = 0
    prunes = []
    for step in range(80):
        graph.update(frame, det.detect(frame))
        if (step + 1) % 20 == 0:
            prunes.append(graph.prune())
        if turns > 0:
            action, turns = DiscreteAction.TURN_LEFT, turns - 1
        elif sim.collided or rng.random() < 0.08:
            action, turns = DiscreteAction.TURN_LEFT, int(rng.integers(1, 6))
        else:
            action = DiscreteAction.MOVE_FORWARD
        frame = sim.step(action)
    sim.close()
    return graph, prunes


def test_nodes_track_instances(replay):
    graph, _ = replay
    nodes = list(graph.objects.values())
    instances = [n.gt_instance for n in nodes]
    assert len(nodes) >= 5
    assert None not in instances
    # duplicates (two nodes for one instance) stay rare
    assert len(instances) - len(set(instances)) <= max(1, len(set(instances)) // 5)
    # no node mixes instances
    for n in nodes:
        assert max(n.instance_votes.values()) == sum(n.instance_votes.values()), n.instance_votes


def test_pruning_on_live_graph_is_exact_and_feasible(replay):
    graph, prunes = replay
    assert prunes and all(p.proven_optimal and not p.is_fallback for p in prunes)
    _, aids, A = graph.cover_matrix()
    req = multicover_requirements(A, graph.config.r)
    assert is_feasible_cover(A, req, np.arange(len(aids)))  # every object still has an anchor
    assert all(len(n.anchor_ids) >= 1 for n in graph.objects.values())
    snap = graph.snapshot()
    for a in snap.anchors:
        for oid in a.object_ids:
            assert a.id in snap.object(oid).anchor_ids  # edges consistent both ways
