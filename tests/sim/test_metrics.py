"""ObjectNav metrics on hand-made cases."""

from __future__ import annotations

import pytest

from hiconav.sim.config import SimConfig
from hiconav.sim.episodes import Episode
from hiconav.sim.metrics import dts, episode_metrics, spl
from hiconav.types import Pose2D

EP = Episode("e1", "h", Pose2D(0, 0, 0), "bed", (3,), 4.0, "find the bed")


def test_spl_cases():
    assert spl(True, 4.0, 4.0) == 1.0
    assert spl(True, 4.0, 8.0) == 0.5
    assert spl(True, 4.0, 2.0) == 1.0  # a path shorter than the geodesic counts as optimal
    assert spl(False, 4.0, 4.0) == 0.0
    assert spl(True, 0.0, 0.0) == 1.0


def test_dts_cases():
    assert dts(3.5, 1.0) == 2.5
    assert dts(0.4, 1.0) == 0.0


def test_success_needs_stop_within_distance_and_steps():
    ok = episode_metrics(EP, final_distance=0.9, path_length=5.0, steps=40, stopped=True, shortest_to_success=4.0)
    assert ok.success and ok.spl == pytest.approx(0.8) and ok.dts == 0.0
    no_stop = episode_metrics(EP, final_distance=0.9, path_length=5.0, steps=500, stopped=False, shortest_to_success=4.0)
    assert not no_stop.success and no_stop.spl == 0.0
    far = episode_metrics(EP, final_distance=1.2, path_length=5.0, steps=40, stopped=True, shortest_to_success=4.0)
    assert not far.success and far.dts == pytest.approx(0.2)
    late = episode_metrics(EP, final_distance=0.5, path_length=5.0, steps=501, stopped=True, shortest_to_success=4.0)
    assert not late.success
    cfg = SimConfig(success_distance=1.5)
    assert episode_metrics(EP, final_distance=1.2, path_length=5.0, steps=40, stopped=True,
                           shortest_to_success=4.0, config=cfg).success
    assert ok.to_json()["episode_id"] == "e1"


def test_tracker_scores_a_simulated_episode():
    import numpy as np
    from sim_synthetic import box_room, obj

    from hiconav.sim.episodes import generate_episodes
    from hiconav.sim.geodesic import GoalDistance
    from hiconav.sim.metrics import EpisodeTracker
    from hiconav.sim.simulator import Simulator
    from hiconav.types import DiscreteAction

    house = box_room(8.0, [obj(0, "bed", (6.5, 4.0, 0.3), (1.0, 2.0, 0.6))])
    ep = generate_episodes(house, 1, seed=0)[0]
    sim = Simulator(house)
    sim.observe = lambda: None
    sim.reset(Pose2D(2.0, 4.0, 0.0))
    ep = Episode("t", house.name, Pose2D(2.0, 4.0, 0.0), "bed", (0,),
                 GoalDistance(house, ep).distance(np.array([2.0, 4.0])), "find the bed")
    tracker = EpisodeTracker(sim, ep)
    sim.step(DiscreteAction.TURN_LEFT)
    sim.step(DiscreteAction.TURN_RIGHT)
    for _ in range(13):  # 3.25 m towards the bed's face at x = 6.0: ends 0.75 m from it
        sim.step(DiscreteAction.MOVE_FORWARD)
    sim.step(DiscreteAction.STOP)
    m = tracker.finish()
    assert tracker.done and m.stopped and m.success
    assert m.steps == 16 and m.turns == 2
    assert m.path_length == pytest.approx(3.25)
    assert m.final_distance == pytest.approx(0.75, abs=0.06)
    # SPL's l is the way to the success region (1 m short of the bed's face), not to the bed:
    # measured to the bed (4.0 m) this 3.25 m run would score SPL 1, shorter than "shortest"
    assert ep.geodesic_distance == pytest.approx(4.0, abs=0.06)
    assert m.shortest_to_success == pytest.approx(ep.geodesic_distance - 1.0, abs=0.06)
    assert m.spl == pytest.approx(m.shortest_to_success / 3.25) and m.spl < 0.95
    # under velocity control nothing turns in place: the turns are not counted, not zero
    from hiconav.types import VelocityCommand

    sim.reset(Pose2D(2.0, 4.0, 0.0))
    tracker = EpisodeTracker(sim, ep)
    sim.step_velocity(VelocityCommand(0.3, 0.5), 0.1)
    assert sim.turns == 0 and tracker.finish().turns is None


def test_excess_by_source_charges_each_step_its_length_less_its_progress_to_the_region():
    import math

    from hiconav.sim.metrics import excess_by_source

    # the success region is x >= 3 (distance 3 - x): straight in costs nothing, a detour its length,
    # a step back twice it, a turn in place nothing, and steps inside the region all their length
    xy = [(0, 0), (1, 0), (1, 0), (1, 1), (1, 0), (0, 0), (1, 0), (2, 0), (3, 0), (4, 0)]
    sources = ["Explore", "Explore", "Explore", "Explore", "VerifyTarget", "VerifyTarget", "Approach",
               "Approach", "Approach"]
    out = excess_by_source(xy, sources, lambda p: max(0.0, 3.0 - float(p[0])))
    assert out["by_behaviour"] == {"Explore": 2.0, "VerifyTarget": 2.0, "Approach": 1.0}
    assert out["inside_m"] == 1.0 and out["unmeasured_m"] == 0.0
    path = sum(math.dist(a, b) for a, b in zip(xy, xy[1:]))
    assert sum(out["by_behaviour"].values()) == pytest.approx(path - 3.0)  # the path less SPL's l
    off = excess_by_source([(0, 0), (5, 5), (1, 0)], ["Explore", "Explore"],
                           lambda p: math.inf if p[1] > 1 else 3.0 - float(p[0]))
    assert off["by_behaviour"] == {} and off["unmeasured_m"] == pytest.approx(math.hypot(5, 5) + math.hypot(4, 5), abs=1e-3)
    assert excess_by_source([(0, 0), (0, 1)], [""], lambda p: 3.0)["by_behaviour"] == {"unnamed": 1.0}
    with pytest.raises(ValueError, match="one more"):
        excess_by_source([(0, 0)], ["Explore"], lambda p: 0.0)
