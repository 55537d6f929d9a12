"""All 25 Gibson floors load; object instances are the connected components of the source."""

from __future__ import annotations

import bz2
import pickle

import cv2
import numpy as np

from hiconav.sim.gibson import CHANNEL_CATEGORIES, beyond_radius, clean_floor, habitat_to_world, habitat_yaw
from hiconav.sim.houses import load_house


def test_all_floors_load_with_component_counts(shared_data):
    info = pickle.load(bz2.BZ2File(shared_data / "gibson" / "train_info.pbz2"))
    floors = [(s, f) for s in sorted(info) for f in sorted(info[s])]
    assert len(floors) == 25
    for scene, floor in floors:
        rec = info[scene][floor]
        sem = rec["sem_map"] > 0
        spec = f"gibson:{scene}" if floor == 0 else f"gibson:{scene}/{floor}"
        house = load_house(spec, shared_data, cache=False)
        expected = {}
        for k, cat in enumerate(CHANNEL_CATEGORIES, start=1):
            n, _ = cv2.connectedComponents(sem[k].astype(np.uint8), connectivity=8)
            expected[cat] = expected.get(cat, 0) + n - 1
        got = {cat: len(house.instances_of(cat)) for cat in CHANNEL_CATEGORIES}
        assert got == expected, scene
        # Navigable covers channel 0 (plus filled scan speckle) and never an object cell that
        # stands an agent radius beyond the navmesh (nearer ones are not drawn: the navmesh
        # comes that near what the scan projected, so nothing there blocks the agent)
        objects = sem[1:].any(axis=0)
        assert np.all(house.nav.navigable[sem[0] & ~objects])
        solid = objects & beyond_radius(clean_floor(sem[0], objects))
        assert not np.any(house.nav.navigable & solid)
        # Footprints are exactly the category cells.
        total = sum(len(house.footprint(o.instance_id)) for o in house.objects)
        assert total == int(sem[1:].sum())


def test_speckled_floor_is_cleaned_but_walls_stay_closed():
    from hiconav.sim.gibson import clean_floor

    floor = np.zeros((40, 40), bool)
    floor[5:35, 5:18] = True
    floor[5:35, 22:35] = True  # a 4-cell (20 cm) wall between two rooms
    holes = floor.copy()
    rng = np.random.default_rng(0)
    holes[rng.random(floor.shape) < 0.3] = False  # 30 % speckle
    objects = np.zeros_like(floor)
    objects[10:12, 10:12] = True
    cleaned = clean_floor(holes & ~objects, objects)
    assert not cleaned[:, 18:22].any()  # the wall is not bridged
    assert not cleaned[objects].any()
    inner = np.zeros_like(floor)
    inner[6:34, 6:17] = True
    inner[6:34, 23:34] = True
    assert cleaned[inner & ~objects].mean() > 0.99


def test_habitat_positions_map_to_the_readme_cells(shared_data):
    info = pickle.load(bz2.BZ2File(shared_data / "gibson" / "train_info.pbz2"))
    origin = info["Allensville"][0]["origin"]
    house = load_house("gibson:Allensville", shared_data)
    rng = np.random.default_rng(0)
    for _ in range(50):
        x, z = rng.uniform(-5, 5, size=2)
        fr, fc = (x - origin[1] / 100) * 20, (z - origin[0] / 100) * 20
        w = habitat_to_world(np.array([x, 0.1, z]))
        rc = house.nav.world_to_cell(w[:2])
        if fr >= 0 and fc >= 0:  # int() truncates toward zero; floor differs below 0
            assert (rc[0], rc[1]) == (int(fr), int(fc))


def test_habitat_yaw_matches_forward_vector():
    # Identity: the agent looks along -z_h, i.e. world (x, y) = (z_h, x_h) = (-1, 0) -> pi.
    assert np.isclose(abs(habitat_yaw([0, 0, 0, 1])), np.pi)
    # 90 deg about +y_h turns -z_h into -x_h -> world (0, -1) -> -pi/2.
    s = np.sin(np.pi / 4)
    assert np.isclose(habitat_yaw([0, s, 0, s]), -np.pi / 2)


def test_enclosed_small_clutter_is_low_furniture_and_the_rest_is_wall():
    """Islands enclosed by floor (a table with chairs around it) must not be drawn as 2.6 m walls:
    the robot would never see the chairs standing in them."""
    from hiconav.sim.gibson import split_clutter

    clutter = np.zeros((100, 120), dtype=bool)
    clutter[0, :] = clutter[-1, :] = clutter[:, 0] = clutter[:, -1] = True  # the outside
    clutter[40:50, 40:60] = True  # 0.5 m x 1 m island: furniture
    clutter[5:95, 100:120] = True  # touches the map edge: wall
    walls, furniture = split_clutter(clutter)
    assert furniture[45, 50] and not walls[45, 50]
    assert walls[0, 5] and walls[50, 110] and not furniture[50, 110]
    assert not (walls & furniture).any() and ((walls | furniture) == clutter).all()
    big = np.zeros((200, 200), dtype=bool)
    big[20:180, 20:180] = True  # 64 m^2 enclosed: a block of rooms' walls, not furniture
    walls, furniture = split_clutter(big)
    assert walls[100, 100] and not furniture.any()
