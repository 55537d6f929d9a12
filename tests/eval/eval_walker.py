"""A small deterministic episode runner for the harness tests (import path "eval_walker:run_episode").

It really runs something cheap: a noisy greedy walker on an open plane walks from the episode's
start toward a goal placed ``geodesic_distance`` ahead of it, in 0.25 m steps, with seeded
heading noise; presets change the noise (so ablations differ), a bounded map makes far goals
"no frontier", a seeded chance of a premature stop gives false positives, and a seeded wall
pins some walkers in place (stuck). Unknown target categories raise ``DataError`` (bad input).
Nothing here is a hard-coded result.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from hiconav.errors import DataError
from hiconav.eval.records import EpisodeRecord
from hiconav.eval.sources import EpisodeSpec
from hiconav.eval.taxonomy import last_progress_step

CATEGORIES = ("bed", "chair", "sofa", "toilet", "tv", "plant")
STEP = 0.25
SUCCESS_DISTANCE = 1.0


def run_episode(spec: EpisodeSpec, overrides: dict[str, Any], seed: int) -> EpisodeRecord:
    if spec.target not in CATEGORIES:
        raise DataError(f"unknown target category {spec.target!r}", field="target")
    if overrides.get("walker.crash"):
        raise RuntimeError("walker crashed on purpose")
    rng = np.random.default_rng(seed)
    noise = float(overrides.get("walker.noise", 0.35))
    if overrides.get("exploration.utility.use_struct") is False:
        noise += 0.25
    if overrides.get("exploration.ordering.ordering") in ("greedy_utility", "nearest"):
        noise += 0.35
    max_steps = int(overrides.get("walker.max_steps", 80))
    map_radius = float(overrides.get("walker.map_radius", 11.0))
    p_false = 0.25 if overrides.get("mission.verify") is False else 0.08
    start = np.array(spec.start[:2], dtype=np.float64)
    yaw = spec.start[2]
    goal = start + spec.geodesic_distance * np.array([math.cos(yaw), math.sin(yaw)])
    wall_at = rng.uniform(0.2, 0.8) * spec.geodesic_distance if rng.random() < 0.1 else None
    stop_at = int(rng.integers(3, max_steps)) if rng.random() < p_false else None

    t0 = time.perf_counter()
    position = start.copy()
    positions = [position.copy()]
    path = 0.0
    termination = "step_limit"
    steps = 0
    for steps in range(1, max_steps + 1):
        to_goal = goal - position
        if np.linalg.norm(to_goal) <= SUCCESS_DISTANCE - 0.05 or steps == stop_at:
            termination = "stop"
            break
        heading = math.atan2(to_goal[1], to_goal[0]) + rng.normal(0.0, noise)
        move = STEP * np.array([math.cos(heading), math.sin(heading)])
        if wall_at is not None and np.linalg.norm(position + move - start) > wall_at:
            move = np.zeros(2)  # collision: the walker stays where it is
        if np.linalg.norm(position + move - start) > map_radius:
            termination = "no_frontier"
            break
        position = position + move
        path += float(np.linalg.norm(move))
        positions.append(position.copy())
    control_s = time.perf_counter() - t0

    distance = float(np.linalg.norm(goal - position))
    success = termination == "stop" and distance <= SUCCESS_DISTANCE
    shortest = max(0.0, spec.geodesic_distance - SUCCESS_DISTANCE)
    spl = shortest / max(shortest, path) if success and max(shortest, path) > 0 else float(success)
    return EpisodeRecord(
        episode_id=spec.episode_id, house=spec.house, target=spec.target, success=success, spl=spl,
        dts=max(0.0, distance - SUCCESS_DISTANCE), steps=steps, max_steps=max_steps, path_length=path,
        geodesic_distance=spec.geodesic_distance, termination=termination,
        last_progress_step=last_progress_step(np.array(positions)), task_time_s=steps * 0.5,
        layer_time_s={"control": control_s, "perception": control_s / 2},
        layer_frames={"control": steps, "perception": steps}, vlm_calls=0,
        detector="oracle", reasoner="offline")


def make_specs(n: int, seed: int = 0, houses: int = 3) -> list[EpisodeSpec]:
    """``n`` synthetic episodes (start pose, target, geodesic distance) from a seeded generator."""
    rng = np.random.default_rng(seed)
    specs = []
    for i in range(n):
        start = (float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5)), float(rng.uniform(-math.pi, math.pi)))
        specs.append(EpisodeSpec(episode_id=f"synthetic/{i % houses}/{i}", house=f"synthetic/{i % houses}",
                                 target=CATEGORIES[int(rng.integers(len(CATEGORIES)))], start=start,
                                 goal_instance_ids=(int(rng.integers(100)),),
                                 geodesic_distance=float(rng.uniform(1.5, 12.0)),
                                 instruction="find the object"))
    return specs
