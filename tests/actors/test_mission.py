"""Missions on real ProcTHOR houses in the built-in simulator (stepped clock unless stated).

The end-to-end test finds an object; the others pin reproducibility, failure handling and the
real-time clock. Each builds the real layers (oracle detector, occupancy grid, memory graph,
exploration planner, offline reasoner, navigator) through ``hiconav.mission``.
"""

from __future__ import annotations

import math

import pytest

from hiconav.mission import build_mission, run_mission

HOUSE = "procthor:val/3"


@pytest.fixture(scope="module")
def house(shared_data):
    from hiconav.sim import load_house

    return load_house(HOUSE)


@pytest.fixture(scope="module")
def episodes(house):
    from hiconav.sim import generate_episodes

    return generate_episodes(house, 6, seed=0)


@pytest.fixture(scope="module")
def embedder():
    from hiconav.perception import get_embedder

    return get_embedder("minilm")


@pytest.mark.slow
def test_end_to_end_finds_the_sofa_in_a_small_procthor_house(house, episodes, embedder):
    episode = episodes[4]
    assert episode.target == "sofa"
    result = run_mission(house, episode, seed=0, embedder=embedder, clock="stepped")
    assert result.failure is None
    assert result.mission_status == "SUCCESS"
    assert result.termination == "stop"
    assert result.metrics.success, result.summary()
    assert result.metrics.spl > 0.5
    assert result.detector == "oracle" and result.reasoner == "offline"
    assert result.fallbacks == []


@pytest.mark.slow
def test_end_to_end_finds_a_dining_table(house, episodes, embedder):
    result = run_mission(house, episodes[1], seed=0, embedder=embedder)
    assert result.metrics.success, result.summary()


def _short_run(house, episode, embedder, seed):
    overrides = {"sim.max_steps": 25}
    result = run_mission(house, episode, seed=seed, embedder=embedder, overrides=overrides)
    stats = {k: (v.ticks, v.handled, dict(v.dropped)) for k, v in result.stats.items()}
    return result.metrics.to_json(), result.trajectory.round(9).tolist(), stats, result.clock_s


def test_same_seed_in_stepped_mode_gives_identical_metrics(house, episodes, embedder):
    a = _short_run(house, episodes[0], embedder, seed=3)
    b = _short_run(house, episodes[0], embedder, seed=3)
    assert a == b
    assert a[0]["steps"] > 0


def test_a_failing_actor_stops_the_robot_and_is_named(house, episodes, embedder):
    parts = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder)
    perception = next(n for n in parts.nodes if n.name == "perception")

    class Broken:
        name = "broken"

        def __init__(self):
            self.calls = 0

        def detect(self, frame, vocabulary=()):
            self.calls += 1
            if self.calls > 3:
                raise ValueError("sensor cable unplugged")
            return []

    perception.detector = Broken()
    from hiconav.actors import TICK_ORDER, SteppedRuntime

    report = SteppedRuntime(parts.nodes, tick_order=TICK_ORDER).run(max_time=60)
    assert report.reason == "actor_failed"
    assert report.failure.actor == "perception"
    assert "sensor cable unplugged" in report.failure.error
    assert parts.driver.ended.reason == "emergency"
    steps = parts.sim.steps
    assert report.stop_order == list(reversed(report.start_order))
    assert steps <= 4


@pytest.mark.slow
def test_real_time_clock_runs_the_same_mission_on_threads(shared_data):
    # In a fresh process: after stepped runs in this process the simulator's EGL renderer cannot
    # create a program in a new thread (reported to the simulator area); a subprocess avoids that.
    import json
    import subprocess
    import sys

    code = (
        "import json, pykka\n"
        "from hiconav.sim import load_house, generate_episodes\n"
        "from hiconav.mission import run_mission\n"
        f"h = load_house({HOUSE!r}); ep = generate_episodes(h, 6, seed=0)[4]\n"
        "r = run_mission(h, ep, seed=0, clock='real', overrides={'sim.max_steps': 15, 'mission.max_time_s': 60})\n"
        "print(json.dumps({**r.summary(), 'alive': len(pykka.ActorRegistry.get_all()),\n"
        "                  'threads': sorted(r.stats)}))\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=240)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["clock"] == "real"
    assert out["failure"] is None
    assert out["steps"] > 0
    assert out["alive"] == 0
    assert math.isfinite(out["wall_s"])


def test_user_actor_by_import_path_alerts_the_mission(house, episodes, embedder):
    overrides = {"sim.max_steps": 30, "mission.extra_actors": {
        "hiconav.actors.monitor:BatteryMonitorNode": {"capacity_s": 2.0, "warn_fraction": 0.5, "rate_hz": 5.0}}}
    parts = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder,
                          overrides=overrides)
    from hiconav.actors import TICK_ORDER, SteppedRuntime

    SteppedRuntime(parts.nodes, tick_order=TICK_ORDER).run(max_time=10)
    assert [a.kind for a in parts.mission.context.alerts] == ["battery"]


def test_eval_runner_entry_point_returns_an_episode_record(shared_data, embedder):
    from hiconav.eval.records import EpisodeRecord
    from hiconav.eval.sources import EpisodeSpec
    from hiconav.mission import run_episode

    spec = EpisodeSpec("t0", HOUSE, "sofa", (4.525, 3.275, 2.7336), (27,), 1.846, "find the sofa")
    record = run_episode(spec, {"sim.max_steps": 12}, 0)
    assert isinstance(record, EpisodeRecord)
    assert record.steps <= 12 and record.max_steps == 12
    assert record.detector == "oracle" and record.reasoner == "offline"
    assert set(record.layer_frames) >= {"driver", "perception", "memory", "mission", "control"}
    # SPL's l: the way to the success region, shorter than the way to the sofa itself
    assert 0.0 < record.extra["shortest_to_success"] < record.geodesic_distance
    assert record.extra["spl_semexp"] is None  # SemExp's own SPL only on its maps (Gibson)
    # each executed action is charged to the behaviour it served: the excesses add up to the path
    # less the progress made toward the success region
    excess = record.extra["excess_path"]
    progress = record.extra["shortest_to_success"] - max(record.dts, 0.0)
    assert sum(excess["by_behaviour"].values()) >= -1e-6 and excess["unmeasured_m"] == 0.0
    assert sum(excess["by_behaviour"].values()) <= record.path_length - progress + 0.3


def test_the_mission_takes_its_decisions_durations_in_robot_time(house, episodes, embedder):
    """On the simulator a driver tick carries a whole discrete action (0.5 s of a robot's time), so
    the mission's clock takes the decisions' durations at a fifth; velocity control at the
    driver's rate moves the robot for a tick's time (one to one)."""
    parts = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder)
    assert parts.mission.time_scale == pytest.approx(0.2)
    assert parts.mission.decisions.explore.max_idle_s == pytest.approx(15.0)  # 75 s of robot time
    moving = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder,
                           overrides={"mission.control_mode": "velocity", "decisions.explore.max_idle_s": 30.0})
    assert moving.mission.time_scale == 1.0 and moving.mission.decisions.explore.max_idle_s == 30.0


def test_stepped_offline_reasoning_takes_no_measured_wall_time(house, episodes, embedder):
    """Same seed, same metrics needs virtual delays that do not depend on the machine's load: the
    offline reasoner's measured wall time must not become its stepped latency; every call takes
    the modelled latency (reasoning.latency_s +- reasoning.latency_jitter_s, seeded) instead."""
    from hiconav.mission import LatencyModel

    parts = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder)
    assert parts.reasoner_name == "offline"
    assert isinstance(parts.reasoning.latency_s, LatencyModel)
    again = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder)
    assert [float(parts.reasoning.latency_s) for _ in range(5)] == [float(again.reasoning.latency_s) for _ in range(5)]
    # robot time: 2.0 +- 0.5 s of a robot making one 0.5 s action per 0.1 s driver tick
    assert 1.5 * 0.2 <= float(parts.reasoning.parse_latency_s) <= 2.5 * 0.2
    clock = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder,
                          overrides={"mission.latency_time": "clock"})
    assert 1.5 <= float(clock.reasoning.parse_latency_s) <= 2.5
    instant = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder,
                            overrides={"reasoning.latency_s": 0.0})
    assert float(instant.reasoning.latency_s) == 0.0
    configured = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder,
                               overrides={"mission.vlm_latency_s": 2.0})
    assert configured.reasoning.latency_s == 2.0


def test_the_reasoning_layer_waits_for_a_clearer_instance_in_robot_time(house, episodes, embedder):
    """reasoning.marginal_patience_s is robot time, as the decisions' durations: 50 s of it is 10
    seconds of the simulator's clock, where a 0.1 s tick carries a 0.5 s action."""
    parts = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder)
    assert parts.reasoning.marginal_patience_s == pytest.approx(10.0)
    moving = build_mission(house, episodes[0].start, episodes[0].instruction, seed=0, embedder=embedder,
                           overrides={"mission.control_mode": "velocity"})
    assert moving.reasoning.marginal_patience_s == pytest.approx(50.0)
