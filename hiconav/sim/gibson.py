"""Gibson top-down semantic maps (SemExp / L3MVN ``train_info.pbz2``) -> ``House``.

Each floor is a (16, H, W) 0/1 map at 5 cm: channel 0 is the navigable floor (cleaned of
scan speckle, see ``clean_floor``), channels 1-15
the categories in ``CHANNEL_CATEGORIES``. Every 8-connected component of a category channel
becomes one object instance, extruded between a typical bottom and top height per category
(``EXTRUSION``; footprints have no heights in the source). All other (non-navigable, non-object)
cells are split by ``split_clutter``: the ones connected to the map's outside are walls of the
full wall height; small islands enclosed by floor are unlabelled furniture (tables, cabinets,
the clutter around a dining set), extruded to ``CLUTTER_HEIGHT`` with a top face. Only their
faces that border the floor or an object are rendered (merged along straight runs), which keeps
the mesh small. (Drawn as full-height walls, those islands hid the chairs and plants standing
inside them from every viewpoint, though a robot in the real home sees over a table.)

Coordinates (data README): a Habitat position (x_h, y_h, z_h) (y up, right-handed) lies in
cell row = int((x_h - origin[1]/100) * 20), col = int((z_h - origin[0]/100) * 20). Our grid
rows run along world y and columns along world x, so the world point is
(x, y, z) = (z_h, x_h, y_h - floor_height): a cyclic permutation, hence right-handed, and the
map is used as is with grid origin (origin[0]/100, origin[1]/100) metres.

This module reads the map file and builds a ``House``; it must not render or simulate.
"""

from __future__ import annotations

import bz2
import math
import pickle
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage

from hiconav.errors import DataError
from hiconav.sim.house import House, NavGrid, QuadSet, SimObject, mask_side_quads
from hiconav.sim.procthor import category_color

RESOLUTION = 0.05
WALL_HEIGHT = 2.6  # m
# Habitat's agent radius in the Gibson ObjectNav task (SemExp's objectnav_gibson.yaml): the
# navmesh of channel 0 keeps the agent's centre this far from every obstacle.
HABITAT_AGENT_RADIUS = 0.18  # m
FLOOR_TOLERANCE = 0.5  # m: a start this close to a floor's floor_height is on it (SemExp floor_thr)

# Channel k (1-based) of sem_map -> category (Habitat names mapped to ours).
CHANNEL_CATEGORIES = ("chair", "sofa", "plant", "bed", "toilet", "tv", "dining_table", "oven",
                      "sink", "fridge", "book", "clock", "vase", "cup", "bottle")
# The Habitat/Gibson ObjectNav names of the 6 goal categories (episode object_id indexes this).
HABITAT_GOAL_NAMES = ("chair", "couch", "potted plant", "bed", "toilet", "tv")
HABITAT_TO_CATEGORY = {"chair": "chair", "couch": "sofa", "potted plant": "plant",
                       "potted_plant": "plant", "bed": "bed", "toilet": "toilet", "tv": "tv",
                       "tv_monitor": "tv", "dining-table": "dining_table",
                       "dining table": "dining_table", "refrigerator": "fridge", "oven": "oven",
                       "sink": "sink", "book": "book", "clock": "clock", "vase": "vase",
                       "cup": "cup", "bottle": "bottle", "sofa": "sofa", "plant": "plant"}
# (bottom, top) metres above the floor: typical heights of each category (assumption).
EXTRUSION = {
    "chair": (0.0, 0.9), "sofa": (0.0, 0.85), "plant": (0.0, 0.9), "bed": (0.0, 0.6),
    "toilet": (0.0, 0.75), "tv": (0.5, 1.2), "dining_table": (0.0, 0.76), "oven": (0.0, 0.9),
    "sink": (0.0, 0.9), "fridge": (0.0, 1.8), "book": (0.75, 0.95), "clock": (1.6, 1.9),
    "vase": (0.75, 1.05), "cup": (0.75, 0.85), "bottle": (0.75, 1.0),
}
EIGHT = np.ones((3, 3), dtype=bool)
SPECKLE_CELLS = 30  # enclosed non-floor holes smaller than this (0.075 m^2) are scan noise
CLUTTER_HEIGHT = 0.8  # m: unlabelled furniture islands (assumption: table / cabinet height)
MAX_FURNITURE_M2 = 6.0  # larger enclosed islands are walls (a room's inner walls, a stairwell)


def split_clutter(clutter: np.ndarray, res: float = RESOLUTION) -> tuple[np.ndarray, np.ndarray]:
    """(walls, furniture) masks of the non-floor, non-object cells: an 8-connected component is
    furniture when it touches no map edge (enclosed by floor) and covers at most
    ``MAX_FURNITURE_M2``; everything else is wall."""
    labels, n = ndimage.label(clutter, structure=EIGHT)
    if n == 0:
        return clutter.copy(), np.zeros_like(clutter)
    sizes = np.bincount(labels.ravel(), minlength=n + 1)
    edge = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
    furniture_label = sizes * res * res <= MAX_FURNITURE_M2
    furniture_label[edge] = False
    furniture_label[0] = False
    furniture = furniture_label[labels]
    return clutter & ~furniture, furniture


def load_info(path: str | Path) -> dict[str, Any]:
    """The decompressed ``{scene: {floor: {sem_map, origin, floor_height}}}`` of a maps file,
    read once per process however the path is spelled (cached on the resolved path)."""
    return _load_info(str(Path(path).expanduser().resolve()))


@lru_cache(maxsize=2)
def _load_info(path: str) -> dict[str, Any]:
    try:
        with bz2.BZ2File(path) as fh:
            info = pickle.load(fh)
    except (OSError, EOFError, pickle.UnpicklingError, ValueError) as exc:
        raise DataError(f"cannot read the Gibson maps: {exc}", file=path) from exc
    if not isinstance(info, dict):
        raise DataError("expected a dict {scene: {floor: ...}}", file=path)
    return info


def info_path(data_dir: Path) -> str:
    return str(data_dir / "gibson" / "train_info.pbz2")


def scene_names(data_dir: Path) -> list[str]:
    return sorted(load_info(info_path(data_dir)))


def habitat_to_world(pos: np.ndarray, floor_height: float = 0.0) -> np.ndarray:
    """Habitat (..., 3) (x_h, y_h, z_h) -> world (..., 3) (z_h, x_h, y_h - floor_height)."""
    p = np.asarray(pos, dtype=np.float64)
    return np.stack([p[..., 2], p[..., 0], p[..., 1] - floor_height], axis=-1)


def habitat_yaw(quat_xyzw: np.ndarray) -> float:
    """World yaw (rad) of a Habitat agent rotation quaternion [x, y, z, w].

    The agent looks along -z_h; we rotate that vector by the quaternion and express it in the
    world frame (x = z_h, y = x_h).
    """
    x, y, z, w = (float(v) for v in quat_xyzw)
    v = np.array([0.0, 0.0, -1.0])
    q = np.array([x, y, z])
    t = 2.0 * np.cross(q, v)
    r = v + w * t + np.cross(q, t)
    return math.atan2(r[0], r[2])


def floor_record(maps_file: Path | str, scene: str, floor: int) -> dict[str, Any]:
    """The record of one floor of a maps file."""
    path = str(maps_file)
    info = load_info(path)
    if scene not in info:
        raise DataError(f"unknown Gibson scene '{scene}'; valid: {', '.join(sorted(info))}",
                        file=path)
    floors = info[scene]
    if floor not in floors:
        raise DataError(f"scene {scene} has no floor {floor}; floors: {sorted(floors)}",
                        file=path, field=f"{scene}")
    rec = floors[floor]
    for key in ("sem_map", "origin"):
        if key not in rec:
            raise DataError(f"missing field '{key}'", file=path, field=f"{scene}.{floor}.{key}")
    sem = np.asarray(rec["sem_map"])
    if sem.ndim != 3 or sem.shape[0] != 16:
        raise DataError(f"sem_map must have shape (16, H, W), got {sem.shape}", file=path,
                        field=f"{scene}.{floor}.sem_map")
    return rec


def component_counts(sem_map: np.ndarray) -> list[int]:
    """Number of 8-connected components of each category channel 1..15."""
    return [int(ndimage.label(sem_map[k] > 0, structure=EIGHT)[1]) for k in range(1, 16)]


def clean_floor(floor: np.ndarray, objects: np.ndarray) -> np.ndarray:
    """(H, W) bool navigable floor with the scan's speckle removed.

    In several scans (Klickitat, Lakeville, Woodbine, ...) channel 0 is a sparse projection
    of the floor: isolated missing cells everywhere, so no 0.36 m robot would fit anywhere.
    We apply one 3x3 binary closing (fills gaps of at most 2 cells, 10 cm, so walls of the
    map, which are thicker, stay closed) and fill enclosed non-floor holes smaller than
    ``SPECKLE_CELLS``; object cells are never made navigable.
    """
    closed = ndimage.binary_closing(floor, structure=EIGHT, iterations=1, border_value=0)
    closed |= floor
    closed &= ~objects
    labels, _ = ndimage.label(~closed)
    sizes = np.bincount(labels.ravel())
    small = sizes < SPECKLE_CELLS
    small[0] = False
    return (closed | small[labels]) & ~objects


def floor_for_height(maps_file: Path | str, scene: str, height: float) -> int | None:
    """The floor of ``scene`` whose ``floor_height`` is nearest the Habitat height ``height`` (m),
    within ``FLOOR_TOLERANCE`` (SemExp's ``floor_thr``, 0.5 m); None when no floor is that close
    (the position lies on a floor the maps file does not hold)."""
    floors = load_info(maps_file).get(scene) or {}
    best, gap = None, FLOOR_TOLERANCE
    for index in sorted(floors):
        rec = floors[index]
        if not isinstance(rec, dict):
            continue
        d = abs(float(rec.get("floor_height", 0.0)) - float(height))
        if d <= gap:
            best, gap = int(index), d
    return best


def floor_heights(maps_file: Path | str, scene: str) -> str:
    """"0 at 0.00 m, 1 at 3.10 m": the floors of ``scene`` for messages."""
    floors = load_info(maps_file).get(scene) or {}
    return ", ".join(f"{k} at {float(v.get('floor_height', 0.0)):.2f} m" for k, v in sorted(floors.items())
                     if isinstance(v, dict)) or "none"


def render_obstacles(nav_mask: np.ndarray, objects: np.ndarray, radius: float = HABITAT_AGENT_RADIUS,
                     res: float = RESOLUTION) -> np.ndarray:
    """(H, W) bool cells where walls and unlabelled furniture are drawn.

    Habitat's navmesh (channel 0) stops ``radius`` short of every wall and piece of furniture, so
    the obstacles stand about that far beyond its edge: a cell is drawn when its centre lies
    farther than ``radius`` plus half a cell from the nearest navmesh cell's centre (the navmesh's
    edge runs through its edge cells), so that a map of what the robot sees, inflated by the
    robot's radius, leaves the navmesh free. A band of non-navigable cells too thin to hold such a cell (a
    thin inner wall, a doorway's jamb) keeps its ridge cells (those no nearer the navmesh than any
    neighbour), so that no wall between two rooms disappears from view, and a gap the navmesh does
    not pass through is drawn across (``closed_necks``), so that it does not look open either.
    """
    return ~nav_mask & ~objects & beyond_radius(nav_mask, radius, res)


def beyond_radius(nav_mask: np.ndarray, radius: float = HABITAT_AGENT_RADIUS,
                  res: float = RESOLUTION) -> np.ndarray:
    """(H, W) bool cells whose centre lies farther than ``radius`` plus half a cell from the
    nearest navmesh cell's centre, or on a ridge (no nearer the navmesh than any neighbour):
    where an obstacle stands in the world of a navmesh that keeps the agent's centre ``radius``
    from it (``render_obstacles`` draws walls there, ``load_gibson_file`` labelled objects)."""
    dist = ndimage.distance_transform_edt(~nav_mask) * res
    ridge = dist >= ndimage.maximum_filter(dist, size=3) - 1e-9
    return (dist > radius + res / 2.0 + 1e-9) | ridge | closed_necks(nav_mask, dist, radius, res)


def closed_necks(nav_mask: np.ndarray, dist: np.ndarray, radius: float = HABITAT_AGENT_RADIUS,
                 res: float = RESOLUTION) -> np.ndarray:
    """(H, W) bool non-navigable cells within ``radius`` of the navmesh that separate it: the
    navmesh cells within ``radius`` plus a cell of them fall apart into two or more pieces of a
    disc radius's cells or more there (a smaller piece is a jag of the navmesh's outline).

    The navmesh stops short of a gap too narrow for the agent (between a pillar and a wall, two
    table legs, a door ajar), and nothing in the maps stands in the gap: the cells there are
    nearer the navmesh than any obstacle would stand, so without this the gap looks open to the
    robot while the agent cannot pass it. At a plain wall or corner the navmesh within the disc
    is one piece; across a closed gap it is two.
    """
    r = int(math.ceil((radius + res) / res))
    # only the gap's middle line is drawn: cells no nearer the navmesh than their two neighbours
    # along some axis and farther than one of them (a saddle's crest; a band's edge cells are not)
    pad_d = np.pad(dist, 1, mode="edge")
    h, w = dist.shape
    crest = np.zeros_like(nav_mask, dtype=bool)
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        a = pad_d[1 + dr:1 + dr + h, 1 + dc:1 + dc + w]
        b = pad_d[1 - dr:1 - dr + h, 1 - dc:1 - dc + w]
        crest |= (dist >= a - 1e-9) & (dist >= b - 1e-9) & ((dist > a + 1e-9) | (dist > b + 1e-9))
    band = ~nav_mask & (dist <= radius + res / 2.0 + 1e-9) & crest
    out = np.zeros_like(nav_mask, dtype=bool)
    rows, cols = np.nonzero(band)
    if len(rows) == 0:
        return out
    yy, xx = np.mgrid[-r:r + 1, -r:r + 1]
    disc = yy ** 2 + xx ** 2 <= r * r
    pad = np.pad(nav_mask, r, constant_values=False)
    for i, j in zip(rows.tolist(), cols.tolist()):
        labels, n = ndimage.label(pad[i:i + 2 * r + 1, j:j + 2 * r + 1] & disc, structure=EIGHT)
        if n >= 2 and int(np.sum(np.bincount(labels.ravel())[1:] >= r)) >= 2:
            out[i, j] = True
    return out


def load_gibson(scene: str, floor: int, data_dir: Path) -> House:
    """Build the ``House`` of one Gibson floor of the data root's maps file."""
    return load_gibson_file(Path(info_path(data_dir)), scene, floor,
                            name=f"gibson:{scene}" if floor == 0 else f"gibson:{scene}/{floor}")


def load_gibson_file(path: Path | str, scene: str, floor: int, *, name: str | None = None) -> House:
    """Build the ``House`` of one floor of any SemExp / L3MVN maps file (``*_info.pbz2``), named
    ``<path>#<scene>/<floor>`` unless ``name`` is given."""
    path = Path(path)
    rec = floor_record(path, scene, floor)
    sem = np.asarray(rec["sem_map"]) > 0
    origin = np.asarray(rec["origin"], dtype=np.float64) / 100.0  # (x_w, y_w) = (z_h, x_h)
    floor_height = float(rec.get("floor_height", 0.0))
    nav_mask = sem[0]
    objects: list[SimObject] = []
    quads: list[QuadSet] = []
    footprints: dict[int, np.ndarray] = {}
    any_object = sem[1:16].any(axis=0)
    nav_mask = clean_floor(nav_mask, any_object)
    # where an obstacle may stand (``beyond_radius``): the walls and clutter, and the labelled
    # objects, whose cells reach right up to the navmesh where the scan's projection of an object
    # is wider than what blocks the agent (about a tenth of the object cells of the 25 floors; drawn
    # whole, they closed corridors the agent passes); an object's every cell still scores success
    solid = beyond_radius(nav_mask)
    drawn_objects = np.zeros_like(nav_mask)
    for k, cat in enumerate(CHANNEL_CATEGORIES, start=1):
        labels, n = ndimage.label(sem[k], structure=EIGHT)
        if n == 0:
            continue
        z0, z1 = EXTRUSION[cat]
        slices = ndimage.find_objects(labels)
        for lab, sl in enumerate(slices, start=1):
            window = labels[sl] == lab
            rr, cc = np.nonzero(window)
            rr = rr + sl[0].start
            cc = cc + sl[1].start
            iid = len(objects)
            x0 = origin[0] + sl[1].start * RESOLUTION
            x1 = origin[0] + sl[1].stop * RESOLUTION
            y0 = origin[1] + sl[0].start * RESOLUTION
            y1 = origin[1] + sl[0].stop * RESOLUTION
            objects.append(SimObject(
                iid, cat, np.array([(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2]),
                np.array([x1 - x0, y1 - y0, z1 - z0]), 0.0, f"sem_map[{k}]"))
            cells = np.stack([rr, cc], axis=1).astype(np.int64)
            cells.flags.writeable = False
            footprints[iid] = cells
            win_origin = np.array([x0, y0])
            shade = 0.85 + 0.3 * ((iid * 0.6180339) % 1.0)
            color = tuple(np.clip(np.array(category_color(cat)) * shade, 0, 1))
            drawn = window & solid[sl]
            drawn = drawn if drawn.any() else window  # never hidden whole
            drawn_objects[sl] |= drawn
            quads.append(mask_side_quads(drawn, win_origin, RESOLUTION, z0, z1, color, iid,
                                         "object", top=True))
    # Walls / clutter: every other cell, drawn as the vertical faces that border the floor
    # or an object (the only faces visible from the floor; the ceiling covers their tops), one
    # agent radius beyond the navmesh's edge (``render_obstacles``).
    walls, furniture = split_clutter(~(nav_mask | any_object))
    drawn = ~nav_mask & ~any_object & solid  # ``render_obstacles``
    walls &= drawn
    furniture &= drawn
    quads.append(mask_side_quads(walls, origin, RESOLUTION, 0.0, WALL_HEIGHT,
                                 (0.8, 0.78, 0.74), material="wall"))
    quads.append(mask_side_quads(furniture, origin, RESOLUTION, 0.0, CLUTTER_HEIGHT,
                                 (0.55, 0.45, 0.35), material="wall", top=True))
    # The navigable grid is the floor free of drawn obstacles and objects; the robot's centre
    # may stand on the navmesh alone (``House.centre_free``), as in Habitat.
    nav = NavGrid(~(walls | furniture | drawn_objects), origin, RESOLUTION)
    centre = nav_mask.copy()
    centre.flags.writeable = False
    return House(name=name or f"{path.resolve()}#{scene}/{floor}", objects=objects, nav=nav, rooms=[],
                 boxes=[], quads=QuadSet.concat(quads),
                 footprints=footprints, wall_height=WALL_HEIGHT,
                 floor_color=(0.5, 0.47, 0.42), source=str(path),
                 floor_height=floor_height, sight_walls=walls, centre_free=centre,
                 success_rule="semexp")
