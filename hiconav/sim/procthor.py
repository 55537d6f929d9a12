"""ProcTHOR house JSON -> the simulator's ``House`` (walls with holes, objects, rooms, grid).

Coordinate conversion (documented once, used everywhere): ProcTHOR/Unity is LEFT-handed with
y up and the floor on x/z. We map a ProcTHOR point (x_p, y_p, z_p) to the world point
(x, y, z) = (x_p, z_p, y_p). Swapping two axes flips handedness, so the world frame is
right-handed (x east, y north, z up) and the top view keeps the physical, unmirrored layout.
A Unity yaw ``rotation.y`` (degrees, clockwise seen from above) becomes the world yaw
``-radians(rotation.y)`` (counter-clockwise); an asset's bounding box (bx, by, bz) becomes the
world box size (bx, bz, by).

Object sizes come from ``asset-database.json`` (``objectType -> [{assetId, boundingBox}]``).
Objaverse objects (``objectType`` starting with "Obja", no entry in the database) get a small
default box of ``OBJAVERSE_DEFAULT_SIZE`` metres centred on their position (a labelled
fallback: ``SimObject.default_size`` is True). Nested ``children`` are loaded as separate
instances (depth first, parent before children).

This module reads files and builds a ``House``; it must not render or simulate.
"""

from __future__ import annotations

import gzip
import json
import math
import re
from dataclasses import replace
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from hiconav.errors import DataError
from hiconav.sim.house import House, Room, SimObject, Wall, assemble_house

MAX_WALL_SHIFT = 0.08  # m: larger intrusions into a wall slab are left alone (not a wall-mounted object)

RESOLUTION = 0.05
WALL_THICKNESS = 0.10  # m; ProcTHOR walls are zero-thickness planes, we give them a slab.
OBJAVERSE_DEFAULT_SIZE = (0.3, 0.3, 0.3)  # m (x, y, z): fallback box of Objaverse decor
GRID_PAD = 0.3  # m around the union of room polygons

# ProcTHOR objectType -> our category where snake case is not what users say.
CATEGORY_ALIASES = {
    "television": "tv",
    "house_plant": "plant",
    "potted_plant": "plant",
    "arm_chair": "armchair",
    "t_v_stand": "tv_stand",
    "refrigerator": "fridge",
    "couch": "sofa",
}


def snake_case(name: str) -> str:
    """"DiningTable" -> "dining_table", "TVStand" -> "tv_stand"."""
    s = re.sub(r"([A-Z]+)([A-Z][a-z])", r"\1_\2", name)
    s = re.sub(r"([a-z0-9])([A-Z])", r"\1_\2", s)
    return s.lower()


def category_of(object_type: str) -> str:
    """Our lowercase category of a ProcTHOR ``objectType`` (Objaverse prefix dropped)."""
    base = object_type[4:] if object_type.startswith("Obja") and len(object_type) > 4 else \
        object_type
    cat = snake_case(base)
    return CATEGORY_ALIASES.get(cat, cat)


def category_color(category: str) -> tuple[float, float, float]:
    """A stable, mid-saturation colour per category (RGB in [0, 1])."""
    import colorsys
    import zlib

    h = zlib.crc32(category.encode()) / 2**32
    s = 0.35 + 0.3 * ((zlib.crc32(category.encode(), 7) % 1000) / 1000.0)
    return colorsys.hsv_to_rgb(h, s, 0.75)


@lru_cache(maxsize=4)
def asset_sizes(path: str) -> dict[str, tuple[float, float, float]]:
    """assetId -> bounding box (x, y, z) in Unity axes, from asset-database.json (cached)."""
    try:
        with open(path, encoding="utf-8") as fh:
            db = json.load(fh)
    except json.JSONDecodeError as exc:
        raise DataError(f"malformed JSON: {exc.msg}", file=path, line=exc.lineno) from exc
    except OSError as exc:
        raise DataError(f"cannot read the asset database: {exc}", file=path) from exc
    out: dict[str, tuple[float, float, float]] = {}
    for object_type, assets in db.items():
        for i, asset in enumerate(assets):
            try:
                bb = asset["boundingBox"]
                out[asset["assetId"]] = (float(bb["x"]), float(bb["y"]), float(bb["z"]))
            except (KeyError, TypeError) as exc:
                raise DataError(f"asset entry lacks {exc}", file=path,
                                field=f"{object_type}[{i}].boundingBox") from exc
    return out


@lru_cache(maxsize=4)
def split_lines(path: str) -> tuple[str, ...]:
    """The raw JSON lines of a ``*.jsonl.gz`` split (cached; parsed per house on demand)."""
    try:
        opener = gzip.open if path.endswith(".gz") else open
        with opener(path, "rt", encoding="utf-8") as fh:
            return tuple(line for line in fh.read().splitlines() if line.strip())
    except OSError as exc:
        raise DataError(f"cannot read ProcTHOR split: {exc}", file=path) from exc


def parse_json(text: str, file: str, line: int | None = None) -> dict[str, Any]:
    """json.loads with a DataError naming the file and line on failure."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise DataError(f"malformed house JSON: {exc.msg} (column {exc.colno})", file=file,
                        line=line if line is not None else exc.lineno) from exc
    if not isinstance(data, dict):
        raise DataError("a house must be a JSON object", file=file, line=line)
    return data


class _Reader:
    """Field access that names the file, line and field path in every error."""

    def __init__(self, file: str, line: int | None) -> None:
        self.file = file
        self.line = line

    def get(self, obj: Any, key: str | int, path: str) -> Any:
        try:
            return obj[key]
        except (KeyError, IndexError, TypeError):
            raise DataError(f"missing or invalid field '{key}'", file=self.file, line=self.line,
                            field=path) from None

    def num(self, obj: Any, key: str, path: str) -> float:
        value = self.get(obj, key, path)
        try:
            out = float(value)
        except (TypeError, ValueError):
            raise DataError(f"expected a number, got {value!r}", file=self.file,
                            line=self.line, field=path) from None
        if not math.isfinite(out):
            raise DataError(f"expected a finite number, got {value!r}", file=self.file,
                            line=self.line, field=path)
        return out

    def xyz(self, obj: Any, path: str) -> tuple[float, float, float]:
        """ProcTHOR {x, y, z} -> world (x, y, z) = (x_p, z_p, y_p)."""
        return (self.num(obj, "x", f"{path}.x"), self.num(obj, "z", f"{path}.z"),
                self.num(obj, "y", f"{path}.y"))


def count_objects(house_json: dict[str, Any]) -> int:
    """Number of objects in a ProcTHOR house, nested children included (source count)."""
    def walk(objs: list[dict[str, Any]]) -> int:
        return sum(1 + walk(o.get("children") or []) for o in objs)
    return walk(house_json.get("objects") or [])


def build_house(data: dict[str, Any], name: str, file: str, line: int | None,
                asset_db: str) -> House:
    """Convert one parsed ProcTHOR house JSON into a ``House``."""
    rd = _Reader(file, line)
    sizes = asset_sizes(asset_db)

    # Rooms.
    rooms: list[Room] = []
    for i, room in enumerate(rd.get(data, "rooms", "rooms")):
        poly = rd.get(room, "floorPolygon", f"rooms[{i}].floorPolygon")
        pts = np.array([rd.xyz(p, f"rooms[{i}].floorPolygon[{k}]")[:2]
                        for k, p in enumerate(poly)], dtype=np.float64)
        if len(pts) < 3:
            raise DataError("a floor polygon needs at least 3 corners", file=file, line=line,
                            field=f"rooms[{i}].floorPolygon")
        rooms.append(Room(str(rd.get(room, "id", f"rooms[{i}].id")),
                          str(room.get("roomType", "Room")), pts))
    if not rooms:
        raise DataError("the house has no rooms", file=file, line=line, field="rooms")

    # Walls: deduplicate the two sides of each wall; keep each side's id for its holes.
    walls_json = rd.get(data, "walls", "walls")
    wall_geo: dict[str, tuple[np.ndarray, np.ndarray, float]] = {}
    by_key: dict[tuple, dict[str, Any]] = {}
    for i, wall in enumerate(walls_json):
        wid = str(rd.get(wall, "id", f"walls[{i}].id"))
        poly = rd.get(wall, "polygon", f"walls[{i}].polygon")
        pts = [rd.xyz(p, f"walls[{i}].polygon[{k}]") for k, p in enumerate(poly)]
        base = [p for p in pts if abs(p[2]) < 1e-6]
        if len(pts) < 4 or len(base) < 2:
            raise DataError("a wall polygon needs two floor corners (y = 0) and two top corners",
                            file=file, line=line, field=f"walls[{i}].polygon")
        p0, p1 = np.array(base[0][:2]), np.array(base[1][:2])
        height = max(p[2] for p in pts)
        wall_geo[wid] = (p0, p1, height)
        key = tuple(sorted([tuple(np.round(p0, 2)), tuple(np.round(p1, 2))]))
        entry = by_key.setdefault(key, {"p0": p0, "p1": p1, "height": height, "ids": [],
                                        "holes": [], "color": None})
        entry["ids"].append(wid)
        entry["height"] = max(entry["height"], height)
        col = (wall.get("material") or {}).get("color")
        if col and entry["color"] is None:
            entry["color"] = (float(col.get("r", 0.85)), float(col.get("g", 0.85)),
                              float(col.get("b", 0.85)))
    id_to_key = {wid: key for key, e in by_key.items() for wid in e["ids"]}

    for kind in ("doors", "windows"):
        for i, hole in enumerate(data.get(kind) or []):
            path = f"{kind}[{i}]"
            wid = str(rd.get(hole, "wall0", f"{path}.wall0"))
            if wid not in wall_geo:
                raise DataError(f"wall0 '{wid}' is not in walls[]", file=file, line=line,
                                field=f"{path}.wall0")
            hp = rd.get(hole, "holePolygon", f"{path}.holePolygon")
            a = rd.get(hp, 0, f"{path}.holePolygon[0]")
            b = rd.get(hp, 1, f"{path}.holePolygon[1]")
            t0 = rd.num(a, "x", f"{path}.holePolygon[0].x")
            t1 = rd.num(b, "x", f"{path}.holePolygon[1].x")
            z0 = rd.num(a, "y", f"{path}.holePolygon[0].y")
            z1 = rd.num(b, "y", f"{path}.holePolygon[1].y")
            p0, p1, _ = wall_geo[wid]
            u = (p1 - p0) / max(np.linalg.norm(p1 - p0), 1e-9)
            # Hole ends in world xy, then re-expressed along the deduplicated wall.
            w0, w1 = p0 + u * min(t0, t1), p0 + u * max(t0, t1)
            entry = by_key[id_to_key[wid]]
            e0, e1 = entry["p0"], entry["p1"]
            eu = (e1 - e0) / max(np.linalg.norm(e1 - e0), 1e-9)
            s0, s1 = float(np.dot(w0 - e0, eu)), float(np.dot(w1 - e0, eu))
            entry["holes"].append((min(s0, s1), max(s0, s1), min(z0, z1), max(z0, z1)))

    walls = [Wall(tuple(e["p0"]), tuple(e["p1"]), float(e["height"]), WALL_THICKNESS,
                  tuple(e["holes"]), e["color"] or (0.85, 0.85, 0.82), tuple(e["ids"]))
             for e in by_key.values()]

    # Objects, depth first.
    objects: list[SimObject] = []

    def add(obj: dict[str, Any], path: str, parent: int | None) -> None:
        otype = str(rd.get(obj, "objectType", f"{path}.objectType"))
        asset = str(rd.get(obj, "assetId", f"{path}.assetId"))
        center = np.array(rd.xyz(rd.get(obj, "position", f"{path}.position"),
                                 f"{path}.position"))
        rot = obj.get("rotation") or {}
        yaw_unity = float(rot.get("y", 0.0)) if isinstance(rot, dict) else 0.0
        default = False
        if asset in sizes:
            bx, by, bz = sizes[asset]
            size = np.array([bx, bz, by])
        elif otype.startswith("Obja"):
            size = np.array(OBJAVERSE_DEFAULT_SIZE, dtype=np.float64)
            default = True
        else:
            raise DataError(f"asset '{asset}' (objectType {otype}) has no size in "
                            f"{Path(asset_db).name}; add its boundingBox there",
                            file=file, line=line, field=f"{path}.assetId")
        iid = len(objects)
        objects.append(SimObject(iid, category_of(otype), center, size,
                                 -math.radians(yaw_unity), otype, parent, default,
                                 str(obj.get("id") or "")))
        for k, child in enumerate(obj.get("children") or []):
            add(child, f"{path}.children[{k}]", iid)

    objs_json = data.get("objects")
    if objs_json is None:
        raise DataError("missing field 'objects'", file=file, line=line, field="objects")
    for i, obj in enumerate(objs_json):
        add(obj, f"objects[{i}]", None)

    objects = clear_wall_slabs(objects, walls)
    house = assemble_house(name, rooms, walls, objects, resolution=RESOLUTION, pad=GRID_PAD,
                           source=file)
    # Footprints (goal cells) are computed on first use by House.footprint.
    agent = (data.get("metadata") or {}).get("agent")
    if isinstance(agent, dict) and isinstance(agent.get("position"), dict):
        p = agent["position"]
        yaw_u = float((agent.get("rotation") or {}).get("y", 0.0))
        # Unity forward (+z_p) rotated clockwise by yaw_u -> world yaw pi/2 - yaw_u.
        house.start_hint = (float(p.get("x", 0.0)), float(p.get("z", 0.0)),
                            math.pi / 2 - math.radians(yaw_u))
    return house


def clear_wall_slabs(objects: list[SimObject], walls: list[Wall]) -> list[SimObject]:
    """Objects moved out of the wall slabs along the wall normal, to the room side.

    ProcTHOR walls are planes and wall-mounted objects (paintings, mirrors, shelves, TVs) hang a
    few centimetres in front of them; our walls are ``WALL_THICKNESS`` slabs centred on the
    plane, which swallowed a 2 cm painting 3 cm from the plane: it was never rendered, so never
    seen (8 of 19 'no frontier' failures on ProcTHOR val were paintings). An object whose box
    intrudes into a slab by at most ``MAX_WALL_SHIFT`` is moved out until its back touches the
    slab's face (+2 mm), on the side where its centre lies.
    """
    out = []
    for obj in objects:
        c = np.asarray(obj.center, dtype=np.float64)
        ax = np.array([math.cos(obj.yaw), math.sin(obj.yaw)])
        ay = np.array([-ax[1], ax[0]])
        shift = np.zeros(2)
        for wall in walls:
            p0, p1 = np.asarray(wall.start, dtype=np.float64), np.asarray(wall.end, dtype=np.float64)
            length = float(np.linalg.norm(p1 - p0))
            if length < 1e-6 or obj.bottom >= wall.height:
                continue
            u = (p1 - p0) / length
            n = np.array([-u[1], u[0]])
            e_n = 0.5 * (abs(ax @ n) * obj.size[0] + abs(ay @ n) * obj.size[1])
            e_u = 0.5 * (abs(ax @ u) * obj.size[0] + abs(ay @ u) * obj.size[1])
            xy = c[:2] + shift
            t, d = float((xy - p0) @ u), float((xy - p0) @ n)
            if t < -e_u or t > length + e_u or abs(d) < 1e-4:
                continue
            need = 0.5 * wall.thickness + e_n + 0.002 - abs(d)
            if 0.0 < need <= MAX_WALL_SHIFT:
                shift += math.copysign(need, d) * n
        if np.any(shift):
            moved = c.copy()
            moved[:2] += shift
            obj = replace(obj, center=moved)
        out.append(obj)
    return out


def load_procthor(split: str, index: int, data_dir: Path) -> House:
    """House ``index`` (0-based line) of ``procthor/<split>.jsonl.gz``."""
    path = data_dir / "procthor" / f"{split}.jsonl.gz"
    if not path.is_file():
        raise DataError(f"ProcTHOR split '{split}' not found (expected train or val)",
                        file=str(path))
    return load_procthor_line(path, index, data_dir, name=f"procthor:{split}/{index}")


def load_procthor_line(path: Path, index: int, data_dir: Path, *, name: str | None = None) -> House:
    """House ``index`` (0-based, counting non-empty lines) of any ProcTHOR ``*.jsonl(.gz)`` file,
    named ``<path>#<index>`` unless ``name`` is given."""
    lines = split_lines(str(path))
    if not 0 <= index < len(lines):
        raise DataError(f"house index {index} out of range: {path} has houses 0..{len(lines) - 1}",
                        file=str(path), field="house")
    data = parse_json(lines[index], str(path), index + 1)
    return build_house(data, name or f"{path}#{index}", str(path), index + 1,
                       str(data_dir / "procthor" / "asset-database.json"))


def load_procthor_file(path: Path, data_dir: Path) -> House:
    """A single ProcTHOR house JSON file (``.json`` or ``.json.gz``)."""
    try:
        opener = gzip.open if str(path).endswith(".gz") else open
        with opener(path, "rt", encoding="utf-8") as fh:
            text = fh.read()
    except OSError as exc:
        raise DataError(f"cannot read house file: {exc}", file=str(path)) from exc
    data = parse_json(text, str(path))
    return build_house(data, str(path), str(path), None,
                       str(data_dir / "procthor" / "asset-database.json"))
