"""Benchmark: the cognitive memory graph on a 500-step episode in the built-in simulator.

Drives a scripted walk (forward; on a collision, or every so often, turn by a seeded random
number of 30-degree steps) through a ProcTHOR house, detects with the OracleDetector (noisy
ground truth, source "oracle") and feeds every frame to ``CognitiveMemoryGraph.update``. Each
step it takes a ``snapshot()``; every ``--prune-every`` steps it prunes the live graph (ILP of
eqs. 5-7). Rendering and detection are not timed; update, snapshot and prune are.

Prints the figures, a diagnostics line (anchors, nodes, distinct ground-truth instances mapped,
duplicates, graph array bytes, process peak RSS) and ends with one JSON line
``{"update_ms_median": ..., "snapshot_ms_median": ..., "prune_ms_median": ..., "peak_rss_mb": ...}``
where ``peak_rss_mb`` is the growth of the process's resident memory from just before the first
graph update to the end of the run (what the graph costs; the simulator, renderer and embedder
model are loaded before the baseline is read).

Run: ``python benchmarks/memory.py [--house procthor:val/3] [--steps 500] [--seed 0]``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time

import numpy as np
import psutil

from hiconav.memory import CognitiveMemoryGraph, MemoryConfig
from hiconav.perception import OracleDetector, get_embedder
from hiconav.sim import Simulator, generate_episodes, load_house
from hiconav.types import DiscreteAction


def _rss_mb() -> float:
    return psutil.Process().memory_info().rss / 2**20


def graph_bytes(graph: CognitiveMemoryGraph) -> int:
    """Bytes held in the graph's arrays (point clouds, images, features, boxes)."""
    total = 0
    for n in graph.objects.values():
        total += n.points.nbytes + n.feature.nbytes + 2 * n.box_min.nbytes
    for a in graph.anchors.values():
        total += a.image.nbytes + a.descriptor.nbytes + a.T_world_cam.nbytes + 16 * len(a.boxes)
    return total


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--house", default="procthor:val/3")
    ap.add_argument("--steps", type=int, default=500)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--prune-every", type=int, default=10)
    ap.add_argument("--embedder", default="minilm", help="minilm (default) or hashing (fallback)")
    args = ap.parse_args(argv)

    house = load_house(args.house)
    sim = Simulator(house, seed=args.seed)
    detector = OracleDetector(house.instance_categories, seed=args.seed)
    embedder = get_embedder(args.embedder)
    embedder.embed(sorted(set(house.instance_categories.values())))  # load the model now
    graph = CognitiveMemoryGraph(MemoryConfig(embedder=args.embedder), embedder=embedder)
    episode = generate_episodes(house, 1, seed=args.seed)[0]
    rng = np.random.default_rng(args.seed)
    frame = sim.reset(episode.start)
    detector.detect(frame)  # warm-up
    rss0 = _rss_mb()
    peak = rss0
    upd, upd_cpu, snap, prune = [], [], [], []
    n_anchor = 0
    prune_status: dict[str, int] = {}
    turns_left = 0
    for step in range(args.steps):
        dets = detector.detect(frame)
        t0 = time.perf_counter()
        c0 = time.process_time()
        u = graph.update(frame, dets)
        upd_cpu.append(1e3 * (time.process_time() - c0))
        t1 = time.perf_counter()
        graph.snapshot()
        t2 = time.perf_counter()
        upd.append(1e3 * (t1 - t0))
        snap.append(1e3 * (t2 - t1))
        n_anchor += int(u.is_anchor)
        if args.prune_every and (step + 1) % args.prune_every == 0:
            r = graph.prune()
            prune.append(r.time_ms)
            prune_status[r.status] = prune_status.get(r.status, 0) + 1
        peak = max(peak, _rss_mb())
        # scripted walk
        if turns_left > 0:
            action = DiscreteAction.TURN_LEFT
            turns_left -= 1
        elif sim.collided or rng.random() < 0.08:
            turns_left = int(rng.integers(1, 6))
            action = DiscreteAction.TURN_LEFT
        else:
            action = DiscreteAction.MOVE_FORWARD
        frame = sim.step(action)
    seen = {i for n in graph.objects.values() for i in n.instance_votes}
    gt = [n.gt_instance for n in graph.objects.values() if n.gt_instance is not None]
    dup = len(gt) - len(set(gt))
    impure = sum(1 for n in graph.objects.values()
                 if n.instance_votes and max(n.instance_votes.values()) < 0.8 * sum(n.instance_votes.values()))
    spurious = sum(1 for n in graph.objects.values() if not n.instance_votes)
    print(f"steps {args.steps}  house {args.house}  anchors selected {n_anchor}, kept {graph.n_anchors}")
    print(f"object nodes {graph.n_objects}  distinct gt instances mapped {len(seen)}  "
          f"duplicate nodes (same majority instance) {dup}  impure nodes (<80% one instance) "
          f"{impure}  nodes from spurious oracle boxes {spurious}")
    print(f"update ms: median {statistics.median(upd):.2f} p90 {np.percentile(upd, 90):.2f} "
          f"max {max(upd):.2f}  (CPU time median {statistics.median(upd_cpu):.2f})")
    print(f"snapshot ms: median {statistics.median(snap):.3f} max {max(snap):.3f}")
    if prune:
        print(f"prune ms: median {statistics.median(prune):.2f} max {max(prune):.2f}  status {prune_status}")
    print(f"graph arrays {graph_bytes(graph) / 2**20:.1f} MB  process peak RSS {peak:.0f} MB "
          f"(baseline {rss0:.0f} MB)")
    print(json.dumps({
        "update_ms_median": round(statistics.median(upd), 3),
        "snapshot_ms_median": round(statistics.median(snap), 4),
        "prune_ms_median": round(statistics.median(prune), 3) if prune else None,
        "peak_rss_mb": round(peak - rss0, 1),
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
