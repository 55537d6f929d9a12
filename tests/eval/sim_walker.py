"""A cheap episode runner on the real simulator data (import path "sim_walker:run_episode").

It loads the episode's house through ``EpisodeSpec.load_house`` (cached per worker), builds the
geodesic goal-distance field (``hiconav.sim.GoalDistance``) and walks down it in 0.25 m moves
among 16 headings, taking a seeded random move with probability ``walker.noise``; it stops
within the success distance. No rendering, no detector: it checks the harness end to end on
real houses, not the method. A start on a cell that cannot reach the goal is bad input.
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

STEP = 0.25
SUCCESS_DISTANCE = 1.0


def run_episode(spec: EpisodeSpec, overrides: dict[str, Any], seed: int) -> EpisodeRecord:
    from hiconav.sim import GoalDistance

    t0 = time.perf_counter()
    house = spec.load_house()
    episode = spec.to_episode()
    field = GoalDistance(house, episode).field
    nav = house.nav
    load_s = time.perf_counter() - t0
    rng = np.random.default_rng(seed)
    noise = float(overrides.get("walker.noise", 0.2))
    max_steps = int(overrides.get("walker.max_steps", 200))

    def dist(xy: np.ndarray) -> float:
        rc = nav.world_to_cell(xy)
        return float(field[rc[0], rc[1]]) if nav.in_bounds(rc) else math.inf

    position = np.array(spec.start[:2])
    if not math.isfinite(dist(position)):
        raise DataError(f"start {position.tolist()} of {spec.episode_id} cannot reach a goal", field="start")
    headings = np.linspace(-math.pi, math.pi, 16, endpoint=False)
    moves = STEP * np.stack([np.cos(headings), np.sin(headings)], axis=1)
    positions = [position.copy()]
    path, steps, termination = 0.0, 0, "step_limit"
    t1 = time.perf_counter()
    for steps in range(1, max_steps + 1):
        here = dist(position)
        if here <= SUCCESS_DISTANCE - 0.05:
            termination = "stop"
            break
        options = [(dist(position + m), i) for i, m in enumerate(moves)]
        finite = [o for o in options if math.isfinite(o[0])]
        if not finite:
            termination = "stuck"
            break
        pick = finite[int(rng.integers(len(finite)))] if rng.random() < noise else min(finite)
        position = position + moves[pick[1]]
        path += STEP
        positions.append(position.copy())
    walk_s = time.perf_counter() - t1
    final = dist(position)
    success = termination == "stop"
    shortest = spec.geodesic_distance
    return EpisodeRecord(
        episode_id=spec.episode_id, house=spec.house, target=spec.target, success=success,
        spl=shortest / max(shortest, path) if success and max(shortest, path) > 0 else float(success),
        dts=max(0.0, final - SUCCESS_DISTANCE), steps=steps, max_steps=max_steps, path_length=path,
        geodesic_distance=shortest, termination=termination,
        last_progress_step=last_progress_step(np.array(positions)), task_time_s=steps * 0.25,
        layer_time_s={"load": load_s, "control": walk_s}, layer_frames={"load": 1, "control": steps},
        detector="oracle", reasoner="offline")
