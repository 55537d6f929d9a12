"""Rescore a finished run's SPL with l^s measured to the success region.

``python -m hiconav.eval.rescore OUT [OUT ...]`` reads ``OUT/specs.jsonl`` and
``OUT/episodes.jsonl`` and prints, per preset, SR, the SPL as recorded and the SPL with l^s the
geodesic distance from the start to the success region (``GoalDistance.to_success``; the
definition since December 2026, docs/evaluation.md). Runs made before the correction measured
l^s to the goal object, up to the success distance longer; this puts them on today's scale
without running them again. It reads files only and changes nothing.
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from hiconav.errors import DataError
from hiconav.eval.records import read_records
from hiconav.eval.sources import read_specs
from hiconav.sim.config import SimConfig
from hiconav.sim.geodesic import GoalDistance
from hiconav.sim.metrics import spl


def rescore(out: Path, success_distance: float | None = None) -> dict[str, tuple[int, float, float, float]]:
    """{preset: (episodes, SR, SPL as recorded, SPL to the success region)} over valid episodes."""
    sim = SimConfig()  # the simulator's robot radius and success distance, as the runs used them
    dist = sim.success_distance if success_distance is None else float(success_distance)
    specs = {s.episode_id: s for s in read_specs(out / "specs.jsonl")}
    acc: dict[str, list[tuple[bool, float, float]]] = defaultdict(list)
    for r in read_records(out / "episodes.jsonl"):
        if r.failure == "invalid_episode":
            continue
        new = 0.0
        if r.success:
            spec = specs[r.episode_id]
            goal = GoalDistance(spec.load_house(), instance_ids=list(spec.goal_instance_ids),
                                radius=sim.robot_radius)
            l_s = goal.to_success(np.asarray(spec.start[:2], dtype=np.float64), dist)
            new = spl(True, l_s, r.path_length)
        acc[r.preset].append((bool(r.success), float(r.spl), new))
    return {p: (len(v), float(np.mean([a for a, _, _ in v])), float(np.mean([b for _, b, _ in v])),
                float(np.mean([c for _, _, c in v]))) for p, v in acc.items()}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m hiconav.eval.rescore", description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="+", type=Path, help="output folders of hiconav eval")
    args = ap.parse_args(argv)
    for out in args.out:
        try:
            scores = rescore(out)
        except DataError as exc:  # a missing or malformed specs.jsonl / episodes.jsonl: say which
            print(f"hiconav.eval.rescore: {exc}", file=sys.stderr)
            return 2
        for preset, (n, sr, old, new) in scores.items():
            print(f"{out} {preset}: {n} episodes  SR {sr:.3f}  SPL recorded {old:.3f}  SPL to the success region {new:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
