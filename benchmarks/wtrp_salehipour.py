"""WTRP solver benchmark on the Salehipour travelling-repairman instances (unit weights).

Reads all instances in ``<data>/trp/salehipour`` (100 XML files, first coordinate = depot),
builds floor(Euclidean) distances, solves the open-path minimum-latency problem with
``hiconav.exploration.solve_wtrp`` under a per-instance time limit, and prints per size the
mean and max gap to ``best_known.csv`` ((found - best) / best) and the mean time. Ends with
one JSON line {"S10": {"gap_mean", "gap_max", "time_s"}, ...}.

Usage: python benchmarks/wtrp_salehipour.py [--method auto|ils|ortools|greedy|exact]
       [--time-limit 1.0] [--sizes 10,20,50,100,200] [--seed 0] [--clock wall|cpu]
Timings depend on the machine's load; numba kernels are compiled/loaded before timing.
``--clock cpu`` (ils only) counts the time limit in this process's CPU seconds, which on a
shared, loaded machine approximates the wall time of a quiet one; the default is wall time.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np


def load_instance(path: Path) -> np.ndarray:
    """(n+1, n+1) float64 floor(Euclidean) distance matrix; row/col 0 is the depot."""
    root = ET.parse(path).getroot()
    xy = np.array([[float(c.get("x")), float(c.get("y"))] for c in root.iter("coordinates")])
    dim = root.findtext("dim")
    if dim is not None and int(dim) + 1 != len(xy):
        raise ValueError(f"{path}: <dim> {dim} but {len(xy)} coordinates (expected dim + 1)")
    return np.floor(np.linalg.norm(xy[:, None, :] - xy[None, :, :], axis=-1))


def main(argv: list[str] | None = None) -> dict:
    from hiconav.data import data_root
    from hiconav.exploration.wtrp import solve_wtrp
    from hiconav.exploration.wtrp.exact import solve_exact
    from hiconav.exploration.wtrp.ils import solve_ils, warm_up

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--method", default="auto")
    ap.add_argument("--time-limit", type=float, default=1.0)
    ap.add_argument("--sizes", default="10,20,50,100,200")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--data", type=Path, default=None)
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall")
    args = ap.parse_args(argv)

    folder = (args.data or data_root()) / "trp" / "salehipour"
    with open(folder / "best_known.csv") as fh:
        best = {row["instance"]: float(row["best_known_latency"]) for row in csv.DictReader(fh)}
    sizes = [int(s) for s in args.sizes.split(",")]
    warm_up()
    solve_exact(np.ones((3, 3)), np.ones(2))  # compile the DP outside the timed part

    summary: dict[str, dict[str, float]] = {}
    for size in sizes:
        files = sorted(folder.glob(f"TRP-S{size:03d}-R*.xml"))
        gaps, times = [], []
        for f in files:
            M = load_instance(f)
            n = M.shape[0] - 1
            t0 = time.perf_counter()
            if args.clock == "cpu" and args.method in ("auto", "ils") and n > 12:
                sol = solve_ils(M, np.ones(n), time_limit=args.time_limit, seed=args.seed,
                                clock=time.process_time)
            else:
                sol = solve_wtrp(M, np.ones(n), method=args.method, time_limit=args.time_limit,
                                 seed=args.seed)
            dt = time.perf_counter() - t0
            gap = (sol.cost - best[f.stem]) / best[f.stem]
            gaps.append(gap)
            times.append(dt)
            print(f"{f.stem}: cost {sol.cost:.0f} best {best[f.stem]:.0f} gap {100 * gap:.3f}% "
                  f"time {dt:.3f}s ({sol.method})", file=sys.stderr)
        g = np.array(gaps)
        summary[f"S{size}"] = {"gap_mean": round(float(g.mean()), 6), "gap_max": round(float(g.max()), 6),
                               "time_s": round(float(np.mean(times)), 4)}
        print(f"S{size}: {len(files)} instances, gap mean {100 * g.mean():.3f}% max {100 * g.max():.3f}%, "
              f"mean time {np.mean(times):.3f}s (wall; method {args.method}, clock {args.clock})")
    print(json.dumps(summary))
    return summary


if __name__ == "__main__":
    main()
