"""Every ProcTHOR house of both splits loads, with the object count of the source JSON."""

from __future__ import annotations

import gzip
import json
import math

import numpy as np
import pytest

from hiconav.sim.houses import load_house


def _lines(shared_data, split: str) -> list[str]:
    with gzip.open(shared_data / "procthor" / f"{split}.jsonl.gz", "rt") as fh:
        return fh.read().splitlines()


def _source_count(objs: list[dict]) -> int:
    n = 0
    stack = list(objs)
    while stack:
        o = stack.pop()
        n += 1
        stack.extend(o.get("children") or [])
    return n


@pytest.mark.parametrize("split", ["train", "val"])
def test_every_house_loads_with_source_object_count(shared_data, split):
    lines = _lines(shared_data, split)
    assert len(lines) == 100
    for i, line in enumerate(lines):
        src = json.loads(line)
        house = load_house(f"procthor:{split}/{i}", shared_data, cache=False)
        assert len(house.objects) == _source_count(src["objects"]), f"{split}/{i}"
        assert [o.instance_id for o in house.objects] == list(range(len(house.objects)))
        assert house.nav.navigable.sum() * 0.05**2 > 5.0, f"{split}/{i}: < 5 m^2 of floor"
        assert len(house.rooms) == len(src["rooms"])


def test_procthor_to_world_mapping_is_x_z_y(shared_data):
    """World (x, y, z) = (x_p, z_p, y_p); yaw = -rotation.y (Unity is left-handed)."""
    line = _lines(shared_data, "val")[3]
    src = json.loads(line)["objects"][0]
    house = load_house("procthor:val/3", shared_data)
    o = house.objects[0]
    p = src["position"]
    from hiconav.sim.procthor import MAX_WALL_SHIFT

    assert o.center[2] == p["y"]  # (x, y) may be moved out of a wall slab, see clear_wall_slabs
    assert np.hypot(o.center[0] - p["x"], o.center[1] - p["z"]) <= MAX_WALL_SHIFT
    assert math.isclose(math.cos(o.yaw), math.cos(-math.radians(src["rotation"]["y"])),
                        abs_tol=1e-9)
    assert o.source_type == src["objectType"]


def test_objaverse_objects_get_the_default_box(shared_data):
    from hiconav.sim.procthor import OBJAVERSE_DEFAULT_SIZE

    house = load_house("procthor:val/3", shared_data)
    obja = [o for o in house.objects if o.source_type.startswith("Obja")]
    others = [o for o in house.objects if not o.source_type.startswith("Obja")]
    assert all(o.default_size for o in obja)
    assert all(tuple(o.size) == OBJAVERSE_DEFAULT_SIZE for o in obja)
    assert not any(o.default_size for o in others)


def test_doors_connect_the_rooms_they_name(shared_data):
    """The two rooms of every interior door share one navigable component (the hole is open).
    val/52 and val/90 have rooms that meet exactly on a column of cell centres: a floor seam
    there once closed their doors on the navigable grid while the renderer showed them open."""
    from scipy import ndimage

    from hiconav.sim.house import rasterize_polygon

    lines = _lines(shared_data, "val")
    checked = 0
    for i in sorted(set(range(0, 100, 7)) | {52, 90}):
        src = json.loads(lines[i])
        house = load_house(f"procthor:val/{i}", shared_data)
        labels, _ = ndimage.label(house.nav.navigable, structure=np.ones((3, 3), bool))
        main = {}
        for room in house.rooms:
            inside = rasterize_polygon(house.nav.shape, house.nav.origin, 0.05, room.polygon)
            counts = np.bincount(labels[inside & house.nav.navigable])
            counts[0] = 0
            main[room.id] = int(np.argmax(counts))
        for door in src["doors"]:
            a, b = door.get("room0"), door.get("room1")
            if a in main and b in main and a != b:
                assert main[a] == main[b], f"val/{i} {door['id']} does not connect {a} and {b}"
                checked += 1
    assert checked > 20


def test_wall_mounted_objects_are_outside_the_wall_slabs_and_rendered(shared_data):
    """ProcTHOR hangs paintings a few cm in front of zero-thickness walls; our 10 cm slabs must not
    swallow them (they were never rendered, so never found)."""
    from hiconav.sim import SimConfig, Simulator
    from hiconav.types import Pose2D

    house = load_house("procthor:val/60", shared_data)
    paintings = [o for o in house.objects if o.category == "painting"]
    assert len(paintings) >= 5
    sim = Simulator(house, SimConfig(), seed=0)
    seen = set()
    for o in paintings:
        ax = np.array([math.cos(o.yaw), math.sin(o.yaw)])
        normal = np.array([-ax[1], ax[0]]) if o.size[1] < o.size[0] else ax  # the thin side faces the room
        for side in (1.0, -1.0):
            xy = o.center[:2] + side * 1.5 * normal
            if sim.is_free(xy):
                yaw = math.atan2(o.center[1] - xy[1], o.center[0] - xy[0])
                sim.reset(Pose2D(float(xy[0]), float(xy[1]), yaw))
                if (sim.observe().instances == o.instance_id).sum() > 150:
                    seen.add(o.instance_id)
    sim.close()
    assert len(seen) >= len(paintings) // 2, (len(seen), len(paintings))
