"""Benchmark of the fast perception-action layer (issue 4) on rendered walks through real houses.

Per frame (640x480 RGB-D + instances from hiconav.sim): oracle detection, back-projection of
every detection mask (stride 2) with voxel downsampling, occupancy-grid update (depth stride 4),
frontier extraction/tracking, and A* (+ smoothing) from the robot to the nearest frontier
viewpoint. Rendering is not timed (it is the simulator's cost, not the fast layer's). The walk is
driven by the simulator's ground truth so that every run sees the same frames.

Prints per-house figures, then ends with exactly one JSON line:
{"fast_layer_hz": ..., "stage_ms": {...}, ...} (medians over all frames).

Usage: python benchmarks/fast_layer.py [--frames-per-house 160] [--houses gibson:Allensville procthor:val/3]
Timings on a shared machine are inflated by contention; the load average is printed with them, and
the median CPU time of the timed work (process_time) is reported beside the wall-clock figures.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
import time
from collections.abc import Iterator

import cv2
import numpy as np

from hiconav.geometry import backproject, voxel_downsample
from hiconav.mapping import FrontierTracker, OccupancyGrid
from hiconav.perception import OracleDetector
from hiconav.planning import Navigator, astar, smooth_path, to_discrete
from hiconav.types import DiscreteAction, Frame, Goal, Pose2D

VOCABULARY = ["chair", "sofa", "plant", "bed", "toilet", "tv"]


def walk(sim, n_frames: int, seed: int) -> Iterator[Frame]:
    """Deterministic walk: A* on the simulator's free mask between random cells, with look-arounds."""
    rng = np.random.default_rng(seed)
    nav = sim.house.nav
    free = sim.free
    _, labels = cv2.connectedComponents(free.astype(np.uint8), connectivity=8)
    big = int(np.argmax(np.bincount(labels[free])))
    rr, cc = np.nonzero(labels == big)
    k = int(rng.integers(len(rr)))
    start = nav.cell_to_world(np.array([rr[k], cc[k]]))
    yield sim.reset(Pose2D(float(start[0]), float(start[1]), float(rng.uniform(-np.pi, np.pi))))
    produced = 1
    path: np.ndarray | None = None
    while produced < n_frames:
        if path is None or len(path) == 0:
            for _ in range(int(rng.integers(0, 12))):
                if produced >= n_frames:
                    return
                yield sim.step(DiscreteAction.TURN_LEFT)
                produced += 1
            g = int(rng.integers(len(rr)))
            s = nav.world_to_cell(sim.pose.xy)
            cells = astar(~free, (int(s[0]), int(s[1])), (int(rr[g]), int(cc[g])))
            path = (
                None if cells is None or len(cells) < 4 else nav.cell_to_world(smooth_path(~free, cells))[1:]
            )
            continue
        while len(path) and np.hypot(*(path[0] - sim.pose.xy)) < 0.2:
            path = path[1:]
        if len(path) == 0:
            continue
        frame = sim.step(to_discrete(sim.pose, path[0], 15.0))
        produced += 1
        if sim.collided:
            path = None
        yield frame


def run_house(spec: str, n_frames: int, seed: int) -> dict[str, list[float]]:
    from hiconav.sim import Simulator, load_house

    house = load_house(spec)
    sim = Simulator(house)
    detector = OracleDetector(house.instance_categories, seed=seed)
    grid = OccupancyGrid()
    tracker = FrontierTracker()
    navigator = Navigator()
    times: dict[str, list[float]] = {
        k: []
        for k in (
            "detect",
            "backproject",
            "grid_update",
            "frontiers",
            "astar",
            "total",
            "total_cpu",
            "render",
        )
    }
    counts = {"detections": 0, "frontiers": 0, "paths": 0}
    t_render = time.perf_counter()
    for frame in walk(sim, n_frames, seed):
        times["render"].append((time.perf_counter() - t_render) * 1e3)
        c0 = time.process_time()
        t0 = time.perf_counter()
        dets = detector.detect(frame, VOCABULARY)
        t1 = time.perf_counter()
        for d in dets:
            pts, _ = backproject(
                frame.depth,
                frame.intrinsics,
                frame.T_world_cam,
                stride=2,
                mask=d.mask,
                min_depth=0.5,
                max_depth=5.0,
            )
            if len(pts):
                voxel_downsample(pts, 0.05)
        t2 = time.perf_counter()
        grid.integrate(frame)
        t3 = time.perf_counter()
        frontiers = tracker.update(grid, frame.base_pose.xy)
        t4 = time.perf_counter()
        if frontiers:
            xy = frame.base_pose.xy
            best = min(frontiers, key=lambda f: float(np.hypot(*(f.viewpoint - xy))))
            navigator.set_goal(Goal(float(best.viewpoint[0]), float(best.viewpoint[1]), ref_id=best.id))
            counts["paths"] += int(navigator.plan(grid, frame.base_pose))
        t5 = time.perf_counter()
        times["total_cpu"].append((time.process_time() - c0) * 1e3)
        for key, a, b in (
            ("detect", t0, t1),
            ("backproject", t1, t2),
            ("grid_update", t2, t3),
            ("frontiers", t3, t4),
            ("astar", t4, t5),
            ("total", t0, t5),
        ):
            times[key].append((b - a) * 1e3)
        counts["detections"] += len(dets)
        counts["frontiers"] += len(frontiers)
        t_render = time.perf_counter()
    med = {k: round(float(np.median(v)), 3) for k, v in times.items()}
    print(
        f"{spec}: {len(times['total'])} frames, grid {grid.shape}, explored {grid.explored_area_m2:.1f} m2, "
        f"{counts['detections']} detections, "
        f"{counts['frontiers'] / len(times['total']):.1f} frontiers/frame, "
        f"{counts['paths']} paths; median ms {med}",
        flush=True,
    )
    return times


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames-per-house", type=int, default=160)
    parser.add_argument("--houses", nargs="+", default=["gibson:Allensville", "procthor:val/3"])
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    # warm-up: compile the numba kernels outside the timed loop
    run_house(args.houses[0], 3, args.seed)
    all_times: dict[str, list[float]] = {}
    for spec in args.houses:
        for k, v in run_house(spec, args.frames_per_house, args.seed).items():
            all_times.setdefault(k, []).extend(v)
    n = len(all_times["total"])
    stage = {
        k: round(float(np.median(v)), 3) for k, v in all_times.items() if k not in ("render", "total_cpu")
    }
    result = {
        "fast_layer_hz": round(1000.0 / float(np.median(all_times["total"])), 2),
        "stage_ms": stage,
        "stage_mean_ms": {
            k: round(float(np.mean(v)), 3) for k, v in all_times.items() if k not in ("render", "total_cpu")
        },
        "frames": n,
        # CPU time of this process for the same work: what a quiet machine would see
        "total_cpu_ms": round(float(np.median(all_times["total_cpu"])), 3),
        "fast_layer_hz_cpu": round(1000.0 / float(np.median(all_times["total_cpu"])), 2),
        "houses": args.houses,
        "detector": "oracle",
        "render_ms_median_not_counted": round(float(np.median(all_times["render"])), 3),
        "loadavg_1min": round(os.getloadavg()[0], 2),
        "cpus": os.cpu_count(),
    }
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
