"""Goal instances must be visible from a view point: hidden ones are no goals (episodes)."""

from __future__ import annotations

import pytest

from hiconav.errors import DataError
from hiconav.sim.episodes import generate_episodes
from hiconav.sim.simulator import Simulator
from hiconav.sim.viewpoints import MIN_VIEW_PIXELS, instance_view_pixels, viewable_instances

from sim_synthetic import box_room, obj


def _house():
    # a dresser-sized box with a vase inside it (hidden from everywhere), a vase on top of a
    # second dresser (visible), and a sofa in the open
    return box_room(6.0, [
        obj(0, "dresser", (1.5, 3.0, 0.5), (0.8, 0.5, 1.0)),
        obj(1, "vase", (1.5, 3.0, 0.3), (0.2, 0.2, 0.3)),
        obj(2, "dresser", (4.5, 3.0, 0.5), (0.8, 0.5, 1.0)),
        obj(3, "laptop", (4.5, 3.0, 1.1), (0.35, 0.3, 0.2)),
        obj(4, "sofa", (3.0, 1.0, 0.45), (1.8, 0.8, 0.9)),
    ])


def test_an_object_inside_its_receptacle_shows_no_pixels_and_one_on_top_does():
    house = _house()
    sim = Simulator(house)
    try:
        assert instance_view_pixels(house, 1, sim) == 0
        assert instance_view_pixels(house, 3, sim) >= MIN_VIEW_PIXELS
        assert viewable_instances(house, (0, 1, 2, 3, 4), sim) == (0, 2, 3, 4)
    finally:
        sim.close()


def test_generated_episodes_never_target_a_hidden_instance():
    house = _house()
    episodes = generate_episodes(house, 40, seed=3, categories=("vase", "laptop", "sofa"))
    targets = {e.target for e in episodes}
    assert "vase" not in targets and targets == {"laptop", "sofa"}
    # without the check the hidden vase is a goal like any other
    unchecked = generate_episodes(house, 40, seed=3, categories=("vase", "laptop", "sofa"),
                                  min_view_pixels=None)
    assert "vase" in {e.target for e in unchecked}


def test_a_house_whose_only_target_is_hidden_is_a_clear_error():
    with pytest.raises(DataError, match="camera can see"):
        generate_episodes(_house(), 3, seed=0, categories=("vase",))
