"""ObjectNav episodes: a seeded generator for any house and a reader for Habitat episode files.

An episode = start pose on free floor that is connected to a goal instance of the target
category, the goal instance ids (every instance of that category in the house), the geodesic
start-to-goal distance and an instruction ("find the bed"). Generation is deterministic per
(house, n, seed). This module builds episodes; it must not run them (see ``metrics``).
"""

from __future__ import annotations

import gzip
import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hiconav.errors import DataError
from hiconav.sim.geodesic import GoalDistance, distance_mask, driving_pieces, house_graph, reaching_pieces
from hiconav.sim.house import House
from hiconav.sim.viewpoints import MIN_VIEW_PIXELS, viewable_instances
from hiconav.types import Pose2D

# Categories a user would ask for (Habitat's six first, then ProcTHOR furniture/appliances).
TARGET_CATEGORIES: tuple[str, ...] = (
    "chair", "sofa", "bed", "toilet", "tv", "plant",
    "dining_table", "fridge", "sink", "laptop", "armchair", "desk", "dresser", "microwave",
    "toaster", "coffee_machine", "washing_machine", "clothes_dryer", "floor_lamp", "desk_lamp",
    "side_table", "tv_stand", "shelving_unit", "garbage_can", "oven", "bathtub", "stool",
    "safe", "teddy_bear", "statue", "vase", "painting", "laundry_hamper", "dog_bed",
)


# What decides a generated episode besides (house, n, seed); an eval output folder records it, so
# that results of episodes generated under other rules are never resumed as if they were these.
EPISODE_RULES = ("goals: instances with >= 150 px from a view point; footprints at least one cell wide; "
                 "gibson: SemExp's protocol (channel 0 is the centre's free space, fast marching, "
                 "visible instances of the category, start 1.5-100 m)")


SEMEXP_MAX_DISTANCE = 100.0  # m: SemExp's max_d for generated Gibson episodes

# Gibson ObjectNav v1.1 uses only these six goal categories (data README).
GIBSON_GOAL_CATEGORIES: tuple[str, ...] = ("chair", "sofa", "plant", "bed", "toilet", "tv")


@dataclass(frozen=True)
class Episode:
    """One ObjectNav episode (world frame; distances in metres)."""

    episode_id: str
    house: str
    start: Pose2D
    target: str
    goal_instance_ids: tuple[int, ...]
    geodesic_distance: float
    instruction: str
    task: str = "objectnav"  # objectnav | ovon | textnav (hiconav.sim.task_episodes)

    def to_json(self) -> dict[str, Any]:
        d = asdict(self)
        d["start"] = [self.start.x, self.start.y, self.start.yaw]
        d["goal_instance_ids"] = list(self.goal_instance_ids)
        if self.task == "objectnav":  # ObjectNav episodes are written as they always were
            d.pop("task")
        return d


def instruction_for(category: str) -> str:
    return f"find the {category.replace('_', ' ')}"


def _resolve(house: House | str) -> House:
    if isinstance(house, House):
        return house
    from hiconav.sim.houses import load_house

    return load_house(house)


def generate_episodes(house: House | str, n: int, seed: int = 0, *, radius: float = 0.18,
                      min_distance: float = 1.5, max_distance: float = 30.0,
                      categories: tuple[str, ...] | None = None,
                      min_view_pixels: int | None = MIN_VIEW_PIXELS,
                      success_distance: float | None = None) -> list[Episode]:
    """``n`` episodes in ``house``; deterministic for a given (house, n, seed).

    The target is drawn uniformly among the categories in ``categories`` (default
    ``GIBSON_GOAL_CATEGORIES`` for Gibson houses, as in Gibson ObjectNav, else
    ``TARGET_CATEGORIES``) that are present, visible and reachable; the start is a uniformly drawn free
    cell whose geodesic distance to the target lies in [min_distance, max_distance], with a
    uniform yaw. Raises ``DataError`` if the house has no reachable target category. Under the
    "semexp" success rule (Gibson) ``max_distance`` is at least 100 m, as in SemExp's generator.

    Goal instances are only those a camera sees: at least ``min_view_pixels`` pixels in a view
    from one of their view points (``viewpoints.viewable_instances``, as Habitat's ObjectNav
    keeps only goals with view points). An object drawn inside its receptacle's box shows in no
    pixel from anywhere; a category whose every instance is hidden is not drawn. ``None`` skips
    the check (every instance is a goal, as before the check existed).

    Under "semexp", distances are measured on SemExp's 2-cell dilation of the navmesh, which
    bridges gaps the robot cannot drive through; a start is drawn only where the robot's own
    free space (the navmesh, 8-connected) joins a goal's success region (``success_distance``
    m, default the simulator's), as Habitat's generator keeps only starts with a navmesh path to the goal.
    """
    house = _resolve(house)
    semexp = house.success_rule == "semexp"
    allowed = categories or (GIBSON_GOAL_CATEGORIES if semexp else TARGET_CATEGORIES)
    if semexp:
        # SemExp's generator (objectgoal_env.generate_new_episode): the start lies 1.5-100 m (its
        # min_d, max_d) from the goal. Its goal is every cell of the category; ours keeps the
        # instances a camera sees, as for ProcTHOR: a room the navmesh lacks (a bathroom whose floor
        # is missing from channel 0) is drawn as a solid block, and the toilet in it shows in no
        # pixel from anywhere, though Habitat renders it
        max_distance = max(max_distance, SEMEXP_MAX_DISTANCE)
    present = sorted(c for c in house.categories if c in allowed)
    rng = np.random.default_rng(seed)
    fields: dict[str, tuple[GoalDistance, np.ndarray]] = {}
    usable: list[str] = []
    graph = house_graph(house, radius)
    pieces = driving_pieces(graph.mask) if semexp else None
    if success_distance is None:
        from hiconav.sim.config import SimConfig

        success_distance = SimConfig().success_distance
    sim = None
    if min_view_pixels is not None:
        from hiconav.sim.simulator import Simulator

        sim = Simulator(house)
    try:
        for cat in present:
            ids = tuple(o.instance_id for o in house.instances_of(cat))
            if sim is not None:
                ids = viewable_instances(house, ids, sim, min_pixels=min_view_pixels)
                if not ids:
                    continue
            gd = GoalDistance(house, instance_ids=ids, radius=radius)
            ok = graph.mask & np.isfinite(gd.field) & (gd.field >= min_distance) & \
                (gd.field <= max_distance)
            if pieces is not None:
                ok &= reaching_pieces(pieces, gd.success_region(success_distance))
            cells = np.argwhere(ok)
            if len(cells):
                fields[cat] = (gd, cells)
                usable.append(cat)
    finally:
        if sim is not None:
            sim.close()
    if not usable:
        raise DataError(f"{house.name} has no reachable target category that a camera can see "
                        f"(present: {', '.join(sorted(house.categories)) or 'none'})", field="target")
    episodes = []
    for i in range(n):
        cat = usable[int(rng.integers(len(usable)))]
        gd, cells = fields[cat]
        rc = cells[int(rng.integers(len(cells)))]
        xy = house.nav.cell_to_world(rc)
        yaw = float(rng.uniform(-math.pi, math.pi))
        episodes.append(Episode(
            episode_id=f"{house.name}#{seed}-{i}", house=house.name,
            start=Pose2D(float(xy[0]), float(xy[1]), yaw), target=cat,
            goal_instance_ids=gd.instance_ids, geodesic_distance=float(gd.field[rc[0], rc[1]]),
            instruction=instruction_for(cat)))
    return episodes


def load_habitat_episodes(path: str | Path, house: House | str, *,
                          radius: float = 0.18) -> list[Episode]:
    """Read a Habitat ObjectNav ``*_episodes.json(.gz)`` file for one (Gibson) house.

    Positions are converted with the Gibson mapping (world = (z_h, x_h, y_h - floor_height),
    see ``gibson.py``). Episodes of other scenes (``scene_id`` basename) or of other floors are
    skipped; an episode's floor is the one whose ``floor_height`` lies within 0.5 m of its
    start's height (SemExp's floor rule; ``floor_id`` only for houses without one). A start
    outside the map or off the traversable area, a goal category with no reachable instance, a
    missing field or an unknown category raises ``DataError`` naming the file and field.
    """
    from hiconav.sim.gibson import (
        FLOOR_TOLERANCE,
        HABITAT_GOAL_NAMES,
        HABITAT_TO_CATEGORY,
        habitat_to_world,
        habitat_yaw,
    )

    house = _resolve(house)
    path = Path(path)
    try:
        opener = gzip.open if path.suffix == ".gz" else open
        with opener(path, "rt", encoding="utf-8") as fh:
            data = json.load(fh)
    except json.JSONDecodeError as exc:
        raise DataError(f"malformed episode JSON: {exc.msg}", file=str(path),
                        line=exc.lineno) from exc
    except OSError as exc:
        raise DataError(f"cannot read episode file: {exc}", file=str(path)) from exc
    if not isinstance(data, dict) or not isinstance(data.get("episodes"), list):
        raise DataError("expected an object with an 'episodes' list", file=str(path),
                        field="episodes")
    # "gibson:Scene/floor" or "<maps file>#Scene/floor"
    tail = house.name.rpartition("#")[2] if "#" in house.name else house.name.split(":", 1)[-1]
    scene, _, floor_text = tail.partition("/")
    floor = int(floor_text) if floor_text.isdigit() else 0
    out: list[Episode] = []
    nav = house.nav
    for i, ep in enumerate(data["episodes"]):
        where = f"episodes[{i}]"
        try:
            scene_id = str(ep["scene_id"])
            ep_scene = Path(scene_id).name.split(".")[0]
            if ep_scene != scene:
                continue
            pos = np.asarray(ep["start_position"], dtype=np.float64)
            if pos.shape == (3,) and house.centre_free is not None:
                # the floor is the one whose height matches the start's (SemExp's floor_thr)
                if abs(float(pos[1]) - house.floor_height) > FLOOR_TOLERANCE:
                    continue
            elif "floor_id" in ep and ep["floor_id"] is not None and int(ep["floor_id"]) != floor:
                continue
            quat = np.asarray(ep["start_rotation"], dtype=np.float64)
        except (KeyError, TypeError, ValueError) as exc:
            raise DataError(f"missing or invalid field {exc}", file=str(path),
                            field=where) from exc
        if pos.shape != (3,) or quat.shape != (4,):
            raise DataError("start_position must be [x, y, z] and start_rotation [x, y, z, w]",
                            file=str(path), field=f"{where}.start_position")
        world = habitat_to_world(pos, house.floor_height)
        rc = nav.world_to_cell(world[:2])
        if not nav.in_bounds(rc):
            raise DataError(
                f"start {pos.tolist()} maps to cell {rc.tolist()} outside the {nav.shape} map "
                f"of {house.name}", file=str(path), field=f"{where}.start_position")
        name = ep.get("object_category")
        if name is None and "object_id" in ep:
            k = int(ep["object_id"])
            if not 0 <= k < len(HABITAT_GOAL_NAMES):
                raise DataError(f"object_id {k} is not in 0..5", file=str(path),
                                field=f"{where}.object_id")
            name = HABITAT_GOAL_NAMES[k]
        category = HABITAT_TO_CATEGORY.get(str(name)) if name is not None else None
        if category is None:
            raise DataError(f"unknown object category {name!r}", file=str(path),
                            field=f"{where}.object_category")
        ids = tuple(o.instance_id for o in house.instances_of(category))
        if not ids:
            raise DataError(f"{house.name} has no '{category}' instance", file=str(path),
                            field=f"{where}.object_category")
        gd = GoalDistance(house, instance_ids=ids, radius=radius)
        distance = gd.distance(world[:2])
        if not math.isfinite(distance):
            free = distance_mask(house, radius)
            reason = (f"start {pos.tolist()} (cell {rc.tolist()}) is not on the traversable area of {house.name}"
                      if not free[rc[0], rc[1]] else
                      f"no '{category}' of {house.name} is reachable from the start {pos.tolist()}")
            raise DataError(reason, file=str(path), field=f"{where}.start_position")
        out.append(Episode(
            episode_id=str(ep.get("episode_id", i)), house=house.name,
            start=Pose2D(float(world[0]), float(world[1]), habitat_yaw(quat)), target=category,
            goal_instance_ids=ids, geodesic_distance=distance,
            instruction=instruction_for(category)))
    return out
