"""Three tasks, one episode format: ObjectNav, open-vocabulary ObjectNav (OVON) and text
navigation (TextNav) on ProcTHOR houses, as JSON Lines files; their generator, reader and checks.

One line per episode (world frame: x east, y north, yaw rad counter-clockwise from +x)::

    {"episode_id": str, "house": int, "start": [x, y, yaw], "task": "objectnav"|"ovon"|"textnav",
     "instruction": str, "target": str, "goal_object_ids": [ProcTHOR object "id", ...]}

``house`` is the 0-based line of the houses file the episodes are read with (any ProcTHOR
``*.jsonl(.gz)``); ``target`` is our category (``hiconav.sim.procthor.category_of``).
``goal_object_ids`` holds every instance of the category a camera can see for objectnav and ovon,
and only the described instance for textnav; success is the usual one (stop within 1 m of a
goal's success region).

- **objectnav**: ``hiconav.sim.episodes.generate_episodes`` as it stands ("find the chair").
- **ovon**: the same draws over the categories people name with other words; the instruction
  names the target with one of ``OVON_NAMES`` (never the category's own words) in one of
  ``OVON_PHRASINGS`` ("take me to the fridge", "where is the nightstand?").
- **textnav**: only categories with two or more visible instances (the category drawn uniformly,
  then one of its instances); the instruction describes the instance by what a person sees: its
  room, an object it stands on, one next to it (planar gap <= 1 m), near it (<= 2 m) or above it
  (``hiconav.relations``). The description is checked on the
  ground truth to single out that instance: every other instance of the category fails one of
  its clauses, read generously (any object of the anchor category, a ProcTHOR parent or the box
  geometry, an unknown room counts as any room), while the described instance satisfies each
  clause strictly (the anchor is a visible landmark, its ProcTHOR parent *and* the geometry for
  "on", and the anchor stands in the described instance's room: a person by a painting on a
  bathroom wall does not call it "next to" the armchair on the wall's living room side, however
  small the planar gap through the wall; ``GroundTruth.same_side``). The shortest description
  wins: room, one relation, room and relation, two relations; an instance that no description
  singles out is not used.

Generation is deterministic per (houses file line, task, n, seed). Reading checks each line
(``parse_line``: fields; ``resolve``: object ids, start on the robot centre's free space, goal
reachable) and raises ``DataError`` naming the file, line and field. This module builds and reads
episodes; it must not run them (``hiconav.eval`` does).
"""

from __future__ import annotations

import json
import math
import zlib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hiconav.errors import DataError
from hiconav.relations import NEAR, NEXT_TO, Thing, gap_lower_bound, holds, in_polygon, planar_gap, polygon_distance
from hiconav.sim.episodes import TARGET_CATEGORIES, generate_episodes
from hiconav.sim.geodesic import GoalDistance, centre_free, house_graph
from hiconav.sim.house import House, SimObject

TASKS: tuple[str, ...] = ("objectnav", "ovon", "textnav")
FIELDS: tuple[str, ...] = ("episode_id", "house", "start", "task", "instruction", "target",
                           "goal_object_ids")
RADIUS = 0.18  # m: the robot's radius for start validity (the simulator's default)
SUCCESS_DISTANCE = 1.0  # m
MIN_DISTANCE, MAX_DISTANCE = 1.5, 30.0  # m: start-to-goal geodesic distance of generated starts

# What people call our categories, in words that are not the category's own (each maps back to
# the category through hiconav.reasoning.decompose's lexicon; a test checks every one). Words
# that name another category as well are left out ("seat": a sofa is one; "computer": a desktop).
OVON_NAMES: dict[str, tuple[str, ...]] = {
    "sofa": ("couch", "settee", "loveseat"),
    "tv": ("television", "telly", "television set", "flat screen"),
    "toilet": ("loo", "commode", "lavatory", "wc"),
    "plant": ("houseplant", "planter", "flower pot"),
    "dining_table": ("kitchen table", "dinner table"),
    "fridge": ("refrigerator", "icebox"),
    "sink": ("washbasin", "wash basin", "basin"),
    "laptop": ("notebook computer",),
    "armchair": ("recliner", "easy chair", "lounge chair", "accent chair"),
    "dresser": ("chest of drawers",),
    "coffee_machine": ("coffee maker", "espresso machine"),
    "washing_machine": ("washer", "laundry machine"),
    "clothes_dryer": ("dryer", "tumble dryer"),
    "floor_lamp": ("standing lamp",),
    "desk_lamp": ("table lamp", "reading lamp", "bedside lamp"),
    "side_table": ("nightstand", "night stand", "bedside table", "end table"),
    "tv_stand": ("tv cabinet", "media console", "entertainment center", "tv unit"),
    "shelving_unit": ("bookcase", "bookshelf"),
    "garbage_can": ("trash can", "trash bin", "wastebasket", "dustbin", "rubbish bin", "waste bin"),
    "oven": ("cooker",),
    "bathtub": ("tub", "bath"),
    "teddy_bear": ("teddy", "stuffed animal", "soft toy", "plush toy"),
    "statue": ("sculpture", "figurine"),
    "painting": ("picture", "artwork", "framed picture"),
    "laundry_hamper": ("laundry basket", "hamper", "clothes basket"),
    "dog_bed": ("pet bed",),
}
OVON_PHRASINGS: tuple[str, ...] = (
    "find {a} {name}", "go to {a} {name}", "take me to the {name}", "where is the {name}?",
    "I need to get to the {name}", "can you find {a} {name}?", "navigate to the {name}",
    "I'm looking for {a} {name}", "please locate the {name}", "head over to the {name}",
    "show me the {name}", "walk to the {name}",
)
TEXTNAV_PHRASINGS: tuple[str, ...] = (
    "find the {np}", "go to the {np}", "take me to the {np}", "where is the {np}?",
    "I'm looking for the {np}", "navigate to the {np}", "can you find the {np}?",
    "please go to the {np}",
)
RELATION_WORDS: dict[str, tuple[str, ...]] = {
    "on": ("on the", "on top of the"),
    "next to": ("next to the", "beside the", "by the"),
    "near": ("near the", "close to the"),
    "under": ("under the", "below the", "beneath the"),
}
ROOM_NAMES: dict[str, str] = {"Kitchen": "kitchen", "LivingRoom": "living room", "Bedroom": "bedroom",
                              "Bathroom": "bathroom"}
# Our category -> the words a description uses for it (default: the label with spaces).
SPOKEN: dict[str, str] = {"counter_top": "counter", "shelving_unit": "shelf", "tv": "TV",
                          "tv_stand": "TV stand"}
# Objects a description may refer to (furniture, appliances, large decor): a person names them,
# the parser knows them, and they are large enough to be seen across a room.
LANDMARKS: frozenset[str] = frozenset(TARGET_CATEGORIES) | {"counter_top", "coffee_table", "ottoman"}
MIN_LANDMARK_SIZE = 0.25  # m: a landmark's largest box side
ROOM_SNAP = 0.3  # m: an object centre this close outside a room polygon belongs to that room


def spoken(category: str) -> str:
    return SPOKEN.get(category, category.replace("_", " "))


def _article(word: str) -> str:
    return "an" if word[:1].lower() in "aeiou" else "a"


def task_seed(seed: int, task: str, house: int) -> int:
    """The generator's stable 31-bit seed for one (task, house line) under ``seed``."""
    return zlib.crc32(f"{int(seed)}:{task}/{int(house)}".encode()) & 0x7FFFFFFF


@dataclass(frozen=True)
class TaskEpisode:
    """One line of a task episode file (see the module docstring)."""

    episode_id: str
    house: int
    start: tuple[float, float, float]
    task: str
    instruction: str
    target: str
    goal_object_ids: tuple[str, ...]

    def to_json(self) -> dict[str, Any]:
        return {"episode_id": self.episode_id, "house": self.house, "start": list(self.start),
                "task": self.task, "instruction": self.instruction, "target": self.target,
                "goal_object_ids": list(self.goal_object_ids)}


# ------------------------------------------------------------------------------- ground truth
def thing_of(obj: SimObject) -> Thing:
    """The relation predicates' view of an object."""
    return Thing(obj.category, (float(obj.center[0]), float(obj.center[1])),
                 (float(obj.size[0]), float(obj.size[1])), float(obj.yaw), obj.bottom, obj.top)


#: A clause of a description: ("in", room type) or (relation, anchor category).
Clause = tuple[str, str]


class GroundTruth:
    """The relations of a house's objects, for writing and checking descriptions.

    ``visible(iid)``: whether a camera sees the instance (None: every instance counts as seen).
    """

    def __init__(self, house: House, visible: Any = None) -> None:
        self.house = house
        self.things = [thing_of(o) for o in house.objects]
        self._visible = visible
        self._rooms: dict[int, int | None] = {}
        self._memo: dict[tuple[str, int, Clause], bool] = {}

    def room_of(self, iid: int) -> str | None:
        """The ProcTHOR roomType of the room whose polygon holds the object's centre (or lies
        within ``ROOM_SNAP`` of it), None if none does."""
        k = self.room_index(iid)
        return None if k is None else self.house.rooms[k].room_type

    def room_index(self, iid: int) -> int | None:
        """The index in ``house.rooms`` of the room that holds the object (``room_of``'s rule),
        None if none does: two bedrooms are two rooms."""
        if iid not in self._rooms:
            xy = self.things[iid].center
            room = next((k for k, r in enumerate(self.house.rooms) if in_polygon(xy, r.polygon)), None)
            if room is None and self.house.rooms:
                d, k = min((polygon_distance(xy, r.polygon), k) for k, r in enumerate(self.house.rooms))
                room = k if d <= ROOM_SNAP else None
            self._rooms[iid] = room
        return self._rooms[iid]

    def same_side(self, a: int, b: int) -> bool:
        """Whether a person standing by one of the two objects sees the other beside it: both
        stand in one room, or the house does not say (an object in no room polygon). A painting
        on a bathroom's wall is not "next to" the armchair on the living room's side of that
        wall, however small the planar gap through it."""
        ra, rb = self.room_index(a), self.room_index(b)
        return ra is None or rb is None or ra == rb

    def is_landmark(self, iid: int) -> bool:
        """Whether a description may name this object: a landmark category, a real (not
        fallback) box of at least ``MIN_LANDMARK_SIZE``, seen by a camera."""
        o = self.house.objects[iid]
        if o.category not in LANDMARKS or o.default_size or float(np.max(o.size)) < MIN_LANDMARK_SIZE:
            return False
        return True if self._visible is None else bool(self._visible(iid))

    def _related(self, relation: str, a: int, b: int, *, strict: bool = True) -> bool:
        """``a <relation> b`` by the geometry; read strictly, also as a person sees it: the two
        in one room (``same_side``). The generous reading (``may_satisfy``) keeps the geometry
        alone, so that no other instance satisfies a description even for a reader who ignores
        walls."""
        return holds(relation, self.things[a], self.things[b]) and (not strict or self.same_side(a, b))

    def may_satisfy(self, iid: int, clause: Clause) -> bool:
        """Whether ``iid`` might be what the clause describes (read generously; memoised)."""
        key = ("may", iid, clause)
        if key not in self._memo:
            self._memo[key] = self._may_satisfy(iid, clause)
        return self._memo[key]

    def satisfies(self, iid: int, clause: Clause) -> bool:
        """Whether ``iid`` is what the clause describes (read strictly; memoised)."""
        key = ("does", iid, clause)
        if key not in self._memo:
            self._memo[key] = self._satisfies(iid, clause)
        return self._memo[key]

    def _may_satisfy(self, iid: int, clause: Clause) -> bool:
        """Whether ``iid`` might be what the clause describes, read generously: any object of the
        anchor category, ProcTHOR's parent or the geometry for "on", an unknown room for any room."""
        kind, what = clause
        if kind == "in":
            room = self.room_of(iid)
            return room is None or room == what
        obj = self.house.objects[iid]
        if kind == "on" and obj.parent_id is not None and self.house.objects[obj.parent_id].category == what:
            return True
        return any(self._related(kind, iid, o.instance_id, strict=False) for o in self.house.objects
                   if o.category == what and o.instance_id != iid)

    def _satisfies(self, iid: int, clause: Clause) -> bool:
        """Whether ``iid`` is what the clause describes, read strictly: a landmark anchor, and
        for "on" its ProcTHOR parent that the geometry also puts it on."""
        kind, what = clause
        if kind == "in":
            return self.room_of(iid) == what
        obj = self.house.objects[iid]
        if kind == "on":
            p = obj.parent_id
            return p is not None and self.house.objects[p].category == what and self.is_landmark(p) \
                and self._related("on", iid, p)
        return any(o.category == what and o.instance_id != iid and self._related(kind, iid, o.instance_id)
                   and self.is_landmark(o.instance_id) for o in self.house.objects)

    def singles_out(self, iid: int, clauses: Sequence[Clause]) -> bool:
        """Whether the clauses hold for ``iid`` and no other instance of its category may satisfy
        them all."""
        if not clauses or not all(self.satisfies(iid, c) for c in clauses):
            return False
        category = self.house.objects[iid].category
        return not any(all(self.may_satisfy(o.instance_id, c) for c in clauses)
                       for o in self.house.objects if o.category == category and o.instance_id != iid)

    def candidate_clauses(self, iid: int) -> list[Clause]:
        """Relation clauses that hold for ``iid`` (one per anchor category, the most telling
        relation: on, under, next to, near), nearest anchor first."""
        obj = self.house.objects[iid]
        me = self.things[iid]
        found: dict[str, tuple[int, float, str]] = {}
        rank = {"on": 0, "under": 1, "next to": 2, "near": 3}
        for o in self.house.objects:
            j = o.instance_id
            if j == iid or o.category == obj.category or gap_lower_bound(me, self.things[j]) > NEAR:
                continue
            gap = planar_gap(me, self.things[j])
            if gap > NEAR:
                continue
            for kind in ("on", "under", "next to", "near"):
                if kind == "near" and gap <= NEXT_TO:
                    continue  # "next to" says more
                if (kind == "on" and obj.parent_id != j) or not self._related(kind, iid, j) \
                        or not self.is_landmark(j):
                    continue
                best = found.get(o.category)
                key = (rank[kind], gap, kind)
                if best is None or key < best:
                    found[o.category] = key
                break
        return [(kind, cat) for cat, (_, _, kind) in sorted(found.items(), key=lambda kv: (kv[1][:2], kv[0]))]

    def describe(self, iid: int) -> list[Clause] | None:
        """The shortest description that singles ``iid`` out, or None."""
        room = self.room_of(iid)
        rels = self.candidate_clauses(iid)
        options: list[list[Clause]] = []
        if room in ROOM_NAMES:
            options.append([("in", room)])
        options += [[c] for c in rels]
        if room in ROOM_NAMES:
            options += [[c, ("in", room)] for c in rels]
        options += [[a, b] for k, a in enumerate(rels) for b in rels[k + 1:]]
        return next((clauses for clauses in options if self.singles_out(iid, clauses)), None)


def describe_phrase(category: str, clauses: Sequence[Clause], rng: np.random.Generator) -> str:
    """The noun phrase of a description, without the article: "armchair next to the floor lamp
    in the living room". Two relations are joined by a comma (both are the target's)."""
    rel = [c for c in clauses if c[0] != "in"]
    room = [c for c in clauses if c[0] == "in"]
    parts = [f"{RELATION_WORDS[k][int(rng.integers(len(RELATION_WORDS[k])))]} {spoken(a)}" for k, a in rel]
    text = spoken(category) + " " + ", ".join(parts) if parts else spoken(category)
    if room:
        text += f" in the {ROOM_NAMES[room[0][1]]}"
    return text


# ----------------------------------------------------------------------------------- generator
def _source_ids(house: House, ids: Iterable[int]) -> tuple[str, ...]:
    out = tuple(house.objects[i].source_id for i in ids)
    if not all(out):
        raise DataError(f"{house.name}: an object has no ProcTHOR id", field="goal_object_ids")
    return out


def generate_task_episodes(house: House, house_index: int, task: str, n: int, seed: int = 0) -> list[TaskEpisode]:
    """``n`` episodes of ``task`` in ``house`` (line ``house_index`` of its houses file);
    deterministic per (house, house_index, task, n, seed). Raises ``DataError`` when the house
    has nothing to draw for the task."""
    if task not in TASKS:
        raise DataError(f"unknown task {task!r}; known: {', '.join(TASKS)}", field="task")
    if n < 1:
        raise DataError("must be at least 1", field="per_house")
    s = task_seed(seed, task, house_index)
    if task == "textnav":
        return _textnav(house, house_index, n, s)
    categories = None if task == "objectnav" else tuple(c for c in TARGET_CATEGORIES if c in OVON_NAMES)
    episodes = generate_episodes(house, n, seed=s, categories=categories)
    rng = np.random.default_rng(s ^ 0x5EED)
    out = []
    for i, ep in enumerate(episodes):
        if task == "objectnav":
            text = ep.instruction
        else:
            names = OVON_NAMES[ep.target]
            name = names[int(rng.integers(len(names)))]
            text = OVON_PHRASINGS[int(rng.integers(len(OVON_PHRASINGS)))].format(a=_article(name), name=name)
        out.append(TaskEpisode(f"{task}/{house_index}/{i}", house_index, (ep.start.x, ep.start.y, ep.start.yaw),
                               task, text, ep.target, _source_ids(house, ep.goal_instance_ids)))
    return out


def textnav_candidates(house: House, visible: Any = None) -> list[tuple[int, list[Clause]]]:
    """(instance id, description) of every visible instance of a target category with two or
    more visible instances that some description singles out, in instance order."""
    truth = GroundTruth(house, visible)
    out = []
    for category in sorted(c for c in house.categories if c in TARGET_CATEGORIES):
        seen = [o.instance_id for o in house.instances_of(category) if visible is None or visible(o.instance_id)]
        if len(seen) < 2:
            continue
        for iid in seen:
            clauses = truth.describe(iid)
            if clauses is not None:
                out.append((iid, clauses))
    return sorted(out)


def _visibility(house: House, sim: Any) -> Any:
    from hiconav.sim.viewpoints import MIN_VIEW_PIXELS, instance_view_pixels

    cache: dict[int, bool] = {}

    def visible(iid: int) -> bool:
        if iid not in cache:
            cache[iid] = instance_view_pixels(house, iid, sim, min_pixels=MIN_VIEW_PIXELS) >= MIN_VIEW_PIXELS
        return cache[iid]
    return visible


def _textnav(house: House, house_index: int, n: int, seed: int) -> list[TaskEpisode]:
    from hiconav.sim.simulator import Simulator

    sim = Simulator(house)
    try:
        candidates = textnav_candidates(house, _visibility(house, sim))
    finally:
        sim.close()
    graph = house_graph(house, RADIUS)
    usable = []
    for iid, clauses in candidates:
        gd = GoalDistance(house, instance_ids=(iid,), radius=RADIUS)
        ok = graph.mask & np.isfinite(gd.field) & (gd.field >= MIN_DISTANCE) & (gd.field <= MAX_DISTANCE)
        cells = np.argwhere(ok)
        if len(cells):
            usable.append((iid, clauses, cells))
    if not usable:
        raise DataError(f"{house.name} has no instance that a description singles out among two or more "
                        "visible instances of a target category", field="task")
    # the category first, uniformly, then one of its described instances (as objectnav draws the
    # category): drawing instances alone made every third episode a painting
    by_category: dict[str, list[tuple[int, list[Clause], np.ndarray]]] = {}
    for entry in usable:
        by_category.setdefault(house.objects[entry[0]].category, []).append(entry)
    categories = sorted(by_category)
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        group = by_category[categories[int(rng.integers(len(categories)))]]
        iid, clauses, cells = group[int(rng.integers(len(group)))]
        rc = cells[int(rng.integers(len(cells)))]
        xy = house.nav.cell_to_world(rc)
        yaw = float(rng.uniform(-math.pi, math.pi))
        category = house.objects[iid].category
        np_text = describe_phrase(category, clauses, rng)
        text = TEXTNAV_PHRASINGS[int(rng.integers(len(TEXTNAV_PHRASINGS)))].format(np=np_text)
        out.append(TaskEpisode(f"textnav/{house_index}/{i}", house_index, (float(xy[0]), float(xy[1]), yaw),
                               "textnav", text, category, _source_ids(house, (iid,))))
    return out


def write_task_episodes(path: str | Path, episodes: Iterable[TaskEpisode]) -> int:
    """Write episodes as JSON Lines (the format's key order); returns how many."""
    count = 0
    with Path(path).open("w", encoding="utf-8") as fh:
        for ep in episodes:
            fh.write(json.dumps(ep.to_json()) + "\n")
            count += 1
    return count


# -------------------------------------------------------------------------------------- reader
def parse_line(text: str, file: str, line: int) -> TaskEpisode:
    """One line of an episode file -> ``TaskEpisode``; ``DataError`` naming file, line and field."""
    def bad(message: str, field: str | None = None) -> DataError:
        return DataError(message, file=file, line=line, field=field)

    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise bad(f"malformed JSON: {exc.msg} (column {exc.colno})") from None
    if not isinstance(data, dict):
        raise bad("an episode must be a JSON object with the fields " + ", ".join(FIELDS))
    missing = [k for k in FIELDS if k not in data]
    if missing:
        raise bad(f"missing field(s) {', '.join(missing)}", missing[0])
    unknown = sorted(k for k in data if k not in FIELDS)
    if unknown:
        raise bad(f"unknown field(s) {', '.join(unknown)}; the fields are {', '.join(FIELDS)}", unknown[0])
    for key in ("episode_id", "instruction", "target", "task"):
        if not isinstance(data[key], str) or not data[key].strip():
            raise bad(f"expected a non-empty string, got {data[key]!r}", key)
    if data["task"] not in TASKS:
        raise bad(f"unknown task {data['task']!r}; known: {', '.join(TASKS)}", "task")
    house = data["house"]
    if not isinstance(house, int) or isinstance(house, bool) or house < 0:
        raise bad(f"expected the houses file's 0-based line (an integer >= 0), got {house!r}", "house")
    start = data["start"]
    if not isinstance(start, list) or len(start) != 3 or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in start):
        raise bad(f"expected [x, y, yaw] (three finite numbers: metres, metres, radians), got {start!r}", "start")
    ids = data["goal_object_ids"]
    if not isinstance(ids, list) or not ids or not all(isinstance(i, str) and i for i in ids):
        raise bad(f"expected a non-empty list of ProcTHOR object id strings, got {ids!r}", "goal_object_ids")
    if data["task"] == "textnav" and len(ids) != 1:
        raise bad(f"a textnav episode has exactly one goal object (the described one), got {len(ids)}",
                  "goal_object_ids")
    return TaskEpisode(data["episode_id"], house, (float(start[0]), float(start[1]), float(start[2])),
                       data["task"], data["instruction"], data["target"], tuple(ids))


def resolve(episode: TaskEpisode, house: House, file: str, line: int, *,
            radius: float = RADIUS) -> tuple[tuple[int, ...], float]:
    """(goal instance ids, geodesic start-to-goal distance) of an episode in its house; raises
    ``DataError`` (file, line, field) for an unknown object id, a goal of another category than the
    target, a start off the robot centre's free space or a goal unreachable from the start."""
    ids = []
    for k, source_id in enumerate(episode.goal_object_ids):
        iid = house.instance_by_source_id(source_id)
        if iid is None:
            raise DataError(f"unknown ProcTHOR object id {source_id!r} in house {episode.house} ({house.name})",
                            file=file, line=line, field=f"goal_object_ids[{k}]")
        category = house.objects[iid].category
        if category != episode.target:
            raise DataError(f"object {source_id!r} is a '{category}', not the target '{episode.target}'",
                            file=file, line=line, field=f"goal_object_ids[{k}]")
        ids.append(iid)
    xy = np.asarray(episode.start[:2], dtype=np.float64)
    rc = house.nav.world_to_cell(xy)
    free = centre_free(house, radius)
    if not house.nav.in_bounds(rc) or not free[rc[0], rc[1]]:
        raise DataError(f"start {list(episode.start[:2])} is off the robot's free space in {house.name} "
                        f"(the robot's centre needs {radius} m of clearance there)",
                        file=file, line=line, field="start")
    gd = GoalDistance(house, instance_ids=tuple(ids), radius=radius)
    if not math.isfinite(gd.to_success(xy, SUCCESS_DISTANCE)):
        raise DataError(f"no '{episode.target}' goal of {house.name} is reachable from the start {list(episode.start[:2])}",
                        file=file, line=line, field="goal_object_ids")
    return tuple(ids), gd.distance(xy)
