"""Per-frame cost of the sensor-input checks (issue #29): building a 640x480 ``Frame`` (which
checks rgb, intrinsics and poses), the ``PoseGate`` check, and the grid's extent check, beside
the cost of building a frame without checks (``object.__new__`` + fields) for reference.

Prints one line per figure (median microseconds over ``--n`` repetitions). Timings on a shared
machine are inflated by contention.

Usage: python benchmarks/frame_checks.py [--n 2000]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from hiconav.mapping import OccupancyGrid, PoseGate
from hiconav.types import CameraIntrinsics, Frame, Pose2D, camera_pose_from_base


def median_us(fn, n: int) -> float:
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times) * 1e6


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=2000)
    n = ap.parse_args().n
    K = CameraIntrinsics.from_hfov(640, 480, 79.0)
    pose = Pose2D(1.0, 2.0, 0.3)
    args = dict(rgb=np.zeros((480, 640, 3), np.uint8), depth=np.ones((480, 640), np.float32), intrinsics=K,
                T_world_cam=camera_pose_from_base(pose, 0.88), base_pose=pose, stamp=1.0)
    frame = Frame(**args)

    def unchecked() -> None:
        f = object.__new__(Frame)
        for k, v in args.items():
            object.__setattr__(f, k, v)

    gate = PoseGate()
    gate.accept(frame)
    grid = OccupancyGrid()
    grid.integrate(frame)
    T = frame.T_world_cam
    reach = grid.config.max_depth + 2 * grid.resolution
    print(f"Frame(...) 640x480 uint8, checked:   {median_us(lambda: Frame(**args), n):8.1f} us")
    print(f"Frame fields set, unchecked:         {median_us(unchecked, n):8.1f} us")
    float_args = {**args, "rgb": np.full((480, 640, 3), 0.5, np.float32)}
    print(f"Frame(...) float rgb in [0, 1]:      {median_us(lambda: Frame(**float_args), n // 10):8.1f} us")
    print(f"CameraIntrinsics(...):               {median_us(lambda: CameraIntrinsics(640, 480, 5.0, 5.0, 3.0, 2.0), n):8.1f} us")
    print(f"PoseGate.check:                      {median_us(lambda: gate.check(frame), n):8.1f} us")
    print(f"OccupancyGrid extent check:          "
          f"{median_us(lambda: grid._grown_bounds(T[0, 3] - reach, T[1, 3] - reach, T[0, 3] + reach, T[1, 3] + reach), n):8.1f} us")


if __name__ == "__main__":
    main()
