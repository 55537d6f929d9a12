"""Episode generation (deterministic per seed) and the Habitat episode reader."""

from __future__ import annotations

import gzip
import json
import math

import numpy as np
import pytest

from hiconav.errors import DataError
from hiconav.sim.episodes import TARGET_CATEGORIES, generate_episodes, load_habitat_episodes
from hiconav.sim.geodesic import GoalDistance, centre_free
from hiconav.sim.houses import load_house
from hiconav.sim.simulator import Simulator
from hiconav.sim.viewpoints import viewable_instances


@pytest.mark.parametrize("spec", ["procthor:val/3", "procthor:train/17", "gibson:Allensville"])
def test_generation_is_deterministic_per_seed(shared_data, spec):
    house = load_house(spec, shared_data)
    a = generate_episodes(house, 8, seed=5)
    b = generate_episodes(house, 8, seed=5)
    c = generate_episodes(house, 8, seed=6)
    assert a == b
    assert a != c


@pytest.mark.parametrize("spec", ["procthor:val/3", "gibson:Cosmos"])
def test_episodes_are_valid(shared_data, spec):
    house = load_house(spec, shared_data)
    free = centre_free(house, 0.18)
    sim = Simulator(house)
    for ep in generate_episodes(house, 10, seed=0):
        assert ep.target in TARGET_CATEGORIES and ep.target in house.categories
        every = tuple(o.instance_id for o in house.instances_of(ep.target))
        # the goals are the instances of the category that a camera sees from a view point
        assert ep.goal_instance_ids == viewable_instances(house, every, sim)
        rc = house.nav.world_to_cell(ep.start.xy)
        assert free[rc[0], rc[1]]
        d = GoalDistance(house, ep).distance(ep.start.xy)
        assert math.isfinite(d) and d == pytest.approx(ep.geodesic_distance)
        assert ep.geodesic_distance >= 1.5
        assert ep.instruction == "find the " + ep.target.replace("_", " ")


def _habitat_episode(house, xy, yaw_quat=(0, 0, 0, 1), category="couch", **extra):
    # world (x, y) = (z_h, x_h)
    ep = {"episode_id": "7", "scene_id": "gibson_semantic/Allensville.glb",
          "start_position": [float(xy[1]), 0.1, float(xy[0])], "start_rotation": list(yaw_quat),
          "object_category": category, "floor_id": 0}
    ep.update(extra)
    return ep


def test_habitat_reader_converts_gibson_coordinates(shared_data, tmp_path):
    house = load_house("gibson:Allensville", shared_data)
    ep0 = generate_episodes(house, 1, seed=0, categories=("sofa",))[0]
    s = np.sin(np.pi / 4)
    eps = [_habitat_episode(house, ep0.start.xy, (0, s, 0, s)),
           _habitat_episode(house, ep0.start.xy, scene_id="x/Other.glb"),
           {k: v for k, v in _habitat_episode(house, ep0.start.xy).items()
            if k != "object_category"} | {"object_id": 3}]
    path = tmp_path / "Allensville_episodes.json.gz"
    with gzip.open(path, "wt") as fh:
        json.dump({"episodes": eps}, fh)
    out = load_habitat_episodes(path, house)
    assert len(out) == 2  # the other scene is skipped
    assert out[0].target == "sofa" and out[1].target == "bed"
    np.testing.assert_allclose(out[0].start.xy, ep0.start.xy)
    assert out[0].start.yaw == pytest.approx(-np.pi / 2)
    assert out[0].geodesic_distance == pytest.approx(ep0.geodesic_distance, abs=0.01)


def test_habitat_start_outside_the_map_is_a_clear_error(shared_data, tmp_path):
    house = load_house("gibson:Allensville", shared_data)
    path = tmp_path / "bad_episodes.json.gz"
    with gzip.open(path, "wt") as fh:
        json.dump({"episodes": [_habitat_episode(house, (500.0, 500.0))]}, fh)
    with pytest.raises(DataError, match=r"bad_episodes.json.gz.*episodes\[0\].start_position.*outside"):
        load_habitat_episodes(path, house)
