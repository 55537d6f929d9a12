"""How well the room prior names an object's room in houses it was not counted in.

The offline reasoner infers a candidate's room from the objects seen with it
(``hiconav.reasoning.grounding.infer_rooms``, likelihoods counted in the ProcTHOR train houses:
``hiconav.reasoning.room_prior``). This script asks the same question of the ground truth of
other houses (default: the shared ProcTHOR **val** houses, never counted): for every object that
stands in one of the four room types, its cues are the other objects of its own room within
``ROOM_REACH_M`` (as if the robot had seen the whole room with it; the object's own category gives
none, as for a described instance). It prints, per posterior threshold, the share of objects
whose room is inferred (coverage), the share of those inferred right (precision), and the share
right over all, then one JSON line for the shipped threshold:

    {"houses": H, "objects": N, "min_posterior": t, "coverage": c, "precision": p, "right": r,
     "by_room": {room: {"objects": n, "coverage": c, "precision": p}, ...}}

    python benchmarks/room_prior.py [--houses FILE] [--prior FILE] [--limit N]

A whole room in view is more than a robot sees at once: read the figures as the prior's
ceiling on these houses, not as the mission's.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter, defaultdict
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from hiconav.reasoning import grounding
from hiconav.reasoning.room_prior import ROOM_TYPES, ROOMS, default_log_ratios, load, log_ratios

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data" / "procthor" / "val.jsonl.gz"
THRESHOLDS = (0.5, 0.6, 0.7, 0.8, 0.9)


def house_nodes(house) -> tuple[list[SimpleNamespace], dict[int, str]]:
    """Nodes of a house's objects in the four room types (the room's index as their common
    anchor: one room, one view) and each node's true room."""
    from hiconav.sim.task_episodes import GroundTruth

    gt = GroundTruth(house)
    nodes: list[SimpleNamespace] = []  # what infer_rooms reads of a memory node
    truth: dict[int, str] = {}
    for k, obj in enumerate(house.objects):
        room = ROOM_TYPES.get(str(gt.room_of(k)))
        idx = gt.room_index(k)
        if room is None or idx is None:
            continue
        c, s = np.asarray(obj.center, float), np.asarray(obj.size, float)
        cy, sy = abs(np.cos(obj.yaw)), abs(np.sin(obj.yaw))
        half = np.array([(s[0] * cy + s[1] * sy) / 2, (s[0] * sy + s[1] * cy) / 2, s[2] / 2])
        nodes.append(SimpleNamespace(id=k, label=str(obj.category), box_min=c - half, box_max=c + half,
                                     anchor_ids=(int(idx),)))
        truth[k] = room
    return nodes, truth


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--houses", default=str(SHARED), help="a ProcTHOR houses file (default: the shared val houses)")
    ap.add_argument("--prior", default=None, help="a counts file (default: the shipped train counts)")
    ap.add_argument("--limit", type=int, default=None, help="the first N houses only")
    args = ap.parse_args(argv)
    from hiconav.sim import load_house
    from hiconav.sim.procthor import split_lines

    path = str(Path(args.houses).expanduser().resolve())
    cues = log_ratios(load(args.prior)) if args.prior else default_log_ratios()
    n_lines = len(split_lines(path))  # reads (and decompresses) the whole file: once
    n_houses = n_lines if args.limit is None else min(args.limit, n_lines)
    rows: list[tuple[str, str | None, float]] = []  # (true room, argmax room, its posterior)
    shipped = grounding.ROOM_MIN_POSTERIOR
    for i in range(n_houses):
        nodes, truth = house_nodes(load_house(f"{path}#{i}", cache=False))
        by_label: dict[str, list[SimpleNamespace]] = defaultdict(list)
        for n in nodes:
            by_label[n.label].append(n)
        for label, group in by_label.items():
            # every argmax room with its posterior; the thresholds are applied below
            rooms = grounding.infer_rooms(nodes, ignore=(label,), cues=cues, min_posterior=0.0)
            for n in group:
                room, p = rooms[n.id]
                rows.append((truth[n.id], room, p if room is not None else 0.0))

    def figures(t: float, subset=None) -> dict:
        rs = [r for r in rows if subset is None or r[0] == subset]
        inferred = [r for r in rs if r[1] is not None and r[2] >= t]
        right = sum(1 for r in inferred if r[1] == r[0])
        return {"objects": len(rs), "coverage": round(len(inferred) / max(len(rs), 1), 3),
                "precision": round(right / max(len(inferred), 1), 3), "right": round(right / max(len(rs), 1), 3)}

    print(f"{n_houses} houses, {len(rows)} objects ({dict(Counter(r[0] for r in rows))})")
    for t in THRESHOLDS:
        f = figures(t)
        mark = "  <- shipped" if abs(t - shipped) < 1e-9 else ""
        print(f"min posterior {t:.1f}: coverage {f['coverage']:.3f}  precision {f['precision']:.3f}  "
              f"right {f['right']:.3f}{mark}")
    out = {"houses": n_houses, "objects": len(rows), "min_posterior": shipped, **{k: v for k, v in figures(shipped).items()
                                                                                   if k != "objects"},
           "by_room": {r: {k: v for k, v in figures(shipped, r).items() if k != "right"} for r in ROOMS}}
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
