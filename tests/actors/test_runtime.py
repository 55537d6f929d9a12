"""Runtimes: start/stop order, failure handling (robot stops, report names the actor),
latest-wins dropping, virtual latency, determinism; real-time pykka actors."""

from __future__ import annotations

import pykka
import pytest
from hiconav.actors import RealtimeRuntime, SteppedRuntime

from hiconav.messages import ActorFailed

from .toys import Relay, ToyDriver


def test_stepped_starts_in_dependency_order_and_stops_in_reverse():
    log: list = []
    report = SteppedRuntime([ToyDriver(log), Relay(log)]).run(max_time=10)
    assert report.reason == "episode_ended"
    assert report.start_order == ["driver", "relay"]
    assert report.stop_order == ["relay", "driver"]
    assert [e for e in log if e[0] in ("start", "stop")] == [("start", "driver"), ("start", "relay"),
                                                             ("stop", "relay"), ("stop", "driver")]


def test_stepped_failure_stops_the_robot_and_names_the_actor():
    log: list = []
    driver = ToyDriver(log, limit=100)
    report = SteppedRuntime([driver, Relay(log, fail_at=3)]).run(max_time=10)
    assert report.reason == "actor_failed"
    assert report.failure.actor == "relay"
    assert "relay broke on ping 3" in report.failure.error
    assert driver.command.v == 0.0 and driver.command.omega == 0.0
    assert ("stop", "driver") in log and ("stop", "relay") in log


def test_latest_wins_drops_and_counts_stale_messages():
    log: list = []
    driver = ToyDriver(log, rate_hz=10.0, limit=3)
    relay = Relay(log, rate_hz=2.0)  # five pings per relay tick: four are stale
    report = SteppedRuntime([driver, relay]).run(max_time=10)
    assert report.stats["relay"].dropped["Ping"] >= 4
    assert relay.seen == sorted(relay.seen) and len(set(relay.seen)) == len(relay.seen)


def test_delayed_messages_become_visible_after_their_virtual_latency():
    log: list = []
    driver = ToyDriver(log, limit=2)
    runtime = SteppedRuntime([driver, Relay(log, delay=1.0)])
    report = runtime.run(max_time=10)
    # command for ping 1 (sent at t=0) is executed at the first driver tick at or after t=1.0
    assert report.reason == "episode_ended"
    assert report.episode.stamp == pytest.approx(1.1)


def test_stepped_runs_are_identical():
    def run():
        log: list = []
        d = ToyDriver(log, limit=7)
        r = SteppedRuntime([d, Relay(log, rate_hz=3.0, delay=0.25)]).run(max_time=20)
        return d.executed, r.clock_s, {k: (v.ticks, v.handled, v.dropped) for k, v in r.stats.items()}
    assert run() == run()


def test_realtime_runs_actors_on_threads_and_ends_on_episode_end():
    log: list = []
    driver = ToyDriver(log, rate_hz=50.0, limit=5)
    report = RealtimeRuntime([driver, Relay(log, rate_hz=50.0)]).run(max_time=10)
    assert report.reason == "episode_ended"
    assert len(driver.executed) == 5
    assert report.start_order == ["driver", "relay"] and report.stop_order == ["relay", "driver"]
    assert pykka.ActorRegistry.get_all() == []


def test_realtime_failure_stops_the_robot_and_names_the_actor():
    log: list = []
    driver = ToyDriver(log, rate_hz=50.0, limit=1000)
    report = RealtimeRuntime([driver, Relay(log, rate_hz=50.0, fail_at=3)]).run(max_time=10)
    assert report.reason == "actor_failed"
    assert isinstance(report.failure, ActorFailed) and report.failure.actor == "relay"
    assert "relay broke" in report.failure.error
    assert driver.command is not None and driver.command.v == 0.0
    assert any(e[0] == "emergency" for e in log)
    assert pykka.ActorRegistry.get_all() == []


def test_realtime_failure_in_start_is_reported():
    class BadStart(Relay):
        def start(self, now):
            raise OSError("camera not found")

    log: list = []
    report = RealtimeRuntime([ToyDriver(log, rate_hz=50.0), BadStart(log)]).run(max_time=5)
    assert report.reason == "actor_failed"
    assert report.failure.actor == "relay" and "camera not found" in report.failure.error
    assert pykka.ActorRegistry.get_all() == []
