"""Render speed of the built-in simulator: RGB + depth + instances at 640x480.

Renders FRAMES_PER_HOUSE frames in each of several ProcTHOR and Gibson houses from seeded
free-space poses (random yaw, some with camera tilt), prints per-house figures and ends with
one JSON line: {"render_ms_median": ..., "width": 640, "height": 480, "cpu_ms_median": ...,
"load_avg_1m": ...} (the load average says how contended the machine was). Time per frame covers
the draw call and the read-back of all three images into fresh numpy arrays (wall clock). The
per-house lines also give the process CPU time per frame summed over all threads (Mesa's
llvmpipe renders on worker threads), which is less sensitive to other load on the machine.

Usage: python benchmarks/render.py [--frames-per-house 40] [--houses spec,spec,...]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time

import numpy as np

from hiconav.sim.episodes import generate_episodes
from hiconav.sim.houses import load_house
from hiconav.sim.renderer import Renderer, gl_context
from hiconav.types import CameraIntrinsics, Pose2D, camera_pose_from_base

HOUSES = ("procthor:val/3", "procthor:train/17", "procthor:val/50", "gibson:Allensville",
          "gibson:Cosmos", "gibson:Beechwood")
W, H = 640, 480


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames-per-house", type=int, default=40)
    ap.add_argument("--houses", default=",".join(HOUSES))
    args = ap.parse_args()
    ctx = gl_context()
    print(f"GL renderer: {ctx.info['GL_RENDERER']}  LP_NUM_THREADS="
          f"{os.environ.get('LP_NUM_THREADS', '(Mesa default: one per core)')}  "
          f"load average (1 min) at start: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    K = CameraIntrinsics.from_hfov(W, H, 79.0)
    renderer = Renderer(W, H, min_depth=0.5, max_depth=5.0)
    all_ms: list[float] = []
    all_cpu: list[float] = []
    for spec in args.houses.split(","):
        house = load_house(spec)
        renderer.set_house(house)
        rng = np.random.default_rng(0)
        starts = [ep.start for ep in generate_episodes(house, args.frames_per_house, seed=0)]
        poses = [Pose2D(p.x, p.y, float(rng.uniform(-math.pi, math.pi))) for p in starts]
        tilts = rng.choice([0.0, 0.0, -math.radians(30)], size=len(poses))
        for _ in range(3):  # warm-up (shader compile, first upload)
            renderer.render(camera_pose_from_base(poses[0], 0.88), K)
        ms, cpu = [], []
        for pose, tilt in zip(poses, tilts):
            T = camera_pose_from_base(pose, 0.88, float(tilt))
            t0, c0 = time.perf_counter(), time.process_time()
            renderer.render(T, K)
            ms.append((time.perf_counter() - t0) * 1000.0)
            cpu.append((time.process_time() - c0) * 1000.0)
        all_ms += ms
        all_cpu += cpu
        print(f"{spec:22s} boxes={len(house.boxes):5d} frames={len(ms)} "
              f"median={np.median(ms):6.2f} ms p90={np.percentile(ms, 90):6.2f} ms "
              f"min={np.min(ms):6.2f} ms cpu(all threads)={np.median(cpu):6.2f} ms")
    renderer.release()
    print(f"total frames: {len(all_ms)}")
    print(json.dumps({"render_ms_median": round(float(np.median(all_ms)), 3), "width": W,
                      "height": H, "cpu_ms_median": round(float(np.median(all_cpu)), 3),
                      "load_avg_1m": round(os.getloadavg()[0], 2)}))


if __name__ == "__main__":
    main()
