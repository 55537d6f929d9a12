"""``hiconav sim``: walk a scripted path through a house and record it to Rerun.

The walk is deterministic per seed: it heads for random reachable free points one after
another, following the geodesic descent with discrete actions only (turn towards the path
point 0.5 m ahead, else move forward). This module is a thin command-line layer; the walk
logic (``scripted_walk``) is importable for the demo and tests.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from hiconav.types import DiscreteAction, Frame, Pose2D, wrap_angle


def _start_pose(sim, rng: np.random.Generator) -> Pose2D:
    house = sim.house
    if house.start_hint is not None and sim.is_free(np.array(house.start_hint[:2])):
        return Pose2D(*house.start_hint)
    from hiconav.sim.geodesic import house_graph

    graph = house_graph(house, sim.config.robot_radius)
    if graph.n == 0:
        from hiconav.errors import DataError

        raise DataError(f"{house.name} has no free floor for the robot", field="house")
    # The largest connected free region, so the walk can go somewhere.
    from scipy import ndimage

    labels, _n = ndimage.label(graph.mask, structure=np.ones((3, 3), dtype=bool))
    big = int(np.argmax(np.bincount(labels.ravel())[1:])) + 1
    cells = np.argwhere(labels == big)
    rc = cells[int(rng.integers(len(cells)))]
    xy = house.nav.cell_to_world(rc)
    return Pose2D(float(xy[0]), float(xy[1]), float(rng.uniform(-math.pi, math.pi)))


def scripted_walk(sim, steps: int, seed: int = 0) -> Iterator[tuple[int, DiscreteAction, Frame]]:
    """Yield (step, action, frame) for ``steps`` actions of a seeded scripted walk.

    The first item is the reset frame with action STOP and step 0 (not counted as a step).
    """
    from hiconav.sim.geodesic import GridGraph, house_graph

    rng = np.random.default_rng(seed)
    # Plan on cells with 10 cm of extra clearance so that 30-degree headings and 0.25 m
    # steps rarely graze obstacles; fall back to the plain traversable graph near walls.
    roomy = GridGraph(sim.clearance >= sim.config.robot_radius + 0.10, sim.house.nav.resolution)
    tight = house_graph(sim.house, sim.config.robot_radius)
    frame = sim.reset(_start_pose(sim, rng))
    yield 0, DiscreteAction.STOP, frame
    nav = sim.house.nav
    field = None
    target = None
    for step in range(1, steps + 1):
        here = sim.pose.xy
        if target is None or np.linalg.norm(here - target) < 0.3:
            cell = nav.world_to_cell(here)
            graph = roomy if nav.in_bounds(cell) and roomy.mask[cell[0], cell[1]] else tight
            if not (nav.in_bounds(cell) and graph.mask[cell[0], cell[1]]):
                graph = tight
                cell = nav.world_to_cell(sim.nearest_free(here) if sim.nearest_free(here)
                                         is not None else here)
            d = graph.multi_source(cell[None, :], np.zeros(1))
            reach = np.argwhere(np.isfinite(d) & (d > 1.5))
            if len(reach) == 0:
                reach = np.argwhere(np.isfinite(d))
            if len(reach) == 0:
                reach = cell[None, :]
            rc = reach[int(rng.integers(len(reach)))]
            target = nav.cell_to_world(rc)
            field = graph.multi_source(rc[None, :], np.zeros(1))
        # Follow the descent of the distance-to-target field for ~0.5 m.
        rc = nav.world_to_cell(here)
        look = here
        if nav.in_bounds(rc) and np.isfinite(field[rc[0], rc[1]]):
            for _ in range(10):
                best = None
                for dr in (-1, 0, 1):
                    for dc in (-1, 0, 1):
                        r, c = rc[0] + dr, rc[1] + dc
                        if 0 <= r < field.shape[0] and 0 <= c < field.shape[1] and \
                                field[r, c] < (field[best[0], best[1]] if best is not None
                                               else field[rc[0], rc[1]]):
                            best = (r, c)
                if best is None:
                    break
                rc = np.array(best)
            look = nav.cell_to_world(rc)
        else:
            look = target
        delta = look - here
        heading = math.atan2(delta[1], delta[0]) if np.linalg.norm(delta) > 1e-6 else sim.pose.yaw
        err = wrap_angle(heading - sim.pose.yaw)
        if abs(err) > math.radians(sim.config.turn_deg) / 2:
            action = DiscreteAction.TURN_LEFT if err > 0 else DiscreteAction.TURN_RIGHT
        else:
            action = DiscreteAction.MOVE_FORWARD
        frame = sim.step(action)
        if sim.collided:
            target = None  # pick another goal rather than pushing into the obstacle
        yield step, action, frame


def sim(
    house: Annotated[str, typer.Option(
        "--house", help="procthor:val/N, procthor:train/N, gibson:Scene, or a file")
    ] = "procthor:val/3",
    steps: Annotated[int, typer.Option("--steps", min=1, help="number of actions")] = 100,
    record: Annotated[Path | None, typer.Option(
        "--record", help="write a Rerun recording (.rrd) here")] = None,
    seed: Annotated[int, typer.Option("--seed", help="seed of the scripted walk")] = 0,
) -> None:
    """Walk a scripted path through a house; optionally record RGB, depth, instances, pose
    and the top-down map to a Rerun .rrd file."""
    from hiconav.sim.houses import load_house
    from hiconav.sim.simulator import Simulator

    h = load_house(house)
    simulator = Simulator(h, seed=seed)
    recorder = None
    if record is not None:
        from hiconav.sim.record import SimRecorder

        recorder = SimRecorder(record, h)
    collisions = 0
    try:
        for step, _action, frame in scripted_walk(simulator, steps, seed):
            collisions += int(simulator.collided and step > 0)
            if recorder is not None:
                recorder.log_frame(frame, step)
    finally:
        if recorder is not None:
            recorder.close()
        simulator.close()
    p = simulator.pose
    typer.echo(f"{h.name}: {len(h.objects)} objects, {steps} steps, path "
               f"{simulator.path_length:.2f} m, {collisions} collisions, final pose "
               f"({p.x:.2f}, {p.y:.2f}, {math.degrees(p.yaw):.0f} deg)"
               + (f"; recording: {record}" if record is not None else ""))
